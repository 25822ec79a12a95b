#include "report/tables.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <set>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "report/html_escape.h"
#include "report/latex_table.h"
#include "report/text_escape.h"
#include "report/uncertainty.h"

namespace impactlab {
namespace {

Cell Fixed(double v, int digits) {
  return Cell{fmt::format("{:.{}f}", v, digits), v, std::nullopt, digits};
}
// A deviation that rounds to zero prints as +0.0000, never -0.0000.
Cell Signed(double v, int digits) {
  std::string text = fmt::format("{:+.{}f}", v, digits);
  if (text.find_first_not_of("+-0.") == std::string::npos) text = "+" + text.substr(1);
  return Cell{text, v, std::nullopt, digits};
}
// At most four digits more than asked for: an error far below them (a
// noiseless simulation's) is written in powers of ten instead.
constexpr int kMoreDigits = 4;
// The value and its error, the error to two significant digits
// (report/uncertainty.h).
Cell WithSigma(const Estimate& e, int digits) {
  if (e.sigma == 0.0) return Fixed(e.value, digits);
  if (!std::isfinite(e.sigma)) {
    return Cell{fmt::format("{:.{}f} ± {}", e.value, digits, e.sigma), e.value, e.sigma, digits};
  }
  const RoundedEstimate r = RoundToError(e.value, e.sigma);
  if (r.decimals > digits + kMoreDigits) {
    const int shown = digits + kMoreDigits;
    return Cell{fmt::format("{:.{}f} ± {:.2g}", e.value, shown, e.sigma), e.value, e.sigma, shown};
  }
  return Cell{r.value + " ± " + r.sigma, e.value, e.sigma, r.decimals};
}
Cell Sig(double v, int significant) {
  return Cell{fmt::format("{:.{}g}", v, significant), v, std::nullopt, -1};
}
Cell Count(long long n) {
  return Cell{fmt::format("{}", n), static_cast<double>(n), std::nullopt, 0};
}

Table DeviationTable(const SessionResult& r, const UnitLabels& u) {
  Table t;
  t.name = "table2_deviations";
  t.caption = "Deviation of theoretical response from experimental response (thesis Table 2)";
  t.columns = {"Run",
               "Rebound",
               "Fit pair",
               fmt::format("Experimental Xmax ({})", u.length),
               fmt::format("Theoretical Xmax ({})", u.length),
               fmt::format("Deviation ({})", u.length),
               "Deviation % of peak",
               "Deviation % of X0"};
  for (const RunResult& run : r.runs) {
    if (!run.ok || !run.fits.kelvin_voigt) continue;  // failed, or reduced --only rebounds
    const auto& fit = *run.fits.kelvin_voigt;
    for (std::size_t n = 0; n < run.measured.xmax.size(); ++n) {
      const bool used = static_cast<int>(n) == fit.rebounds_used[0] ||
                        static_cast<int>(n) == fit.rebounds_used[1];
      t.rows.push_back({run.id, Count(static_cast<long long>(n)), used ? "*" : "",
                        Fixed(run.measured.xmax[n], 4), Fixed(fit.predicted_xmax[n].value, 4),
                        Signed(run.fits.deviation[n], 4),
                        Fixed(std::abs(run.fits.deviation_pct_peak[n]), 1),
                        Fixed(std::abs(run.fits.deviation_pct_x0[n]), 1)});
    }
  }
  t.notes = {"Fit pair *: the rebounds that determine the Kelvin-Voigt parameters.",
             "Deviation = theoretical - experimental; percentages are of its magnitude."};
  return t;
}

// With [reduction] average_stiffness: the session's K avg and the run's C
// from it, as the run's K and C.
std::optional<std::pair<Estimate, Estimate>> AveragedRun(const SessionResult& r,
                                                         const std::string& run_id) {
  if (!r.kelvin_voigt || !r.kelvin_voigt->average_stiffness) return std::nullopt;
  const SessionKelvinVoigt& s = *r.kelvin_voigt;
  const auto at = std::find(s.run_ids.begin(), s.run_ids.end(), run_id);
  if (at == s.run_ids.end()) return std::nullopt;
  const auto i = static_cast<std::size_t>(at - s.run_ids.begin());
  return std::pair{*s.average_stiffness, Estimate{s.damping[i], s.damping_sigma[i]}};
}

Table ParameterTable(const SessionResult& r, const UnitLabels& u) {
  Table t;
  t.name = "kelvin_voigt_parameters";
  t.caption = "Kelvin-Voigt parameters per run (two-point fit, eq. 34-38)";
  t.columns = {"Run",
               "Pair",
               "zeta",
               "e",
               fmt::format("K ({})", u.stiffness),
               fmt::format("C ({})", u.damping),
               "tau_c (us)",
               "Status"};
  for (const RunResult& run : r.runs) {
    if (!run.ok || !run.fits.kelvin_voigt) {
      t.rows.push_back({run.id, "", "", "", "", "", "", run.Status()});
      continue;
    }
    const auto& fit = *run.fits.kelvin_voigt;
    std::optional<Estimate> stiffness = fit.stiffness, damping = fit.damping;
    if (const auto average = AveragedRun(r, run.id)) std::tie(stiffness, damping) = *average;
    t.rows.push_back({run.id, fmt::format("{}-{}", fit.rebounds_used[0], fit.rebounds_used[1]),
                      WithSigma(fit.damping_ratio, 5), WithSigma(fit.restitution, 4),
                      stiffness ? WithSigma(*stiffness, 0) : "-",
                      damping ? WithSigma(*damping, 3) : "-",
                      fit.contact_time ? Fixed(*fit.contact_time * 1e6, 1) : "-", "ok"});
  }
  t.notes = {"± one standard error, propagated from the stated reading uncertainties.",
             fmt::format("Pendulum convention: {}; separation: {}.", ConventionName(r.convention),
                         SeparationName(r.separation))};
  if (r.kelvin_voigt && r.kelvin_voigt->average_stiffness) {
    t.notes.push_back("K: the session's average; C from it at each run's own zeta.");
  }
  return t;
}

// A value with its standard error, "undetermined" where the data do not fix
// it, "-" where the fit did not run; `scale` converts it for display (1e6: s to us).
Cell Determined(const FitStatus& status, const std::optional<Estimate>& e, int digits,
                double scale = 1.0) {
  if (!status.Ran() || !e) return "-";
  const Estimate shown{e->value * scale, e->sigma * scale};
  if (!std::isfinite(e->sigma)) return Cell{"undetermined", shown.value, shown.sigma, -1};
  return WithSigma(shown, digits);
}

// "ok", or the flag of a fit whose scatter exceeds its stated sigmas (by
// the Birge ratio beside it).
std::string ScatterStatus(const ScatterCheck& scatter) {
  return scatter.excess ? "ok; excess scatter" : "ok";
}

Table KelvinVoigtLeastSquaresTable(const SessionResult& r, const UnitLabels& u) {
  Table t;
  t.name = "kelvin_voigt_least_squares";
  t.caption = "Kelvin-Voigt by least squares over every rebound maximum of each run";
  t.columns = {"Run",
               "zeta",
               "e",
               fmt::format("K ({})", u.stiffness),
               fmt::format("C ({})", u.damping),
               "chi2",
               "dof",
               "Birge ratio",
               "Status"};
  for (const RunResult& run : r.runs) {
    const auto& fit = run.fits.kelvin_voigt_least_squares;
    if (!fit) continue;
    const FitStatus& status = fit->status;
    t.rows.push_back({run.id, Determined(status, fit->damping_ratio, 5),
                      Determined(status, fit->restitution, 4),
                      Determined(status, fit->stiffness, 0), Determined(status, fit->damping, 3),
                      Sig(fit->chi2, 3), Count(fit->dof), Sig(fit->scatter.birge_ratio, 3),
                      fit->ok ? ScatterStatus(fit->scatter) : fit->reason});
  }
  t.notes = {"Weighted by the maxima's uncertainties; K from the contact time (eq. 37).",
             "The ± are the stated standard errors (from the maxima's sigmas). Where chi2 is "
             "significantly above its dof (p < 0.001) the status says \"excess scatter\": "
             "multiply the ± by the Birge ratio sqrt(chi2/dof) (the results file "
             "has them as *_std_error_scaled; the model's predicted maxima use them)."};
  return t;
}

Table PoyntingThomsonTable(const SessionResult& r, const UnitLabels& u) {
  Table t;
  t.name = "poynting_thomson";
  t.caption = "Poynting-Thomson by least squares: what the data determine";
  t.columns = {"Runs",
               fmt::format("K1 ({})", u.stiffness),
               fmt::format("K2 ({})", u.stiffness),
               fmt::format("C ({})", u.damping),
               "e",
               "tau_c (us)",
               "Identifiability"};
  // One short sentence per fit; the advice the fits share said once, below;
  // each fit's full account (which combinations, with their values) folded.
  std::set<std::string> advice;
  const auto row = [&](const std::string& name, const PoyntingThomsonLeastSquaresFit& fit) {
    const Identifiability& id = fit.identifiability;
    std::string identifiability = fit.ok ? fit.status.message : fit.reason;
    if (id.identifiable) {
      identifiability = "K1, K2 and C determined";
      if (fit.scatter.excess) {
        identifiability +=
            fmt::format(" (scatter {:.3g} x the sigmas: scale the ±)", fit.scatter.birge_ratio);
      }
    } else if (!id.message.empty()) {
      identifiability = fmt::format("{} of 3 combinations determined", id.rank);
      if (const auto last = id.message.rfind(". "); last != std::string::npos) {
        advice.insert(id.message.substr(last + 2));
      }
      t.details.push_back(fmt::format("{}: {}", name, id.message));
    }
    const FitStatus& status = fit.status;
    t.rows.push_back({name, Determined(status, fit.stiffness1, 0),
                      Determined(status, fit.stiffness2, 0), Determined(status, fit.damping, 3),
                      Determined(status, fit.restitution, 4),
                      Determined(status, fit.contact_time, 2, 1e6), identifiability});
  };
  for (const RunResult& run : r.runs) {
    if (run.fits.poynting_thomson) {
      row(run.id, *run.fits.poynting_thomson);
      t.row_kinds.push_back("run");
    }
  }
  for (const PoyntingThomsonLeastSquaresFit& fit : r.joint_fits) {
    row("all runs (joint)", fit);
    t.row_kinds.push_back("joint");
  }
  t.notes = {
      "\"undetermined\": the data fix only some combinations of log K1, log K2 and log C; "
      "K1, K2, C are not reported as confident numbers there."};
  for (const std::string& a : advice) t.notes.push_back("What would determine them: " + a + ".");
  return t;
}

// The Birge-scaled standard error where the scatter exceeds the stated one
// (scale > 1), else no value.
Cell ScaledSigma(const Estimate& e, double scale) {
  if (!(scale > 1.0) || !std::isfinite(e.sigma)) return "-";
  return Sig(e.sigma * scale, 2);
}

Table ModelComparisonTable(const ModelComparison& c, const UnitLabels& u) {
  const bool loo = !c.best_by_leave_one_out.empty();  // leave-one-out made
  Table t;
  t.name = "model_comparison";
  t.caption =
      "Restitution models and contact laws fitted jointly to the runs' maxima, compared "
      "(leave-one-run-out)";
  t.columns = {"Model",
               "k",
               "chi2",
               "dof",
               "AIC",
               "BIC",
               "spread of ln e",
               "LOO rms / sigma",
               fmt::format("LOO rms ({})", u.length),
               "Verdict"};
  // A model's row from its fit's own figures (the restitution models' and the
  // laws' name them differently).
  const auto add = [&](const std::string& model, bool ok, const std::string& reason, int k,
                       double chi2, int dof, double aic, double bic, double spread,
                       double loo_normalized, double loo_length, const std::string& verdict) {
    if (!ok) {
      t.rows.push_back(
          {model + " (failed)", "-", "-", "-", "-", "-", "-", "-", "-", "failed: " + reason});
      return;
    }
    t.rows.push_back({model, Count(k), Sig(chi2, 4), Count(dof), Sig(aic, 5), Sig(bic, 5),
                      Sig(spread, 3), loo ? Sig(loo_normalized, 4) : Cell("-"),
                      loo ? Sig(loo_length, 4) : Cell("-"), verdict});
  };
  for (const ComparedRestitutionModel& m : c.restitution_models) {
    const JointModelFit& f = m.fit;
    add(f.name, f.ok, f.reason, f.parameter_count, f.chi2, f.dof, f.aic, f.bic,
        f.log_restitution_spread, f.leave_one_out.rms_normalized, f.leave_one_out.rms_length,
        m.verdict);
  }
  for (const ComparedContactLaw& m : c.contact_laws) {
    const ContactLawFit& f = m.fit;
    add(f.law, f.ok, f.reason, f.parameter_count, f.chi2, f.dof, f.aic, f.bic,
        m.log_restitution_spread, f.loo_rms_normalized, f.loo_rms_length, m.verdict);
  }
  t.notes = {loo ? fmt::format("Best at predicting an unseen run: {}; lowest BIC: {}.",
                               c.best_by_leave_one_out, c.best_by_bic)
                 : fmt::format("Lowest BIC: {} (no leave-one-out refits).", c.best_by_bic),
             "chi2 / dof far above 1 means the stated uncertainties understate the scatter; "
             "\"scaled\" standard errors are multiplied by sqrt(chi2/dof) (Birge) where that "
             "excess is significant (p < 0.001). The fitted parameters are in table "
             "model_comparison_parameters."};
  for (const std::string& e : c.evidence) t.notes.push_back(e);
  return t;
}

// The models' fitted parameters, one row per model and parameter (tidy: the
// value and its errors in columns of their own).
Table ModelParameterTable(const ModelComparison& c, const UnitLabels& u) {
  Table t;
  t.name = "model_comparison_parameters";
  t.caption = "Restitution models: the fitted parameters";
  t.columns = {"Model", "Parameter", "Value", "Scaled std error", "Units"};
  const auto add = [&](const std::string& model, const std::vector<NamedEstimate>& parameters,
                       double scale) {
    for (const NamedEstimate& p : parameters) {
      t.rows.push_back({model, p.name, WithSigma(p.estimate, 4), ScaledSigma(p.estimate, scale),
                        Cell::Unit(UnitOfKind(p.units, u))});
    }
  };
  for (const ComparedRestitutionModel& m : c.restitution_models) {
    if (m.fit.ok) add(m.fit.name, m.fit.parameters, m.fit.scatter.Scale());
  }
  for (const ComparedContactLaw& m : c.contact_laws) {
    if (m.fit.ok) add(m.fit.law, m.fit.parameters, m.fit.scatter.Scale());
  }
  t.notes = {
      "± the stated standard error; \"scaled\": times the Birge ratio sqrt(chi2/dof), "
      "where the scatter exceeds the stated errors (p < 0.001)."};
  return t;
}

// The session-level products a reduce did not make, and why (pipeline/products.h).
Table SkippedProductTable(const SessionResult& r) {
  Table t;
  t.name = "products_skipped";
  t.caption = "Session-level products not made";
  t.columns = {"Product", "Why"};
  for (const ProductRecord& p : r.products) {
    if (!p.made) t.rows.push_back({p.name, p.reason});
  }
  t.notes = {"Asked for with [products] in session.toml or reduce --products.KEY true."};
  return t;
}

Table ReboundAnomalyTable(const SessionResult& r) {
  Table t;
  t.name = "rebound_anomalies";
  t.caption = "Rebounds the free pendulum cannot explain (marked, not dropped)";
  t.columns = {"Run", "Anomaly"};
  for (const RunResult& run : r.runs) {
    for (const std::string& a : run.anomalies) t.rows.push_back({run.id, a});
  }
  t.notes = {
      "A rebound whose maximum exceeds its predecessor's, or whose duration departs from "
      "the pendulum's half period at its amplitude, by more than 3 combined sigma: the "
      "swing was disturbed (support wires, a second contact) or misread."};
  return t;
}

Table ContactLawTable(const std::vector<ContactLawFit>& laws) {
  Table t;
  t.name = "contact_laws";
  t.caption = "Contact laws fitted across the runs: maxima and the runs' own contact times";
  t.columns = {"Law",         "k",   "chi2 maxima",     "chi2 contact",     "dof",
               "Birge ratio", "BIC", "LOO rms / sigma", "What the data fix"};
  for (const ContactLawFit& fit : laws) {
    if (!fit.ok && fit.maxima == 0) {
      t.rows.push_back({fit.law + " (failed)", "-", "-", "-", "-", "-", "-", "-", fit.reason});
      continue;
    }
    t.rows.push_back({fit.law + (fit.ok ? "" : " (failed)"), Count(fit.parameter_count),
                      Sig(fit.chi2_maxima, 4), Sig(fit.chi2_contact, 4), Count(fit.dof),
                      Sig(fit.scatter.birge_ratio, 3), Sig(fit.bic, 5),
                      fit.loo_ok ? Sig(fit.loo_rms_normalized, 4) : Cell("-"),
                      fit.ok ? fit.identifiability : fit.reason});
  }
  t.notes = {
      "Each law predicts every impact's e and contact time from its speed; a run's "
      "maxima follow impact by impact. Birge ratio sqrt(chi2/dof). The fitted parameters "
      "are in table contact_law_parameters."};
  return t;
}

// The laws' parameters, one row per law and parameter: the value with its
// stated and scaled errors, and the 68 % interval where it comes from the
// chi2 profile.
Table ContactLawParameterTable(const std::vector<ContactLawFit>& laws, const UnitLabels& u) {
  Table t;
  t.name = "contact_law_parameters";
  t.caption = "Contact laws: the fitted parameters";
  t.columns = {
      "Law",  "Parameter", "Value", "Scaled std error", "Profile 68 % low", "Profile 68 % high",
      "Units"};
  bool at_bound = false;
  std::vector<std::string> unidentifiable;
  for (const ContactLawFit& fit : laws) {
    if (!fit.ok && fit.maxima == 0) continue;
    for (std::size_t i = 0; i < fit.parameters.size(); ++i) {
      const NamedEstimate& p = fit.parameters[i];
      const ParameterInterval* in =
          i < fit.intervals.size() && fit.intervals[i].profile ? &fit.intervals[i] : nullptr;
      std::string name = p.name;
      if (in != nullptr && in->at_bound) {
        name += " (interval at a bound)";
        at_bound = true;
      }
      t.rows.push_back(
          {fit.law, name, WithSigma(p.estimate, 4), ScaledSigma(p.estimate, fit.scatter.Scale()),
           in != nullptr ? Sig(in->lower, 4) : Cell("-"),
           in != nullptr ? Sig(in->upper, 4) : Cell("-"), Cell::Unit(UnitOfKind(p.units, u))});
    }
    // The material constant k holds where the specimen's ends make it identifiable.
    if (fit.effective_modulus) {
      t.rows.push_back({fit.law, "effective_modulus (E* = 3k/(8 sqrt(R)))",
                        WithSigma(*fit.effective_modulus, 0),
                        ScaledSigma(*fit.effective_modulus, fit.scatter.Scale()), "-", "-",
                        Cell::Unit(u.pressure)});
    }
    if (fit.handbook_effective_modulus) {
      t.rows.push_back({fit.law, "handbook_effective_modulus (E/(2(1 - nu^2)))",
                        Sig(*fit.handbook_effective_modulus, 4), "-", "-", "-",
                        Cell::Unit(u.pressure)});
    }
    if (!fit.effective_modulus_unidentifiable.empty()) {
      unidentifiable.push_back(fmt::format("{}: E* not identifiable: {}.", fit.law,
                                           fit.effective_modulus_unidentifiable));
    }
  }
  t.notes = {
      "± the stated standard error; \"scaled\": times the Birge ratio where chi2 is "
      "significantly high (p < 0.001). \"Profile 68 %\": where chi2 is not quadratic over "
      "±1 sigma, the interval from the chi2 profile."};
  t.notes.insert(t.notes.end(), unidentifiable.begin(), unidentifiable.end());
  if (at_bound) t.notes.push_back("At a bound: an end of the interval stopped at n's bound.");
  return t;
}

Cell OptionalWithSigma(const std::optional<Estimate>& e, int digits) {
  return e ? WithSigma(*e, digits) : Cell("-");
}

// A log channel's flags in a few words each (its notes say more):
// signal/log_analysis.h writes the notes these begin with.
std::vector<std::string> ChannelFlags(const ChannelAnalysis& c) {
  const auto noted = [&](std::string_view prefix) {
    return std::any_of(c.notes.begin(), c.notes.end(),
                       [&](const std::string& n) { return n.rfind(prefix, 0) == 0; });
  };
  std::vector<std::string> flags;
  if (!c.dominant_frequency_hz) {
    flags.push_back(noted("no oscillation") ? "no oscillation" : "no dominant frequency");
  }
  if (c.frequency_mismatch) flags.push_back("FFT/fit mismatch");
  if (noted("no spectral peak")) flags.push_back("no spectral peak");
  if (noted("ring-down fit:")) flags.push_back("ring-down fit caveat");
  return flags;
}

// One flag of one channel, and the sources that raise it.
struct ChannelFlag {
  std::string channel, flag;
  std::vector<std::string> sources;
};

// Every channel's flags, in the experiment's channel order.
std::vector<ChannelFlag> LogFlags(const LogResult& log) {
  std::vector<ChannelFlag> out;
  if (log.sources.empty()) return out;
  for (const ChannelAnalysis& first : log.sources.front().channels) {
    const std::size_t begin = out.size();
    for (const LogSourceResult& s : log.sources) {
      for (const ChannelAnalysis& c : s.channels) {
        if (c.name != first.name) continue;
        for (const std::string& flag : ChannelFlags(c)) {
          const auto at = std::find_if(out.begin() + static_cast<std::ptrdiff_t>(begin), out.end(),
                                       [&](const ChannelFlag& f) { return f.flag == flag; });
          if (at == out.end()) {
            out.push_back({c.name, flag, {s.source}});
          } else {
            at->sources.push_back(s.source);
          }
        }
      }
    }
  }
  return out;
}

// "both", or the sources named ("simulation"); nothing for a log of one source.
std::string SourcesText(const std::vector<std::string>& sources, const LogResult& log) {
  if (log.sources.size() < 2) return "";
  if (sources.size() == log.sources.size()) return "both";
  std::string text;
  for (const std::string& s : sources) text += (text.empty() ? "" : ", ") + s;
  return text;
}

// What the impact offset compares: one channel in both sources, or which.
std::string OffsetBasis(const LogResult& log) {
  if (!log.comparison) return "";
  if (!log.comparison->impact_channel.empty()) return log.comparison->impact_channel + " in both";
  if (log.sources.size() < 2) return "";
  return fmt::format(
      "different channels: {} in the experiment, {} in the simulation (no channel found the "
      "impact in both)",
      log.sources[0].impact_method, log.sources[1].impact_method);
}

Cell FrequencyCell(const ChannelAnalysis* c) {
  if (c == nullptr) return "-";
  return c->dominant_frequency_hz ? WithSigma(*c->dominant_frequency_hz, 4) : Cell("none");
}

Table LogTable(const LogResult& log) {
  Table t;
  t.name = FileSafeName("log_" + log.id);
  t.caption = fmt::format(
      "Log {}: dominant frequencies and damping, experiment against "
      "simulation",
      log.id);
  t.columns = {"Channel",
               "Experiment f (Hz)",
               "Simulation f (Hz)",
               "Difference (Hz)",
               "Difference (%)",
               "Experiment zeta",
               "Simulation zeta",
               "RMS difference (aligned)",
               "Units",
               "Flags"};
  const auto channel_of = [&](const std::string& source,
                              const std::string& name) -> const ChannelAnalysis* {
    for (const LogSourceResult& s : log.sources) {
      if (s.source != source) continue;
      for (const ChannelAnalysis& c : s.channels) {
        if (c.name == name) return &c;
      }
    }
    return nullptr;
  };
  const std::vector<ChannelFlag> flags = LogFlags(log);
  for (const LogSourceResult& s : log.sources) {
    if (s.source != "experiment") continue;
    for (const ChannelAnalysis& c : s.channels) {
      const ChannelAnalysis* sim = channel_of("simulation", c.name);
      const ChannelComparison* row = nullptr;
      if (log.comparison) {
        for (const ChannelComparison& r : log.comparison->channels) {
          if (r.channel == c.name) row = &r;
        }
      }
      const bool compared = row != nullptr;
      // A channel with a dominant frequency in one source only has no
      // difference (NaN in the results file): a dash, not "+nan".
      const bool differed = compared && std::isfinite(row->frequency_difference_hz);
      std::string flagged;
      for (const ChannelFlag& f : flags) {
        if (f.channel != c.name) continue;
        const std::string sources = SourcesText(f.sources, log);
        flagged +=
            (flagged.empty() ? "" : "; ") + f.flag + (sources.empty() ? "" : " (" + sources + ")");
      }
      t.rows.push_back({c.name, FrequencyCell(&c), sim ? FrequencyCell(sim) : Cell("-"),
                        differed ? Signed(row->frequency_difference_hz, 3) : Cell("-"),
                        differed ? Signed(row->frequency_difference_percent, 2) : Cell("-"),
                        OptionalWithSigma(c.damping_ratio, 4),
                        sim ? OptionalWithSigma(sim->damping_ratio, 4) : Cell("-"),
                        compared ? Sig(row->rms_difference, 4) : Cell("-"), Cell::Unit(c.units),
                        flagged});
    }
  }
  t.notes = {
      "f: the damped frequency of the ring-down's oscillating mode nearest its FFT peak; "
      "\"none\": no fitted mode oscillates (fewer than one period while its amplitude falls "
      "by e), so the channel has no dominant frequency and is not compared.",
      fmt::format("Flags: FFT/fit mismatch (the ring-down's FFT peak and the fitted frequency "
                  "disagree beyond their errors), no spectral peak above the noise, a caveat of "
                  "the ring-down fit; each in words in table {}. The impact instants and their "
                  "offset are in table {}.",
                  FileSafeName("log_" + log.id + "_notes"),
                  FileSafeName("log_" + log.id + "_impact"))};
  return t;
}

Table LogImpactTable(const LogResult& log) {
  Table t;
  t.name = FileSafeName("log_" + log.id + "_impact");
  t.caption = fmt::format("Log {}: the impact instants and their offset", log.id);
  t.columns = {"Source", "Impact time (s)", "Found by"};
  for (const LogSourceResult& s : log.sources) {
    t.rows.push_back({s.source, s.impact_time_s ? WithSigma(*s.impact_time_s, 5) : "not found",
                      s.impact_method});
  }
  if (log.comparison && !log.comparison->impact_channel.empty()) {
    // The instants compared, where they are not a source's own.
    const LogComparison& c = *log.comparison;
    const std::optional<Estimate>* compared[] = {&c.experiment_impact_s, &c.simulation_impact_s};
    for (std::size_t k = 0; k < log.sources.size() && k < 2; ++k) {
      const LogSourceResult& s = log.sources[k];
      if (!*compared[k] || s.impact_method == c.impact_channel) continue;
      t.rows.push_back({s.source + ", compared", WithSigma(**compared[k], 5), c.impact_channel});
    }
  }
  if (log.comparison && log.comparison->impact_offset_s) {
    t.rows.push_back({"simulation - experiment", WithSigma(*log.comparison->impact_offset_s, 5),
                      OffsetBasis(log)});
  }
  t.notes = {
      "Each source's own instant is its strongest jump's, which places its post-impact "
      "segment. The instants compared are one channel's in both sources, where a channel found "
      "the impact in both: the accelerometer whose jump is strongest in the weaker source (else "
      "an encoder); a source whose own instant is another channel's has a row \"compared\" "
      "too. The offset aligns the histories for the RMS differences."};
  return t;
}

Table LogNotesTable(const LogResult& log) {
  Table t;
  t.name = FileSafeName("log_" + log.id + "_notes");
  t.caption = fmt::format("Log {}: what the analysis noted, channel by channel", log.id);
  t.columns = {"Channel", "Source", "Note"};
  if (log.sources.empty()) return t;
  for (const ChannelAnalysis& first : log.sources.front().channels) {
    for (const LogSourceResult& s : log.sources) {
      for (const ChannelAnalysis& c : s.channels) {
        if (c.name != first.name) continue;
        for (const std::string& note : c.notes) t.rows.push_back({c.name, s.source, note});
      }
    }
  }
  return t;
}

Table StiffnessTable(const SessionKelvinVoigt& s, const UnitLabels& u) {
  Table t;
  t.name = "table3_stiffness";
  t.caption = "Values of K versus sqrt(xi) (thesis Table 3)";
  t.columns = {"Run", "sqrt(xi)", fmt::format("K ({})", u.stiffness),
               fmt::format("Delta K ({})", u.stiffness), "% variation"};
  std::vector<std::size_t> order(s.run_ids.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return s.sqrt_restitution[a] < s.sqrt_restitution[b];
  });
  for (std::size_t i : order) {
    t.rows.push_back({s.run_ids[i], Fixed(s.sqrt_restitution[i], 4), Fixed(s.stiffness[i], 0),
                      Signed(s.spread.deviation[i], 0), Fixed(s.spread.pct_variation[i], 2)});
    t.row_kinds.push_back("run");
  }
  t.rows.push_back({"K avg", "", Fixed(s.spread.average, 0), "", ""});
  t.row_kinds.push_back("average");
  t.notes = {"xi is the run's fitted coefficient of restitution e; Delta K = K - K avg."};
  return t;
}

Table DampingLineTable(const SessionKelvinVoigt& s, const UnitLabels& u) {
  Table t;
  t.name = "eq40_damping_line";
  t.caption = "C versus sqrt(xi): least-squares line C = a (1 - b sqrt(xi)) (thesis eq. 40)";
  t.columns = {"Quantity", "Value", "Standard error", "Units"};
  const DampingLine& line = *s.damping_line;
  t.rows = {{"a", Sig(line.a.value, 6), Sig(line.a.sigma, 3), Cell::Unit(u.damping)},
            {"b", Sig(line.b.value, 6), Sig(line.b.sigma, 3), "1"},
            {"correlation(a, b)", Fixed(line.correlation_ab, 4), "", "1"},
            {"rms residual", Sig(line.rms_residual, 4), "", Cell::Unit(u.damping)},
            {"runs", Count(line.points), "", ""}};
  t.notes = {s.average_stiffness ? "C from the session's average K." : "C from each run's own K."};
  return t;
}

Table PredictionTable(const RunPrediction& p, const UnitLabels& u) {
  Table t;
  t.name = FileSafeName(fmt::format("table4_prediction_{}_from_{}", p.target_run, p.source_run));
  t.caption = fmt::format(
      "Predicted (from run {}) and calculated theoretical response for run {} (thesis Table 4)",
      p.source_run, p.target_run);
  t.columns = {"Rebound",
               fmt::format("Predicted Xmax ({})", u.length),
               fmt::format("Calculated Xmax ({})", u.length),
               fmt::format("Deviation ({})", u.length),
               "Deviation % peak",
               "Deviation % X0"};
  for (std::size_t i = 0; i < p.predicted.size(); ++i) {
    t.rows.push_back({Count(p.start_rebound + static_cast<long long>(i)), Fixed(p.predicted[i], 4),
                      Fixed(p.calculated[i], 4), Signed(p.deviation[i], 4),
                      Fixed(std::abs(p.pct_peak[i]), 1), Fixed(std::abs(p.pct_start[i]), 1)});
  }
  t.notes = {fmt::format("X0 here is the starting maximum, rebound {} = {} {}.", p.start_rebound,
                         Fixed(p.start_xmax, 4).text, u.length)};
  return t;
}

// Whether `text` names run `id`: as run "ID", or run ID followed by a space,
// a colon, a comma or its end.
bool NamesRun(const std::string& text, const std::string& id) {
  if (text.find("run \"" + id + "\"") != std::string::npos) return true;
  const std::string plain = "run " + id;
  for (std::size_t at = text.find(plain); at != std::string::npos; at = text.find(plain, at + 1)) {
    const std::size_t next = at + plain.size();
    if (next == text.size() || std::string(" :,;").find(text[next]) != std::string::npos) {
      return true;
    }
  }
  return false;
}

// "a, b and c".
std::string JoinedList(const std::vector<std::string>& items) {
  std::string text;
  for (std::size_t i = 0; i < items.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == items.size() ? " and " : ", ") + items[i];
  }
  return text;
}

// A least-squares fit as the check list weighs it: named ("run 0.405", "the
// joint fit"), with its status, scatter and identifiability.
struct CheckedFit {
  std::string name;
  bool ok;
  const std::string& reason;
  const ScatterCheck& scatter;
  const Identifiability& identifiability;
};

template <typename Fit>
CheckedFit Checked(std::string name, const Fit& fit) {
  return {std::move(name), fit.ok, fit.reason, fit.scatter, fit.identifiability};
}

// The least-squares fits of one model (per run, and the joint fit): failures
// one by one, excess scatter and undetermined parameters each in one item.
void CheckLeastSquares(const std::vector<CheckedFit>& fits, const std::string& label,
                       const std::string& table, std::vector<CheckItem>& items) {
  std::vector<std::string> scattered, undetermined;
  double widest = 0.0;
  for (const CheckedFit& fit : fits) {
    const Identifiability& id = fit.identifiability;
    if (!fit.ok && id.message.empty()) {
      items.push_back({fmt::format("{}: {} failed: {}", fit.name, label, fit.reason), table, ""});
      continue;
    }
    if (fit.scatter.excess) {
      scattered.push_back(fit.name);
      widest = std::max(widest, fit.scatter.birge_ratio);
    }
    if (!id.identifiable && !id.message.empty()) undetermined.push_back(fit.name);
  }
  // Every fit, or the ones named.
  const auto which = [&](const std::vector<std::string>& names) {
    return names.size() == fits.size() && names.size() > 1
               ? fmt::format("all {} fits", names.size())
               : JoinedList(names);
  };
  if (!scattered.empty()) {
    items.push_back({fmt::format("{}: the maxima scatter more than their stated errors allow in "
                                 "{} (Birge ratio up to {:.3g}): scale the ± by it",
                                 label, which(scattered), widest),
                     table, ""});
  }
  if (!undetermined.empty()) {
    items.push_back({fmt::format("{}: the data do not determine every parameter in {}: quote "
                                 "only the combinations the table gives",
                                 label, which(undetermined)),
                     table, ""});
  }
}

// A log's flags in words, one item per kind of flag.
void CheckLog(const LogResult& log, std::vector<CheckItem>& items) {
  const std::string section = "log-" + log.id;
  if (!log.ok) {
    items.push_back({fmt::format("log {} failed: {}", log.id, log.reason), "", section});
    return;
  }
  const std::string table = FileSafeName("log_" + log.id);
  const std::string impact_table = FileSafeName("log_" + log.id + "_impact");
  static const std::pair<const char*, const char*> kSentences[] = {
      {"no oscillation", "no oscillation, so no dominant frequency, on"},
      {"no dominant frequency", "no dominant frequency on"},
      {"FFT/fit mismatch", "the FFT peak and the fitted frequency disagree on"},
      {"no spectral peak", "no spectral peak above the noise (the fitted mode is used) on"},
      {"ring-down fit caveat", "the ring-down fit has a caveat (see the notes) on"}};
  const std::vector<ChannelFlag> flags = LogFlags(log);
  for (const auto& [flag, sentence] : kSentences) {
    std::vector<std::string> where;
    for (const ChannelFlag& f : flags) {
      if (f.flag != flag) continue;
      const std::string sources = SourcesText(f.sources, log);
      where.push_back(f.channel + (sources.empty() ? "" : " (" + sources + ")"));
    }
    if (!where.empty()) {
      items.push_back(
          {fmt::format("log {}: {} {}", log.id, sentence, JoinedList(where)), table, ""});
    }
  }
  for (const LogSourceResult& s : log.sources) {
    if (!s.impact_time_s) {
      items.push_back(
          {fmt::format("log {}: no impact found in the {}: {}", log.id, s.source, s.impact_method),
           impact_table, ""});
    }
  }
  if (log.comparison && log.comparison->impact_offset_s) {
    const std::string basis = OffsetBasis(log);
    if (basis.rfind("different channels", 0) == 0) {
      items.push_back(
          {fmt::format("log {}: the impact offset compares {}", log.id, basis), impact_table, ""});
    }
  }
}

Table CheckTable(const std::vector<CheckItem>& items) {
  Table t;
  t.name = "check_these";
  t.caption = "Check these: every failure, warning and flag, and where it applies";
  t.columns = {"Check", "Where"};
  for (const CheckItem& item : items) {
    // The item itself leads to its run's or log's section (HTML), the
    // "Where" to its table (every format but CSV).
    Cell check(item.text);
    check.link = item.section;
    Cell where = item.table.empty() ? Cell("-") : Cell(item.table);
    if (!item.table.empty()) where.link = "table-" + item.table;
    t.rows.push_back({check, where});
  }
  if (t.rows.empty()) {
    t.rows.push_back(
        {"Nothing: no run, log or prediction failed, and nothing was flagged or "
         "warned of.",
         "-"});
  }
  return t;
}

std::string Join(const std::vector<std::string>& cells, const std::string& separator,
                 std::string (*escape)(const std::string&)) {
  std::string out;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i > 0) out += separator;
    out += escape ? escape(cells[i]) : cells[i];
  }
  return out;
}

// Which columns have a cell with `part` set in some row.
std::vector<bool> ColumnsHolding(const Table& t, std::optional<double> Cell::*part) {
  std::vector<bool> holding(t.columns.size(), false);
  for (const auto& row : t.rows) {
    for (std::size_t c = 0; c < row.size() && c < holding.size(); ++c) {
      if (row[c].*part) holding[c] = true;
    }
  }
  return holding;
}

// Which columns carry standard errors (CSV gives them a column of their own).
std::vector<bool> ColumnsWithSigma(const Table& t) { return ColumnsHolding(t, &Cell::sigma); }

// Which columns hold a number in some row (CSV writes no text there).
std::vector<bool> NumericColumns(const Table& t) { return ColumnsHolding(t, &Cell::value); }

std::string FullPrecision(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{}", v);  // the shortest text that reads back to v exactly
}

// The text cells of a row, each as its format writes it: escaped, and a
// cell that points to a table linked (Markdown, HTML) or referenced (LaTeX).
std::vector<std::string> RenderedCells(const std::vector<Cell>& row, ReportFormat format) {
  std::vector<std::string> cells;
  for (const Cell& cell : row) {
    const bool to_table = cell.link.rfind("table-", 0) == 0;
    switch (format) {
      case ReportFormat::kMarkdown:
        cells.push_back(to_table ? fmt::format("[{}](#{})", EscapeMarkdown(cell.text), cell.link)
                                 : EscapeMarkdown(cell.text));
        break;
      case ReportFormat::kHtml:
        cells.push_back(!cell.link.empty()
                            ? fmt::format("<a href=\"#{}\">{}</a>", EscapeHtml(cell.link),
                                          EscapeHtml(cell.text))
                            : EscapeHtml(cell.text));
        break;
      case ReportFormat::kLatex:  // not used: LatexTable writes its own cells
      case ReportFormat::kCsv:
        cells.push_back(EscapeCsv(cell.text));
        break;
    }
  }
  return cells;
}

}  // namespace

std::vector<CheckItem> CheckList(const SessionResult& r) {
  std::vector<CheckItem> items;
  for (const RunResult& run : r.runs) {
    if (!run.ok) {
      items.push_back({fmt::format("run {} failed: {}", run.id, run.reason),
                       "kelvin_voigt_parameters", "run-" + run.id});
    }
  }
  for (const LogResult& log : r.logs) {
    if (!log.ok) CheckLog(log, items);
  }
  // Warnings: the manifest's, skipped calibrations and predictions (a
  // prediction skipped has no Table 4), and the reduction's findings.
  for (const std::string& w : r.warnings) {
    CheckItem item{"warning: " + w, "", ""};
    for (const RunResult& run : r.runs) {
      if (NamesRun(w, run.id)) {
        item.section = "run-" + run.id;
        break;
      }
    }
    items.push_back(item);
  }
  for (const RunResult& run : r.runs) {
    if (!run.anomalies.empty()) {
      items.push_back({fmt::format("run {}: {} rebound(s) the free pendulum cannot explain", run.id,
                                   run.anomalies.size()),
                       "rebound_anomalies", ""});
    }
  }
  std::vector<CheckedFit> kelvin_voigt, poynting_thomson;
  for (const RunResult& run : r.runs) {
    if (const auto& fit = run.fits.kelvin_voigt_least_squares) {
      kelvin_voigt.push_back(Checked("run " + run.id, *fit));
    }
    if (const auto& fit = run.fits.poynting_thomson) {
      poynting_thomson.push_back(Checked("run " + run.id, *fit));
    }
  }
  for (const PoyntingThomsonLeastSquaresFit& fit : r.joint_fits) {
    poynting_thomson.push_back(Checked("the joint fit", fit));
  }
  CheckLeastSquares(kelvin_voigt, "Kelvin-Voigt least squares", "kelvin_voigt_least_squares",
                    items);
  CheckLeastSquares(poynting_thomson, "Poynting-Thomson", "poynting_thomson", items);
  if (r.model_comparison) {
    const auto failed = [&](const std::string& model, bool ok, const std::string& reason) {
      if (!ok) {
        items.push_back({fmt::format("model comparison: {} failed: {}", model, reason),
                         "model_comparison", ""});
      }
    };
    for (const ComparedRestitutionModel& m : r.model_comparison->restitution_models) {
      failed(m.fit.name, m.fit.ok, m.fit.reason);
    }
    for (const ComparedContactLaw& m : r.model_comparison->contact_laws) {
      failed(m.fit.law, m.fit.ok, m.fit.reason);
    }
  }
  std::vector<std::string> scattered;
  double widest = 0.0;
  for (const ContactLawFit& fit : r.contact_laws) {
    if (!fit.ok) {
      items.push_back(
          {fmt::format("contact law {} failed: {}", fit.law, fit.reason), "contact_laws", ""});
    } else if (fit.scatter.excess) {
      scattered.push_back(fit.law);
      widest = std::max(widest, fit.scatter.birge_ratio);
    }
  }
  if (!scattered.empty()) {
    items.push_back({fmt::format("contact laws: the data scatter more than their stated errors "
                                 "allow for {} (Birge ratio up to {:.3g}): scale the ± by it",
                                 JoinedList(scattered), widest),
                     "contact_laws", ""});
  }
  for (const LogResult& log : r.logs) {
    if (log.ok) CheckLog(log, items);
  }
  return items;
}

std::vector<Table> BuildTables(const SessionResult& r) {
  const UnitLabels u = LabelsFor(r.units);
  std::vector<Table> tables;
  if (!r.runs.empty()) tables = {DeviationTable(r, u), ParameterTable(r, u)};
  const bool any_least_squares =
      std::any_of(r.runs.begin(), r.runs.end(), [](const RunResult& run) {
        return run.fits.kelvin_voigt_least_squares || run.fits.poynting_thomson;
      });
  if (any_least_squares) {
    tables.push_back(KelvinVoigtLeastSquaresTable(r, u));
    tables.push_back(PoyntingThomsonTable(r, u));
  }
  if (r.kelvin_voigt) {
    tables.push_back(StiffnessTable(*r.kelvin_voigt, u));
    if (r.kelvin_voigt->damping_line) tables.push_back(DampingLineTable(*r.kelvin_voigt, u));
  }
  if (r.model_comparison) {
    tables.push_back(ModelComparisonTable(*r.model_comparison, u));
    tables.push_back(ModelParameterTable(*r.model_comparison, u));
  }
  if (!r.contact_laws.empty()) {
    tables.push_back(ContactLawTable(r.contact_laws));
    tables.push_back(ContactLawParameterTable(r.contact_laws, u));
  }
  if (std::any_of(r.products.begin(), r.products.end(),
                  [](const ProductRecord& p) { return !p.made; })) {
    tables.push_back(SkippedProductTable(r));
  }
  tables.push_back(ReboundAnomalyTable(r));
  for (const RunPrediction& p : r.predictions) tables.push_back(PredictionTable(p, u));
  for (const LogResult& log : r.logs) {
    if (!log.ok) continue;
    tables.push_back(LogTable(log));
    tables.push_back(LogImpactTable(log));
    tables.push_back(LogNotesTable(log));
  }
  // A logs-only or calibration-only result has no rows for the runs' tables.
  std::erase_if(tables, [](const Table& t) { return t.rows.empty(); });
  // The list first; its links only to tables the report has.
  std::vector<CheckItem> items = CheckList(r);
  for (CheckItem& item : items) {
    if (std::none_of(tables.begin(), tables.end(),
                     [&](const Table& t) { return t.name == item.table; })) {
      item.table.clear();
    }
  }
  tables.insert(tables.begin(), CheckTable(items));
  return tables;
}

std::vector<std::string> TidyColumns(const Table& t) {
  const std::vector<bool> with_sigma = ColumnsWithSigma(t);
  std::vector<std::string> columns;
  if (!t.row_kinds.empty()) columns.push_back("row_kind");
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    columns.push_back(t.columns[c]);
    if (with_sigma[c]) columns.push_back(t.columns[c] + " std_error");
  }
  return columns;
}

std::vector<std::vector<std::string>> TidyRows(const Table& t) {
  const std::vector<bool> with_sigma = ColumnsWithSigma(t);
  const std::vector<bool> numeric = NumericColumns(t);
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const auto& row = t.rows[i];
    std::vector<std::string> cells;
    // A summary row says what it is in row_kind; its label ("K avg") is no
    // value of the first column (a run's id).
    const bool summary =
        !t.row_kinds.empty() && i < t.row_kinds.size() && t.row_kinds[i] != t.row_kinds.front();
    if (!t.row_kinds.empty()) cells.push_back(i < t.row_kinds.size() ? t.row_kinds[i] : "");
    for (std::size_t c = 0; c < row.size(); ++c) {
      const Cell& cell = row[c];
      if (c == 0 && summary) {
        cells.push_back("");
        continue;
      }
      // Text in a number's column ("none", "not found") is no value there.
      const bool no_value = cell.text == "-" || (c < numeric.size() && numeric[c]);
      cells.push_back(cell.value ? FullPrecision(*cell.value) : no_value ? "" : cell.text);
      if (c < with_sigma.size() && with_sigma[c]) {
        cells.push_back(cell.sigma ? FullPrecision(*cell.sigma) : cell.value ? "0" : "");
      }
    }
    rows.push_back(std::move(cells));
  }
  return rows;
}

std::optional<ReportFormat> ParseReportFormat(const std::string& name) {
  if (name == "md") return ReportFormat::kMarkdown;
  if (name == "csv") return ReportFormat::kCsv;
  if (name == "tex") return ReportFormat::kLatex;
  if (name == "html") return ReportFormat::kHtml;
  return std::nullopt;
}

std::string RenderTable(const Table& t, ReportFormat format) {
  std::string out;
  switch (format) {
    case ReportFormat::kCsv:
      out += Join(TidyColumns(t), ",", EscapeCsv) + "\n";
      for (const auto& row : TidyRows(t)) out += Join(row, ",", EscapeCsv) + "\n";
      return out;
    case ReportFormat::kMarkdown:
      // The anchor is the report's own (a table name is file-safe): what the
      // check list links to.
      out += fmt::format("### <a id=\"table-{}\"></a>{}\n\n| {} |\n|", t.name,
                         EscapeMarkdown(t.caption), Join(t.columns, " | ", EscapeMarkdown));
      // Numbers right-aligned, texts (the first column, notes, flags) left.
      for (std::size_t i = 0; i < t.columns.size(); ++i) {
        out += i > 0 && NumericColumns(t)[i] ? " ---: |" : " :--- |";
      }
      out += "\n";
      for (const auto& row : t.rows) {
        out += fmt::format("| {} |\n", Join(RenderedCells(row, format), " | ", nullptr));
      }
      for (const auto& note : t.notes) out += fmt::format("\n{}\n", EscapeMarkdown(note));
      return out + "\n";
    case ReportFormat::kHtml: {
      // Numbers right-aligned (class "num"), texts left.
      const std::vector<bool> numeric = NumericColumns(t);
      const auto open = [&](const char* tag, std::size_t c) {
        return fmt::format("<{}{}>", tag, c > 0 && numeric[c] ? " class=\"num\"" : "");
      };
      out += fmt::format("<table id=\"table-{}\">\n<caption>{}</caption>\n<thead><tr>", t.name,
                         EscapeHtml(t.caption));
      for (std::size_t c = 0; c < t.columns.size(); ++c) {
        out += open("th", c) + EscapeHtml(t.columns[c]) + "</th>";
      }
      out += "</tr></thead>\n<tbody>\n";
      for (std::size_t i = 0; i < t.rows.size(); ++i) {
        // The summary rows (K avg, the joint fit) set apart.
        const bool summary =
            !t.row_kinds.empty() && i < t.row_kinds.size() && t.row_kinds[i] != t.row_kinds.front();
        out += summary ? "<tr class=\"summary\">" : "<tr>";
        const std::vector<std::string> cells = RenderedCells(t.rows[i], format);
        for (std::size_t c = 0; c < cells.size(); ++c) {
          out += open("td", c) + cells[c] + "</td>";
        }
        out += "</tr>\n";
      }
      out += "</tbody>\n</table>\n";
      for (const auto& note : t.notes) {
        out += fmt::format("<p class=\"note\">{}</p>\n", EscapeHtml(note));
      }
      if (!t.details.empty()) {
        out += "<details><summary>Details</summary>\n";
        for (const auto& text : t.details) {
          out += fmt::format("<p class=\"note\">{}</p>\n", EscapeHtml(text));
        }
        out += "</details>\n";
      }
      return out;
    }
    case ReportFormat::kLatex:
      return LatexTable(t);
  }
  return out;
}

std::string RenderTables(const std::string& title, const std::vector<Table>& tables,
                         ReportFormat format) {
  std::string out;
  // The title is the user's: escaped like every other string (in LaTeX it is
  // a % comment, which a newline in it must not end).
  if (format == ReportFormat::kMarkdown) out += fmt::format("# {}\n\n", EscapeMarkdown(title));
  if (format == ReportFormat::kLatex) {
    out += fmt::format("% {}\n% Needs in the preamble:\n", EscapeLatex(title));
    const std::string packages = kLatexPackages;
    for (std::size_t at = 0, end; (end = packages.find('\n', at)) != std::string::npos;
         at = end + 1) {
      out += "%   " + packages.substr(at, end - at) + "\n";
    }
  }
  for (Table t : tables) {
    // A link to a table left out (report --table) would lead nowhere.
    for (auto& row : t.rows) {
      for (Cell& cell : row) {
        if (cell.link.rfind("table-", 0) == 0 &&
            std::none_of(tables.begin(), tables.end(),
                         [&](const Table& u) { return "table-" + u.name == cell.link; })) {
          cell.link.clear();
        }
      }
    }
    if (format == ReportFormat::kCsv) {
      out += fmt::format("{}\n{}\n", CsvComment(fmt::format("# {}: {}", t.name, t.caption)),
                         RenderTable(t, format));
    } else {
      out += RenderTable(t, format);
    }
  }
  return out;
}

}  // namespace impactlab
