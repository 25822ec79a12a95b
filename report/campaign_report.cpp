#include "report/campaign_report.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "model/power_law_contact.h"
#include "report/figure_file_name.h"
#include "report/html_escape.h"
#include "report/uncertainty.h"

namespace impactlab {
namespace {

// A value and its error as a reader quotes them, the error to two digits.
Cell Quoted(double value, double sigma) {
  if (!(sigma > 0.0) || !std::isfinite(sigma)) {
    return Cell{fmt::format("{:.6g}", value), value, std::nullopt, -1};
  }
  const RoundedEstimate r = RoundToError(value, sigma);
  return Cell{r.value + " ± " + r.sigma, value, sigma, r.decimals};
}

Cell Number(double value, int significant) {
  return Cell{fmt::format("{:.{}g}", value, significant), value, std::nullopt, -1};
}

Table SessionsTable(const Campaign& c) {
  Table t;
  t.name = "campaign_sessions";
  t.caption = "Every session's estimates, grouped by material and end geometry";
  t.columns = {"Material", "Geometry", "Session", "From", "Parameter", "Value", "Unit"};
  for (const CampaignSession& s : c.sessions) {
    for (const SessionEstimate& e : s.estimates) {
      t.rows.push_back({s.material, s.geometry, s.name, e.source, e.name, Quoted(e.value, e.sigma),
                        Cell::Unit(e.unit)});
    }
    if (s.estimates.empty()) {
      t.rows.push_back({s.material, s.geometry, s.name, "-", "-", "-", "-"});
    }
  }
  t.notes.push_back(fmt::format("Units: {}; a session in the other system is converted.",
                                UnitSystemName(c.units)));
  return t;
}

Table ContactTimesTable(const Campaign& c) {
  const UnitLabels u = LabelsFor(c.units);
  Table t;
  t.name = "campaign_contact_times";
  t.caption = "The runs' own contact times at their impact speeds";
  t.columns = {"Material", "Geometry", "Session", "Run", "Impact speed (" + u.speed + ")",
               "tau_c (s)"};
  for (const CampaignSession& s : c.sessions) {
    for (const ContactTimeAtSpeed& ct : s.contact_times) {
      t.rows.push_back({s.material, s.geometry, s.name, ct.run, Number(ct.speed, 5),
                        Quoted(ct.contact_time, ct.contact_time_sigma)});
    }
  }
  t.notes.push_back("Each contact time belongs to the impact after the run's rebound 0.");
  return t;
}

// The sessions a fit names as pulling away, and the constants on which two
// sessions alone disagree (neither can be named).
std::string PullingAway(const MaterialFit& m) {
  std::vector<std::string> said;
  if (!m.pulling_away.empty()) said.push_back(fmt::format("{}", fmt::join(m.pulling_away, ", ")));
  for (const std::string& c : m.disagreeing_pairs) {
    said.push_back(
        fmt::format("the two sessions stating {} disagree (which is off cannot be told)", c));
  }
  return said.empty() ? std::string("none") : fmt::format("{}", fmt::join(said, "; "));
}

Table SharedTable(const Campaign& c) {
  Table t;
  t.name = "campaign_shared_constants";
  t.caption = "The constants each material's sessions share, fitted together";
  t.columns = {"Material", "Fit", "Constant",    "Value", "sigma scaled", "Unit", "Sessions",
               "chi2",     "dof", "Birge ratio", "p",     "Pulling away"};
  for (const MaterialFit& m : c.fits) {
    if (!m.ok) {
      t.rows.push_back({m.material, m.fit, fmt::format("{}", fmt::join(m.constants, ", ")),
                        "failed: " + m.reason, "-", "-",
                        Cell{fmt::format("{}", m.sessions.size()),
                             static_cast<double>(m.sessions.size()), std::nullopt, 0},
                        "-", "-", "-", "-", "-"});
      continue;
    }
    for (std::size_t i = 0; i < m.constants.size(); ++i) {
      t.rows.push_back({m.material, m.fit, m.constants[i], Quoted(m.values[i], m.sigma[i]),
                        Number(m.sigma_scaled[i], 2), Cell::Unit(m.units[i]),
                        Cell{fmt::format("{}", m.sessions.size()),
                             static_cast<double>(m.sessions.size()), std::nullopt, 0},
                        Number(m.chi2, 4),
                        Cell{fmt::format("{}", m.dof), static_cast<double>(m.dof), std::nullopt, 0},
                        Number(m.birge_ratio, 3), Number(m.p_value, 2), PullingAway(m)});
    }
  }
  t.notes.push_back(
      "Generalised least squares on the sessions' estimates and covariances; hunt-crossley and "
      "hertz fit ln E* and ln chi, restitution ln chi and beta of e(u) = E(chi u0 (u/u0)^beta). "
      "sigma scaled: times the Birge ratio where it exceeds 1.");
  return t;
}

Table PullsTable(const Campaign& c) {
  Table t;
  t.name = "campaign_pulls";
  t.caption = "Each session's pull: its estimate against the fit of the other sessions, in sigma";
  t.columns = {"Material", "Fit", "Session", "Constant", "Pull", "Threshold", "Pulls away"};
  for (const MaterialFit& m : c.fits) {
    for (std::size_t i = 0; i < m.pull.size(); ++i) {
      const bool away = std::find(m.pulling_away.begin(), m.pulling_away.end(),
                                  m.pull_session[i]) != m.pulling_away.end() &&
                        std::abs(m.pull[i]) > m.pull_threshold;
      t.rows.push_back({m.material, m.fit, m.pull_session[i], m.pull_constant[i],
                        Cell{fmt::format("{:+.2f}", m.pull[i]), m.pull[i], std::nullopt, 2},
                        Number(m.pull_threshold, 3), away ? "yes" : "no"});
    }
  }
  return t;
}

Table FailuresTable(const Campaign& c) {
  Table t;
  t.name = "campaign_failures";
  t.caption = "Inputs that could not be read";
  t.columns = {"Input", "Reason"};
  for (const CampaignFailure& f : c.failures) t.rows.push_back({f.input, f.reason});
  if (c.failures.empty()) t.rows.push_back({"-", "every input was read"});
  return t;
}

constexpr const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

std::string ColourOf(std::size_t k) { return kColours[k % std::size(kColours)]; }

std::vector<std::string> Materials(const Campaign& c) {
  std::vector<std::string> out;
  for (const CampaignSession& s : c.sessions) {
    if (std::find(out.begin(), out.end(), s.material) == out.end()) out.push_back(s.material);
  }
  return out;
}

Plot RestitutionFigure(const Campaign& c) {
  const UnitLabels u = LabelsFor(c.units);
  Plot plot;
  plot.title = "Restitution against impact speed, every session";
  plot.x_label = "impact speed (" + u.speed + ")";
  plot.y_label = "e";
  const std::vector<std::string> materials = Materials(c);
  for (std::size_t k = 0; k < materials.size(); ++k) {
    PlotSeries s;
    s.name = materials[k];
    s.style = PlotSeries::Style::kMarkers;
    s.colour = ColourOf(k);
    for (const CampaignSession& session : c.sessions) {
      if (session.material != materials[k]) continue;
      for (const ImpactRestitution& r : session.restitution) {
        s.x.push_back(r.speed), s.y.push_back(r.restitution),
            s.sigma.push_back(r.restitution_sigma);
      }
    }
    plot.series.push_back(std::move(s));
  }
  return plot;
}

// One material's contact times and, through each session's speeds, its
// fitted law's (Hunt-Crossley where fitted, else Hertz).
Plot ContactTimeFigure(const Campaign& c, const std::string& material) {
  const UnitLabels u = LabelsFor(c.units);
  Plot plot;
  plot.title = "Contact time against impact speed: " + material;
  plot.x_label = "impact speed (" + u.speed + ")";
  plot.y_label = "contact time (s)";
  PlotSeries measured;
  measured.name = "measured";
  measured.style = PlotSeries::Style::kMarkers;
  std::size_t k = 1;
  for (const CampaignSession& s : c.sessions) {
    if (s.material != material) continue;
    for (const ContactTimeAtSpeed& ct : s.contact_times) {
      measured.x.push_back(ct.speed), measured.y.push_back(ct.contact_time);
      measured.sigma.push_back(ct.contact_time_sigma);
    }
    const auto law = std::find_if(s.laws.begin(), s.laws.end(), [](const SessionContactLaw& l) {
      return l.law == "hunt-crossley";
    });
    const SessionContactLaw* drawn = law != s.laws.end() ? &*law
                                     : s.laws.empty()    ? nullptr
                                                         : &s.laws.front();
    if (drawn == nullptr || s.contact_times.empty()) continue;
    double lo = s.contact_times.front().speed, hi = lo;
    for (const ContactTimeAtSpeed& ct : s.contact_times)
      lo = std::min(lo, ct.speed), hi = std::max(hi, ct.speed);
    PlotSeries curve;
    curve.name = s.name + " (" + drawn->law + ")";
    curve.colour = ColourOf(k++);
    for (int i = 0; i <= 24; ++i) {
      const double v = lo * 0.9 + (hi * 1.1 - lo * 0.9) * i / 24.0;
      try {
        const ContactResponse r = HuntCrossleyContact(
            HuntCrossley{drawn->mass, drawn->hertz_stiffness, 1.5, drawn->damping_factor}, v);
        curve.x.push_back(v), curve.y.push_back(r.contact_time);
      } catch (const std::exception&) {
        // outside the law's domain: no point there
      }
    }
    plot.series.push_back(std::move(curve));
  }
  plot.series.insert(plot.series.begin(), std::move(measured));
  return plot;
}

// Each session's estimate of one shared constant with its error bar, and the
// joint value, session by session in the fit's order.
Plot ConstantFigure(const Campaign& c, const MaterialFit& m, std::size_t i) {
  Plot plot;
  plot.title = fmt::format("{} per session: {} ({})", m.constants[i], m.material, m.fit);
  plot.x_label = "session (in the order of the fit's sessions)";
  plot.y_label = fmt::format("{} ({})", m.constants[i], m.units[i]);
  PlotSeries sessions;
  sessions.name = "each session";
  sessions.style = PlotSeries::Style::kMarkers;
  const std::string source = m.fit == "restitution" ? "restitution speed law" : m.fit;
  for (std::size_t k = 0; k < m.sessions.size(); ++k) {
    const auto s = std::find_if(c.sessions.begin(), c.sessions.end(),
                                [&](const CampaignSession& x) { return x.name == m.sessions[k]; });
    if (s == c.sessions.end()) continue;
    for (const SessionEstimate& e : s->estimates) {
      if (e.source != source || e.name != m.constants[i]) continue;
      double value = e.value;
      double sigma = e.sigma;
      // A session's chi is eps/u at its own reference speed: moved to u0
      // along the joint beta (eps grows as u^beta, so eps/u as u^(beta-1)).
      if (m.fit == "restitution" && e.name == "damping_factor" && m.values.size() == 2 &&
          s->reference_speed > 0.0 && m.reference_speed > 0.0) {
        const double factor = std::pow(m.reference_speed / s->reference_speed, m.values[1] - 1.0);
        value *= factor;
        sigma *= factor;
      }
      sessions.x.push_back(static_cast<double>(k + 1));
      sessions.y.push_back(value);
      sessions.sigma.push_back(sigma);
    }
  }
  plot.series.push_back(sessions);
  if (m.ok) {
    const double lo = 0.5, hi = static_cast<double>(m.sessions.size()) + 0.5;
    PlotSeries joint{
        "joint fit", {lo, hi}, {m.values[i], m.values[i]}, {}, PlotSeries::Style::kLine, "#d62728"};
    PlotSeries band_hi{"joint fit + sigma scaled",
                       {lo, hi},
                       {m.values[i] + m.sigma_scaled[i], m.values[i] + m.sigma_scaled[i]},
                       {},
                       PlotSeries::Style::kLine,
                       "#ff9896"};
    PlotSeries band_lo{"joint fit - sigma scaled",
                       {lo, hi},
                       {m.values[i] - m.sigma_scaled[i], m.values[i] - m.sigma_scaled[i]},
                       {},
                       PlotSeries::Style::kLine,
                       "#ff9896"};
    plot.series.push_back(joint);
    plot.series.push_back(band_hi);
    plot.series.push_back(band_lo);
  }
  return plot;
}

}  // namespace

std::vector<Table> BuildCampaignTables(const Campaign& campaign) {
  return {FailuresTable(campaign), SharedTable(campaign), PullsTable(campaign),
          SessionsTable(campaign), ContactTimesTable(campaign)};
}

std::vector<Plot> CampaignFigures(const Campaign& campaign) {
  std::vector<Plot> plots = {RestitutionFigure(campaign)};
  for (const std::string& material : Materials(campaign)) {
    const bool any = std::any_of(campaign.sessions.begin(), campaign.sessions.end(),
                                 [&](const CampaignSession& s) {
                                   return s.material == material && !s.contact_times.empty();
                                 });
    if (any) plots.push_back(ContactTimeFigure(campaign, material));
  }
  for (const MaterialFit& m : campaign.fits) {
    for (std::size_t i = 0; i < m.constants.size(); ++i)
      plots.push_back(ConstantFigure(campaign, m, i));
  }
  return plots;
}

std::string RenderCampaignHtml(const Campaign& campaign) {
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>Campaign"
      "</title>\n<style>body{{font-family:sans-serif;max-width:70em;margin:auto}}"
      "table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:2px 6px}}"
      "</style>\n</head>\n<body>\n<h1>Campaign: {} sessions</h1>\n<p>{} inputs, {} not read; "
      "units {}; {}</p>\n",
      campaign.sessions.size(), campaign.inputs.size(), campaign.failures.size(),
      EscapeHtml(std::string(UnitSystemName(campaign.units))), EscapeHtml(campaign.producer));
  html += "<h2>Tables</h2>\n";
  for (const Table& t : BuildCampaignTables(campaign)) html += RenderTable(t, ReportFormat::kHtml);
  html += "<h2>Figures</h2>\n";
  for (const Plot& p : CampaignFigures(campaign)) html += "<figure>" + RenderSvg(p) + "</figure>\n";
  html += "</body>\n</html>\n";
  return html;
}

std::vector<std::pair<std::string, std::string>> RenderCampaignFigures(const Campaign& campaign) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::vector<Plot> plots = CampaignFigures(campaign);
  for (std::size_t i = 0; i < plots.size(); ++i) {
    out.emplace_back(FigureFileName(i + 1, plots[i].title), RenderSvg(plots[i]));
  }
  return out;
}

}  // namespace impactlab
