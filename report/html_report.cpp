#include "report/html_report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "calibration/photocell_calibration.h"
#include "pipeline/log_results.h"
#include "report/dygraph_plot.h"
#include "report/figure_file_name.h"
#include "report/html_escape.h"
#include "report/svg_plot.h"
#include "report/tables.h"
#include "report/text_escape.h"

namespace impactlab {
namespace {

constexpr const char* kBlue = "#1f77b4";
constexpr const char* kOrange = "#ff7f0e";
constexpr const char* kGreen = "#2ca02c";
constexpr const char* kRed = "#d62728";

constexpr const char* kStyle = R"(
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { font-size: 1.6em; } h2 { margin-top: 2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
caption { text-align: left; font-weight: bold; padding: 0.3em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th.num, td.num { text-align: right; } tr.summary td { border-top: 2px solid #888; }
.note { font-size: 0.85em; color: #555; margin: 0.2em 0; }
.ok { color: #2a7; } .failed { color: #c33; }
.plot { display: flex; gap: 1em; align-items: flex-start; }
.graph { width: 760px; height: 340px; flex: none; } .legend { font-size: 0.8em; min-width: 14em; }
nav ul ul { font-size: 0.9em; } ul.summary li { margin: 0.3em 0; }
figure { margin: 1em 0; } figcaption { font-size: 0.85em; color: #555; }
)";

// Standard base64 (RFC 4648), for images embedded in the page.
std::string Base64(const std::vector<unsigned char>& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned n = bytes[i] << 16 | (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0) |
                       (i + 2 < bytes.size() ? bytes[i + 2] : 0);
    out += kAlphabet[n >> 18 & 63];
    out += kAlphabet[n >> 12 & 63];
    out += i + 1 < bytes.size() ? kAlphabet[n >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

std::string OverlayFigure(const PhotoOverlay& o) {
  std::string coverage, spread;
  for (std::size_t i = 0; i < o.trace_names.size(); ++i) {
    coverage += fmt::format("{}{} {:.0f} %", i ? ", " : "", EscapeHtml(o.trace_names[i]),
                            100.0 * o.trace_coverage[i]);
    if (i < o.trace_spread_px2.size() && o.trace_spread_px2[i] > 0.0) {
      spread += fmt::format("{}{} {:.2f} ± {:.2f} px²", spread.empty() ? "" : ", ",
                            EscapeHtml(o.trace_names[i]), o.trace_spread_px2[i],
                            o.trace_spread_sigma_px2[i]);
    }
  }
  if (!spread.empty()) {
    spread = "; spread whose pull inside curves was undone: " + spread;
  }
  return fmt::format(
      "<figure><img alt=\"digitized {0}\" style=\"max-width:100%\" loading=\"lazy\" "
      "decoding=\"async\" src=\"data:image/jpeg;base64,{1}\"><figcaption>{0}: the graticule found "
      "(residual {2:.3f} "
      "px RMS) and the traces followed; coverage of the sweep: {3}{5}; {4:.0f} ms of digitizing "
      "beyond decoding.</figcaption></figure>\n",
      EscapeHtml(o.photo), Base64(o.jpeg), o.graticule_residual_px, coverage, o.processing_ms,
      spread);
}

// The calibration photos behind a run's curves, folded away: they matter
// when a curve looks wrong, and a session has two per run.
std::string CalibrationOverlays(const std::vector<CellCalibration>& calibrations) {
  std::string figures;
  for (const CellCalibration& c : calibrations) {
    if (c.overlay) figures += OverlayFigure(*c.overlay);
  }
  if (figures.empty()) return "";
  return "<details><summary>Calibration photos, digitized</summary>\n" + figures + "</details>\n";
}

// The page's figures: each drawn by dygraphs where it stands, and kept, by a
// file name, for the static export (`report --figures DIR`).
class Figures {
 public:
  std::string Add(const Plot& plot, const std::string& caption) {
    if (std::none_of(plot.series.begin(), plot.series.end(),
                     [](const PlotSeries& s) { return !s.x.empty(); })) {
      return "";  // nothing to draw (a typed-in run whose fit failed has no times)
    }
    const std::string id = fmt::format("figure-{}", plots_.size() + 1);
    plots_.push_back({FigureFileName(plots_.size() + 1, plot.title), plot});
    return fmt::format("<figure>{}<figcaption>{}</figcaption></figure>\n", RenderDygraph(plot, id),
                       EscapeHtml(caption));
  }
  const std::vector<std::pair<std::string, Plot>>& plots() const { return plots_; }

 private:
  std::vector<std::pair<std::string, Plot>> plots_;
};

// Thesis Figures 16-18: the fit, the measured history drawn over it, the
// maxima with their errors; beneath, what the fit leaves.
std::string RunFigure(const RunResult& run, const UnitLabels& u, Figures& figures) {
  const Curve& measured = run.measured.measured_displacement;
  const Curve& model = run.fits.model_response;
  Plot plot;
  plot.title = fmt::format("Run {}: displacement", run.id);
  plot.x_label = "time since release (s)";
  plot.y_label = fmt::format("displacement X ({})", u.length);
  if (!model.time_s.empty()) {
    plot.series.push_back(
        {"Kelvin–Voigt fit", model.time_s, model.value, {}, PlotSeries::Style::kLine, kOrange});
  }
  if (!measured.time_s.empty()) {
    plot.series.push_back({"measured (average of the bars)",
                           measured.time_s,
                           measured.value,
                           {},
                           PlotSeries::Style::kLine,
                           kBlue});
  }
  if (run.PeakTimes().size() == run.measured.xmax.size()) {
    plot.series.push_back({"measured maxima ± 1σ", run.PeakTimes(), run.measured.xmax,
                           run.measured.xmax_sigma, PlotSeries::Style::kMarkers, kRed});
  }
  std::string out = figures.Add(
      plot, fmt::format("Measured and theoretical response of run {} (thesis Figures 16-18); "
                        "maxima from {}, times from the {}.",
                        run.id, run.measured.source, run.PeakTimesSource()));
  if (const Curve& left = run.fits.model_residual; !left.time_s.empty()) {
    Plot residual;
    residual.title = fmt::format("Run {}: measured − fitted", run.id);
    residual.x_label = plot.x_label;
    residual.y_label = fmt::format("residual ({})", u.length);
    residual.height_px = 220;
    residual.series.push_back({"measured − Kelvin–Voigt fit",
                               left.time_s,
                               left.value,
                               {},
                               PlotSeries::Style::kLine,
                               kBlue});
    out += figures.Add(residual, fmt::format("Run {}: the measured displacement less the fitted "
                                             "model's, at the measured times.",
                                             run.id));
  }
  return out;
}

// Thesis Figures 13-14: each cell's points (thinned for display) and its
// fitted curve on top, a colour per cell. A hundred points a cell show the
// scatter, and 80 segments draw the smooth curve; more only weighs the page
// (the cells' points lie at different x, so each costs a row of its own).
constexpr std::size_t kCalibrationPoints = 100;
constexpr int kCurvePoints = 80;
std::string CalibrationFigure(const RunResult& run, const UnitLabels& u, Figures& figures) {
  Plot plot;
  plot.title = fmt::format("Run {}: photocell calibrations", run.id);
  plot.x_label = fmt::format("ideal pendulum displacement X ({})", u.length);
  plot.y_label = "photocell output (V)";
  const char* points_colour[] = {"#8ab6e0", "#9fd49f"};
  const char* curve_colour[] = {"#0b3c6b", "#145214"};
  std::string notes;
  for (std::size_t k = 0; k < run.measured.calibrations.size(); ++k) {
    const CellCalibration& c = run.measured.calibrations[k];
    PlotSeries points{fmt::format("{} cell ({}): points", c.cell, c.calibration_id),
                      {},
                      {},
                      {},
                      PlotSeries::Style::kMarkers,
                      points_colour[k % 2]};
    const std::size_t stride = std::max<std::size_t>(1, c.points_x.size() / kCalibrationPoints);
    for (std::size_t i = 0; i < c.points_x.size(); i += stride) {
      points.x.push_back(c.points_x[i]);
      points.y.push_back(c.points_volts[i]);
    }
    // The curve as fitted (its stored coefficients), evaluated for display,
    // with its one-sigma band in volts where the covariance is known.
    const std::size_t n = c.chebyshev.size();
    const bool band = c.chebyshev_covariance.values.size() == n * n && n > 0;
    const PhotocellCurve stored(c.release_x, c.chebyshev,
                                band ? c.chebyshev_covariance.values : std::vector<double>{}, 0.0);
    PlotSeries curve{fmt::format("{} cell: fitted curve (order {}) ± 1σ", c.cell, c.order),
                     {},
                     {},
                     {},
                     PlotSeries::Style::kLine,
                     curve_colour[k % 2]};
    for (int i = 0; i <= kCurvePoints; ++i) {
      const double x = c.release_x * i / kCurvePoints;
      curve.x.push_back(x);
      curve.y.push_back(stored.VoltsAt(x));
      if (band) curve.sigma.push_back(stored.DisplacementSigmaAt(x) * std::abs(stored.SlopeAt(x)));
    }
    plot.series.push_back(std::move(points));
    plot.series.push_back(std::move(curve));
    notes += fmt::format("{} cell: {} samples, residual {:.3g} V rms ({:.3g} {} rms). ", c.cell,
                         c.samples_used, c.residual_rms_volts, c.residual_rms_length, u.length);
  }
  return figures.Add(plot,
                     "Dynamic calibration (thesis Figures 13-14): the cell's voltage against the "
                     "free pendulum's displacement over the first swing. " +
                         notes);
}

std::string SessionFigures(const SessionResult& r, const UnitLabels& u, Figures& figures) {
  std::string out;
  Plot contact;
  contact.title = "Contact time against initial displacement";
  contact.x_label = fmt::format("initial displacement X0 ({})", u.length);
  contact.y_label = "contact time τc (µs)";
  PlotSeries points{"runs ± 1σ", {}, {}, {}, PlotSeries::Style::kMarkers, kBlue};
  for (const RunResult& run : r.runs) {
    if (run.measured.contact_time) {
      points.x.push_back(run.initial_displacement);
      points.y.push_back(*run.measured.contact_time * 1e6);
      points.sigma.push_back(run.measured.contact_time_sigma * 1e6);
    }
  }
  if (!points.x.empty()) {
    contact.series.push_back(points);
    out += figures.Add(contact,
                       "Measured contact time against initial displacement (thesis Figure 19).");
  }
  if (r.kelvin_voigt && r.kelvin_voigt->damping_line) {
    const SessionKelvinVoigt& s = *r.kelvin_voigt;
    const DampingLine& line = *s.damping_line;
    Plot damping;
    damping.title = "C against √ξ";
    damping.x_label = "√ξ (ξ = the run's restitution e)";
    damping.y_label = fmt::format("C ({})", u.damping);
    const auto [lo, hi] = std::minmax_element(s.sqrt_restitution.begin(), s.sqrt_restitution.end());
    PlotSeries fit{fmt::format("C = {:.4g} (1 − {:.4g} √ξ)", line.a.value, line.b.value),
                   {*lo, *hi},
                   {},
                   {},
                   PlotSeries::Style::kLine,
                   kOrange};
    for (double x : fit.x) fit.y.push_back(line.a.value * (1.0 - line.b.value * x));
    damping.series.push_back(fit);
    damping.series.push_back({"runs ± 1σ", s.sqrt_restitution, s.damping, s.damping_sigma,
                              PlotSeries::Style::kMarkers, kBlue});
    out += figures.Add(damping,
                       "Damping coefficient against the square root of the restitution, with "
                       "its least-squares line (thesis Figure 20, eq. 40).");
  }
  return out;
}

// Per channel: the experiment's and the simulation's histories and spectra.
std::string LogFigures(const LogResult& log, Figures& figures) {
  std::string out;
  const char* colours[] = {kBlue, kOrange};
  const LogSourceResult* first = log.sources.empty() ? nullptr : &log.sources.front();
  if (first == nullptr) return out;
  for (const ChannelAnalysis& c : first->channels) {
    Plot history;
    history.title = fmt::format("Log {}: {} over time", log.id, c.name);
    history.x_label = "time (s)";
    history.y_label = fmt::format("{} ({})", c.name, c.units);
    for (std::size_t k = 0; k < log.sources.size(); ++k) {
      for (const ChannelAnalysis& d : log.sources[k].channels) {
        if (d.name == c.name && !d.series.time_s.empty()) {
          history.series.push_back({log.sources[k].source,
                                    d.series.time_s,
                                    d.series.value,
                                    {},
                                    PlotSeries::Style::kLine,
                                    colours[k % 2]});
        }
      }
    }
    if (!history.series.empty()) {
      out += figures.Add(history, fmt::format("{} of experiment and simulation on their own "
                                              "time axes; the impact offset is in the table "
                                              "above.",
                                              c.name));
    }
    Plot plot;
    plot.title = fmt::format("Log {}: spectrum of {}", log.id, c.name);
    plot.x_label = "frequency (Hz)";
    plot.y_label = fmt::format("log10 PSD (({})²/Hz)", c.units);
    for (std::size_t k = 0; k < log.sources.size(); ++k) {
      for (const ChannelAnalysis& d : log.sources[k].channels) {
        const SegmentSpectrum* kept = KeptSpectrum(d);
        if (d.name != c.name || kept == nullptr || kept->spectrum.psd.empty()) continue;
        PlotSeries series{
            log.sources[k].source, kept->spectrum.frequency_hz, {}, {}, PlotSeries::Style::kLine,
            colours[k % 2]};
        for (double p : kept->spectrum.psd) series.y.push_back(std::log10(std::max(p, 1e-300)));
        plot.series.push_back(std::move(series));
      }
    }
    if (!plot.series.empty()) {
      out += figures.Add(plot, fmt::format("Post-impact spectra of {}, experiment and "
                                           "simulation overlaid (the dominant peaks are in the "
                                           "table above).",
                                           c.name));
    }
  }
  return out;
}

// What a reader wants first: how many runs reduced, the session's headline
// numbers with their uncertainties, the model comparison's verdict and each
// log's comparison, in a few lines.
std::string Summary(const SessionResult& r, const UnitLabels& u) {
  std::vector<std::string> lines;
  if (!r.runs.empty()) {
    const auto failed =
        std::count_if(r.runs.begin(), r.runs.end(), [](const RunResult& run) { return !run.ok; });
    std::string failures;
    for (const RunResult& run : r.runs) {
      if (!run.ok) {
        failures += fmt::format("{0}<a href=\"#run-{1}\">{1}</a>", failures.empty() ? ": " : ", ",
                                EscapeHtml(run.id));
      }
    }
    lines.push_back(
        fmt::format("{} run(s): <span class=\"ok\">{} reduced</span>, "
                    "<span class=\"{}\">{} failed</span>{}.",
                    r.runs.size(), static_cast<long>(r.runs.size()) - failed,
                    failed > 0 ? "failed" : "ok", failed, failures));
  }
  if (!r.calibrations.empty()) {
    lines.push_back(fmt::format("{} photocell calibration(s).", r.calibrations.size()));
  }
  if (r.kelvin_voigt) {
    const SessionKelvinVoigt& s = *r.kelvin_voigt;
    double widest = 0.0;
    for (double p : s.spread.pct_variation) widest = std::max(widest, p);
    lines.push_back(fmt::format(
        "Kelvin–Voigt stiffness over {} run(s): K avg = {:.6g} {} (the runs within {:.2g} %){}.",
        s.run_ids.size(), s.spread.average, u.stiffness, widest,
        s.average_stiffness ? "; every run's C is from K avg" : ""));
    if (s.damping_line) {
      const DampingLine& line = *s.damping_line;
      lines.push_back(
          fmt::format("Damping against √ξ (eq. 40): C = a (1 − b √ξ), a = {:.4g} ± "
                      "{:.2g} {}, b = {:.4g} ± {:.2g}.",
                      line.a.value, line.a.sigma, u.damping, line.b.value, line.b.sigma));
    }
  }
  if (r.model_comparison) {
    lines.push_back(fmt::format(
        "Restitution models: best at predicting an unseen run <b>{}</b>; lowest BIC <b>{}</b>.",
        EscapeHtml(r.model_comparison->best_by_leave_one_out),
        EscapeHtml(r.model_comparison->best_by_bic)));
  }
  for (const LogResult& log : r.logs) {
    if (!log.ok) {
      lines.push_back(fmt::format("Log {}: <span class=\"failed\">{}</span>", EscapeHtml(log.id),
                                  EscapeHtml(log.Status())));
      continue;
    }
    std::string rows;
    if (log.comparison) {
      for (const ChannelComparison& c : log.comparison->channels) {
        // A channel without a frequency in both sources is not compared (the
        // check list says why).
        if (!std::isfinite(c.frequency_difference_hz)) continue;
        rows += fmt::format("{}{}: {:.5g} Hz measured, {:.5g} Hz simulated ({:+.2f} %)",
                            rows.empty() ? "" : "; ", EscapeHtml(c.channel),
                            c.experiment_frequency_hz.value, c.simulation_frequency_hz.value,
                            c.frequency_difference_percent);
      }
      if (const std::optional<Estimate>& offset = log.comparison->impact_offset_s) {
        rows += fmt::format("; impact offset {:.4g} ± {:.2g} s", offset->value, offset->sigma);
      }
    }
    lines.push_back(
        fmt::format("Log {}: {}.", EscapeHtml(log.id), rows.empty() ? "analysed" : rows));
  }
  if (!r.warnings.empty()) {
    lines.push_back(fmt::format("{} warning(s), in the list above.", r.warnings.size()));
  }
  std::string out = "<h2 id=\"summary\">Summary</h2>\n<ul class=\"summary\">\n";
  for (const std::string& line : lines) out += "<li>" + line + "</li>\n";
  return out + "</ul>\n";
}

// Links to every section, in the page's order.
std::string Contents(const SessionResult& r, const std::vector<Table>& tables) {
  std::string out =
      "<nav><h2>Contents</h2>\n<ul>\n<li><a href=\"#table-check_these\">Check these</a></li>\n"
      "<li><a href=\"#summary\">Summary</a></li>\n";
  if (!tables.empty()) {
    out += "<li><a href=\"#tables\">Tables</a><ul>\n";
    for (const Table& t : tables) {
      out += fmt::format("<li><a href=\"#table-{}\">{}</a></li>\n", t.name, EscapeHtml(t.caption));
    }
    out += "</ul></li>\n";
  }
  if (!r.runs.empty()) out += "<li><a href=\"#across-runs\">Across runs</a></li>\n";
  for (const LogResult& log : r.logs) {
    out += fmt::format("<li><a href=\"#log-{0}\">Log {0}</a></li>\n", EscapeHtml(log.id));
  }
  if (!r.runs.empty()) {
    out += "<li>Runs:";
    for (const RunResult& run : r.runs) {
      out += fmt::format(" <a href=\"#run-{0}\" class=\"{1}\">{0}</a>", EscapeHtml(run.id),
                         run.ok ? "ok" : "failed");
    }
    out += "</li>\n";
  }
  return out + "</ul></nav>\n";
}

// The page, its figures added to `figures` as they are placed.
std::string BuildPage(const SessionResult& r, Figures& figures) {
  const UnitLabels u = LabelsFor(r.units);
  std::string html = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{0}</title>\n"
      "<style>{1}</style>\n{2}</head>\n<body>\n<h1>{0}</h1>\n",
      EscapeHtml(r.title), kStyle, DygraphLibrary());
  // The pendulum's settings only where there is a pendulum (runs or calibrations).
  const bool pendulum = !r.runs.empty() || !r.calibrations.empty();
  html += fmt::format(
      "<p>Reduced by {} on {} from <code>{}</code>. Units {}{}.</p>\n", EscapeHtml(r.producer),
      EscapeHtml(r.created), EscapeHtml(r.session_folder), UnitSystemName(r.units),
      pendulum ? fmt::format("; pendulum convention {}; Kelvin-Voigt separation {}",
                             ConventionName(r.convention), SeparationName(r.separation))
               : std::string());
  // The check list (BuildTables' first) opens the page, each item linked to
  // its run's or log's section and to its table.
  std::vector<Table> tables = BuildTables(r);
  html += "<h2 id=\"check\">Check these</h2>\n" + RenderTable(tables.front(), ReportFormat::kHtml);
  tables.erase(tables.begin());
  html += Contents(r, tables) + Summary(r, u);
  if (!r.runs.empty()) {
    html += "<h3>Runs</h3>\n<ul>\n";
    for (const RunResult& run : r.runs) {
      html +=
          fmt::format("<li><a href=\"#run-{0}\">{0}</a>: <span class=\"{1}\">{2}</span>{3}</li>\n",
                      EscapeHtml(run.id), run.ok ? "ok" : "failed", EscapeHtml(run.Status()),
                      run.reused ? " (reused)" : "");
    }
    html += "</ul>\n";
  }

  if (!tables.empty()) {
    html += "<h2 id=\"tables\">Tables</h2>\n";
    for (const Table& t : tables) html += RenderTable(t, ReportFormat::kHtml);
  }
  if (!r.runs.empty()) {
    html += "<h2 id=\"across-runs\">Across runs</h2>\n" + SessionFigures(r, u, figures);
  }
  for (const LogResult& log : r.logs) {
    html += fmt::format("<h2 id=\"log-{0}\">Log {0}</h2>\n<p>{1}</p>\n", EscapeHtml(log.id),
                        EscapeHtml(log.Status()));
    html += LogFigures(log, figures);
  }
  // Every run has its section, a failed one with its reason (the run list links here).
  for (const RunResult& run : r.runs) {
    html += fmt::format("<h2 id=\"run-{0}\">Run {0}</h2>\n", EscapeHtml(run.id));
    if (!run.ok) {
      html += fmt::format("<p class=\"failed\">{}</p>\n", EscapeHtml(run.Status()));
    }
    if (!run.measured.xmax.empty()) html += RunFigure(run, u, figures);
    if (!run.measured.calibrations.empty()) html += CalibrationFigure(run, u, figures);
    // A failed run's photo too: it is the one the user must look at.
    for (const PhotoOverlay& o : run.measured.overlays) html += OverlayFigure(o);
    html += CalibrationOverlays(run.measured.calibrations);
  }
  return html + "</body>\n</html>\n";
}

}  // namespace

std::string RenderHtmlReport(const SessionResult& r) {
  Figures figures;
  return BuildPage(r, figures);
}

std::vector<std::pair<std::string, std::string>> RenderStaticFigures(const SessionResult& r) {
  Figures figures;
  BuildPage(r, figures);
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [name, plot] : figures.plots()) out.emplace_back(name, RenderSvg(plot));
  return out;
}

}  // namespace impactlab
