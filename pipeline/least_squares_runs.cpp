#include "pipeline/least_squares_runs.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>

#include <fmt/format.h>

#include "fit/contact_law_fit.h"
#include "fit/joint_fits.h"
#include "fit/kelvin_voigt_least_squares.h"
#include "fit/poynting_thomson_least_squares.h"
#include "model/power_law_contact.h"

namespace impactlab {
namespace {

// The run's observations as the fits take them. Every observation of a fit
// must carry an uncertainty, or none: a contact time without one is left out
// when the maxima have theirs (it would weigh arbitrarily against them).
PoyntingThomsonRun AsPoyntingThomsonRun(const Pendulum& pendulum, const std::string& id,
                                        const ReboundMeasurements& fitted) {
  PoyntingThomsonRun out{id, pendulum, {}, std::nullopt};
  out.measured.xmax = fitted.xmax;
  out.measured.xmax_sigma = fitted.xmax_sigma;
  const bool weighted = !fitted.xmax_sigma.empty() && fitted.xmax_sigma.front() > 0.0;
  if (fitted.contact_time && (fitted.contact_time_sigma > 0.0) == weighted) {
    out.measured.contact_time = fitted.contact_time;
    out.measured.contact_time_sigma = fitted.contact_time_sigma;
  }
  if (!weighted) out.measured.xmax_sigma.clear();
  return out;
}

// Where Poynting-Thomson starts when no contact time enters its fit (the
// maxima alone fix no time scale): the run's Kelvin-Voigt K and C, with K2 = 10 K.
std::optional<PoyntingThomson> StartFromKelvinVoigt(const RunFits& fits, double mass) {
  if (!fits.kelvin_voigt || !fits.kelvin_voigt->stiffness) return std::nullopt;
  const double k = fits.kelvin_voigt->stiffness->value;
  return PoyntingThomson{mass, k, 10.0 * k, std::max(fits.kelvin_voigt->damping->value, 1e-9 * k)};
}

}  // namespace

void FitRunLeastSquares(const Pendulum& pendulum, double mass, Separation separation,
                        const FitOptions& fit, const std::string& run_id, RunFits& fits) {
  ReboundMeasurements measured = fits.fitted;
  if (!measured.xmax_sigma.empty() && measured.xmax_sigma.front() <= 0.0)
    measured.xmax_sigma.clear();
  // A fit refuses data it cannot take as a fit that did not run, with why.
  KelvinVoigtLeastSquaresOptions kelvin_voigt = fit.kelvin_voigt;
  kelvin_voigt.separation = separation;
  fits.kelvin_voigt_least_squares =
      FitKelvinVoigtLeastSquares(pendulum, mass, measured, kelvin_voigt);
  PoyntingThomsonLeastSquaresOptions poynting_thomson = fit.poynting_thomson;
  poynting_thomson.mass = mass;
  poynting_thomson.separation = separation;
  poynting_thomson.initial = StartFromKelvinVoigt(fits, mass);
  fits.poynting_thomson = FitPoyntingThomsonLeastSquares(
      {AsPoyntingThomsonRun(pendulum, run_id, fits.fitted)}, poynting_thomson);
}

std::vector<PoyntingThomsonLeastSquaresFit> FitSessionJointly(const Pendulum& pendulum, double mass,
                                                              Separation separation,
                                                              const FitOptions& fit,
                                                              const std::vector<RunResult>& runs) {
  std::vector<PoyntingThomsonRun> joint;
  for (const RunResult& run : runs) {
    if (run.ok && run.measured.xmax.size() >= 2) {
      joint.push_back(AsPoyntingThomsonRun(pendulum, run.id, run.fits.fitted));
    }
  }
  if (joint.size() < 2) return {};
  PoyntingThomsonLeastSquaresOptions options = fit.poynting_thomson;
  options.mass = mass;
  options.separation = separation;
  for (const RunResult& run : runs) {
    if (!options.initial && run.ok) options.initial = StartFromKelvinVoigt(run.fits, mass);
  }
  return {FitPoyntingThomsonLeastSquares(joint, options)};
}

namespace {

bool AllWeighted(const RunMeasurement& m) {
  return !m.xmax_sigma.empty() &&
         std::all_of(m.xmax_sigma.begin(), m.xmax_sigma.end(), [](double s) { return s > 0.0; });
}

// The runs the cross-run models use: reduced, two maxima or more, every one
// with an uncertainty.
std::vector<const RunResult*> ComparableRuns(const std::vector<RunResult>& runs) {
  std::vector<const RunResult*> out;
  for (const RunResult& run : runs) {
    if (run.ok && run.measured.xmax.size() >= 2 && AllWeighted(run.measured)) out.push_back(&run);
  }
  return out;
}

std::vector<LawRun> LawRunsOf(const LawInputs& in, const std::vector<const RunResult*>& runs) {
  std::vector<LawRun> out;
  for (const RunResult* run : runs) {
    LawRun r;
    r.name = run->id;
    r.pendulum = in.pendulum;
    r.mass = in.mass;
    r.initial_displacement = run->initial_displacement;
    r.measured.xmax = run->measured.xmax;
    r.measured.xmax_sigma = run->measured.xmax_sigma;
    const auto rebound = in.contact_rebounds.find(run->id);
    if (run->measured.contact_time && run->measured.contact_time_sigma > 0.0 &&
        rebound != in.contact_rebounds.end()) {
      r.measured.contact_time = run->measured.contact_time;
      r.measured.contact_time_sigma = run->measured.contact_time_sigma;
      r.contact_rebound = rebound->second;
    }
    out.push_back(std::move(r));
  }
  return out;
}

// The standard deviation of a contact law's ln e over the runs' fitted
// rebound-0 speeds: the spread a restitution model reports of its runs' ln e.
// Of the laws compared only Hunt-Crossley's e depends on the speed, e(chi v);
// elastic Hertz keeps e = 1, a spread of 0.
double LogRestitutionSpread(const ContactLawFit& fit) {
  if (!fit.ok || fit.law != "hunt-crossley" || fit.parameters.empty()) return 0.0;
  const double chi = fit.parameters.front().estimate.value;
  std::vector<double> q;
  for (const Estimate& v : fit.run_rebound0_speed) {
    q.push_back(std::log(HuntCrossleyRestitution(chi * v.value)));
  }
  double mean = 0.0, ss = 0.0;
  for (double x : q) mean += x / static_cast<double>(q.size());
  for (double x : q) ss += (x - mean) * (x - mean);
  return q.empty() ? 0.0 : std::sqrt(ss / static_cast<double>(q.size()));
}

// What the comparison judges each model by, whichever fit it is.
struct Judged {
  const std::string& model;
  bool ok;
  int maxima, parameter_count, dof;
  double chi2, loo_rms_normalized;
  std::string* verdict;
  const std::vector<NamedEstimate>& parameters;
};

std::vector<Judged> JudgedModels(ModelComparison& c) {
  std::vector<Judged> out;
  for (ComparedRestitutionModel& m : c.restitution_models) {
    const JointModelFit& f = m.fit;
    out.push_back({f.name, f.ok, f.maxima, f.parameter_count, f.dof, f.chi2,
                   f.leave_one_out.rms_normalized, &m.verdict, f.parameters});
  }
  for (ComparedContactLaw& m : c.contact_laws) {
    const ContactLawFit& f = m.fit;
    out.push_back({f.law, f.ok, f.maxima, f.parameter_count, f.dof, f.chi2, f.loo_rms_normalized,
                   &m.verdict, f.parameters});
  }
  return out;
}

const Judged* Row(const std::vector<Judged>& models, const std::string& model) {
  for (const Judged& m : models) {
    if (m.model == model && m.ok) return &m;
  }
  return nullptr;
}

const NamedEstimate* ParameterOf(const Judged& m, const std::string& name) {
  for (const NamedEstimate& p : m.parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

// The best by BIC and by leave-one-out, and every model's verdict. When the
// most general model (the most parameters) still shows excess scatter, the
// stated sigmas understate the reading errors: every chi^2 is divided by that
// model's chi^2/dof before the BIC is formed (the sigmas scaled by its Birge
// ratio, as an F-test would), so that understated errors do not turn small
// differences into rejections. Verdicts on the BIC difference from the best
// (Kass and Raftery): < 2 comparable, < 10 disfavoured, else rejected.
void Judge(ModelComparison& c, const std::vector<Judged>& models, bool leave_one_out) {
  const Judged* general = nullptr;
  const Judged* best_loo = nullptr;
  for (const Judged& m : models) {
    if (!m.ok) continue;
    if (!general || m.parameter_count > general->parameter_count) general = &m;
    if (!leave_one_out) continue;
    if (!best_loo || m.loo_rms_normalized < best_loo->loo_rms_normalized) best_loo = &m;
  }
  c.best_by_leave_one_out = best_loo ? best_loo->model : "";
  if (!general) return;
  const ScatterCheck scatter = CheckScatter(general->chi2, general->dof);
  const double scale = scatter.Scale() * scatter.Scale();
  const auto bic = [&](const Judged& m) {
    return m.chi2 / scale +
           m.parameter_count * std::log(static_cast<double>(std::max(1, m.maxima)));
  };
  const Judged* best = nullptr;
  for (const Judged& m : models) {
    if (m.ok && (!best || bic(m) < bic(*best))) best = &m;
  }
  c.best_by_bic = best->model;
  for (const Judged& m : models) {
    if (!m.ok) {
      *m.verdict = "failed";
      continue;
    }
    const double delta = bic(m) - bic(*best);
    const char* word = delta < 2.0 ? "comparable" : delta < 10.0 ? "disfavoured" : "rejected";
    *m.verdict = &m == best ? "best" : fmt::format("{} (dBIC = {:.3g})", word, delta);
  }
  if (scatter.excess) {
    c.evidence.push_back(fmt::format(
        "The most general model, {}, leaves chi2/dof = {:.3g}: the maxima' stated uncertainties "
        "understate their scatter by a factor {:.3g}, so the verdicts and the best by BIC use "
        "every chi2 divided by {:.3g}.",
        general->model, general->chi2 / general->dof, scatter.birge_ratio, scale));
  }
}

// What the speed dependence of e says about the laws: the data's slope of
// ln e against impact speed (linear-in-speed, its sigma scaled by its Birge
// ratio) against the slope Hunt-Crossley needs at these speeds.
void Evidence(ModelComparison& c, const std::vector<Judged>& models,
              const std::vector<const RunResult*>& runs, const Pendulum& pendulum) {
  const Judged* linear = Row(models, "linear-in-speed");
  const Judged* hc = Row(models, "hunt-crossley");
  const Judged* hertz = Row(models, "hertz");
  if (linear) {
    const NamedEstimate* b = ParameterOf(*linear, "b");
    if (b) {
      const double sigma = b->estimate.sigma * CheckScatter(linear->chi2, linear->dof).Scale();
      const double z = b->estimate.value / sigma;
      std::string sentence =
          fmt::format("ln e changes with impact speed by b = {:.3g} ± {:.2g} per unit speed ({}).",
                      b->estimate.value, sigma,
                      std::abs(z) < 2.0 ? "flat within 2 sigma"
                      : z < 0           ? "e falls as speed rises"
                                        : "e rises with speed");
      if (hc) {
        const NamedEstimate* chi = ParameterOf(*hc, "damping_factor");
        double mean_speed = 0.0;
        for (const RunResult* r : runs) {
          mean_speed += SpeedFromAmplitude(pendulum, r->measured.xmax.front()) / runs.size();
        }
        if (chi && mean_speed > 0.0) {
          // d ln e/dv = chi (de/deps)/e, de/deps = (gap/((1 + eps) e) - e)/eps.
          const double eps = chi->estimate.value * mean_speed;
          const double e = HuntCrossleyRestitution(eps);
          const double gap = 1.0 - eps * e;
          const double needed = chi->estimate.value * ((gap / ((1.0 + eps) * e) - e) / eps) / e;
          const double apart = std::abs(b->estimate.value - needed) / sigma;
          sentence += fmt::format(
              " Hunt-Crossley, whose e -> 1 as v -> 0, needs {:.3g} at the runs' mean speed "
              "{:.3g}: {}.",
              needed, mean_speed,
              apart > 3.0
                  ? fmt::format("{:.2g} sigma from the data's slope, which contradicts it", apart)
                  : fmt::format("within {:.2g} sigma of the data's slope", apart));
        }
      }
      c.evidence.push_back(sentence);
    }
  }
  if (hertz) {
    c.evidence.push_back(
        fmt::format("The elastic Hertz law keeps e = 1: the maxima' decay {} it (verdict: {}).",
                    hertz->verdict->rfind("rejected", 0) == 0 ? "rejects" : "does not reject",
                    *hertz->verdict));
  }
  if (Row(models, "common")) {
    c.evidence.push_back(
        "Every linear law (Kelvin-Voigt, Poynting-Thomson) keeps e the same at every speed: its "
        "prediction of the maxima is the \"common\" model.");
  }
}

}  // namespace

std::optional<ModelComparison> CompareModels(const LawInputs& inputs, const FitOptions& fit,
                                             const std::vector<RunResult>& runs, bool leave_one_out,
                                             std::string* why) {
  const std::vector<const RunResult*> comparable = ComparableRuns(runs);
  std::vector<JointRun> joint;
  for (const RunResult* run : comparable) {
    const RunMeasurement& m = run->measured;
    joint.push_back({run->id,
                     inputs.pendulum,
                     {m.xmax, m.xmax_sigma, std::nullopt, 0.0},
                     run->initial_displacement});
  }
  if (joint.size() < 3) {
    *why = fmt::format(
        "model comparison skipped: it needs three runs whose maxima all carry an uncertainty, "
        "found {}",
        joint.size());
    return std::nullopt;
  }
  JointFitOptions joint_options = fit.restitution_models;
  joint_options.leave_one_out = leave_one_out;
  SessionModelComparison c = CompareRestitutionModels(joint, joint_options);
  if (!c.ok) {
    *why = fmt::format("model comparison skipped: {}", c.reason);
    return std::nullopt;
  }
  ModelComparison out;
  out.run_ids = std::move(c.run_names);
  for (JointModelFit& m : c.models) out.restitution_models.push_back({std::move(m), ""});
  // The laws' predictions of the same maxima (no contact times: the same data);
  // a law the runs cannot take is a fit that is not ok, with its reason.
  const std::vector<LawRun> law_runs = LawRunsOf(inputs, comparable);
  ContactLawFitOptions options = fit.contact_laws;
  options.separation = inputs.separation;
  options.use_contact_times = false;
  options.leave_one_out = leave_one_out;
  options.intervals = false;  // the comparison judges by the fit, not the parameters' ranges
  for (ContactLawKind kind : {ContactLawKind::kHuntCrossley, ContactLawKind::kHertz}) {
    ComparedContactLaw law;
    law.fit = FitContactLaw(kind, law_runs, options);
    law.log_restitution_spread = LogRestitutionSpread(law.fit);
    out.contact_laws.push_back(std::move(law));
  }
  const std::vector<Judged> models = JudgedModels(out);
  Judge(out, models, leave_one_out);
  Evidence(out, models, comparable, inputs.pendulum);
  return out;
}

std::vector<ContactLawFit> FitContactLaws(const LawInputs& inputs, const FitOptions& fit,
                                          const std::vector<RunResult>& runs,
                                          const ProductOptions& asked,
                                          std::vector<ProductRecord>* records, std::string* why) {
  struct Law {
    ContactLawKind kind;
    const char* product;
    bool asked;
  };
  const ContactLawProducts& laws = asked.contact_laws;
  const Law all[] = {
      {ContactLawKind::kKelvinVoigt, "contact_laws.kelvin_voigt", laws.kelvin_voigt},
      {ContactLawKind::kHertz, "contact_laws.hertz", laws.hertz},
      {ContactLawKind::kHuntCrossley, "contact_laws.hunt_crossley", laws.hunt_crossley},
      {ContactLawKind::kHuntCrossleyExponent, "contact_laws.hunt_crossley_n", laws.hunt_crossley_n},
      {ContactLawKind::kHertzDamper, "contact_laws.hertz_damper", laws.hertz_damper}};
  const std::vector<const RunResult*> comparable = ComparableRuns(runs);
  const std::vector<LawRun> law_runs = LawRunsOf(inputs, comparable);
  ContactLawFitOptions options = fit.contact_laws;
  options.separation = inputs.separation;
  options.leave_one_out = asked.leave_one_out;
  options.intervals = asked.intervals;
  std::vector<ContactLawKind> to_fit;
  for (const Law& law : all) {
    const std::string uninformed =
        !law.asked ? ""
        : comparable.size() < 2
            ? fmt::format(
                  "a contact law needs two runs whose maxima all carry an uncertainty, "
                  "found {}",
                  comparable.size())
            : ContactLawUninformed(law.kind, law_runs, options);
    records->push_back(DecideProduct(law.product, law.asked, uninformed));
    if (records->back().made) to_fit.push_back(law.kind);
  }
  if (comparable.size() < 2) {
    *why = fmt::format(
        "contact laws skipped: they need two runs whose maxima all carry an uncertainty, found {}",
        comparable.size());
    return {};
  }
  // The laws are independent problems: with jobs > 1 they run side by side
  // (the damper's and the free exponent's leave-one-out dominate).
  // A law the runs cannot take is a fit that is not ok, with its reason.
  const auto fit_law = [&](ContactLawKind kind) { return FitContactLaw(kind, law_runs, options); };
  std::vector<std::future<ContactLawFit>> pending;
  for (ContactLawKind kind : to_fit) {
    pending.push_back(
        std::async(inputs.jobs > 1 ? std::launch::async : std::launch::deferred, fit_law, kind));
  }
  std::vector<ContactLawFit> out;
  for (auto& p : pending) out.push_back(p.get());
  return out;
}

void MakeSessionFits(const LawInputs& inputs, const FitOptions& fit, const ProductOptions& asked,
                     SessionResult& result) {
  std::vector<ProductRecord>& records = result.products;
  const auto record = [&](const char* name, bool asked_for, const std::string& uninformed) {
    records.push_back(DecideProduct(name, asked_for, uninformed));
    return records.back().made;
  };
  const std::size_t fitted_runs = static_cast<std::size_t>(
      std::count_if(result.runs.begin(), result.runs.end(),
                    [](const RunResult& r) { return r.ok && r.measured.xmax.size() >= 2; }));
  const std::size_t comparable = ComparableRuns(result.runs).size();

  if (record("joint_fits", asked.joint_fits,
             fitted_runs < 2 ? fmt::format("a joint fit needs two reduced runs with two maxima or "
                                           "more, found {}",
                                           fitted_runs)
                             : "")) {
    result.joint_fits =
        FitSessionJointly(inputs.pendulum, inputs.mass, inputs.separation, fit, result.runs);
  }
  // Leave-one-out refits the comparison and the laws: it needs three runs.
  const bool leave_one_out = asked.leave_one_out && comparable >= 3;
  std::string why;
  if (record("model_comparison", asked.model_comparison, "")) {
    // Fewer than three runs: CompareModels says why, as a warning too.
    result.model_comparison = CompareModels(inputs, fit, result.runs, leave_one_out, &why);
    if (!result.model_comparison) {
      result.warnings.push_back(why);
      records.back().made = false;
      const std::string prefix = "model comparison skipped: ";
      records.back().reason =
          std::string(kUninformed) + (why.starts_with(prefix) ? why.substr(prefix.size()) : why);
    }
  }
  why.clear();
  result.contact_laws = FitContactLaws(inputs, fit, result.runs, asked, &records, &why);
  const bool any_law = std::any_of(records.begin(), records.end(), [](const ProductRecord& r) {
    return r.made && r.name.starts_with("contact_laws.");
  });
  if (comparable >= 2 && !any_law &&
      std::any_of(records.begin(), records.end(), [](const ProductRecord& r) {
        return r.name.starts_with("contact_laws.") && r.reason != kNotAsked;
      })) {
    why = "contact laws skipped: the runs inform none of those asked for";
  }
  if (result.contact_laws.empty() && !why.empty()) result.warnings.push_back(why);
  record("intervals", asked.intervals,
         any_law ? "" : "intervals are of the contact laws' parameters, and no law is fitted");
  record("leave_one_out", asked.leave_one_out,
         comparable < 3 ? fmt::format("leave-one-out needs three runs whose maxima all carry an "
                                      "uncertainty, found {}",
                                      comparable)
         : !any_law && !result.model_comparison
             ? "there is no model comparison or contact law to refit"
             : "");
}

}  // namespace impactlab
