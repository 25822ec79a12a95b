#include "synth/session_generator.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <tuple>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "io/errors.h"
#include "io/trace.h"
#include "synth/experiment.h"
#include "synth/photocell.h"
#include "synth/randomised_photo.h"

namespace impactlab {
namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

constexpr double kLength = 22.0;      // in, the thesis's pendula
constexpr double kGravity = 385.644;  // in/s^2
constexpr double kWeight = 2.23;      // lbf, one bar
constexpr double kStiffness = 4.6e5;  // lbf/in, about the thesis's K avg
constexpr int kContactImpact = 2;     // the thesis showed the second impact

// One run of a preset: its release displacement and damping ratio.
struct RunPlan {
  std::string id;
  double x0 = 0.0;
  double zeta = 0.0;
  enum class Form { kPhoto, kCsv, kTyped } form = Form::kPhoto;
};

// Damping ratio of Table 2's starred pair (a, b): e = (X_b/X_a)^(1/(b-a)).
double ZetaFromPair(double xa, double xb, int impacts) {
  const double log_e = std::log(xb / xa) / impacts;
  return -log_e / std::hypot(log_e, std::numbers::pi);
}

std::vector<RunPlan> PresetRuns(const SynthOptions& options) {
  std::vector<RunPlan> runs;
  if (options.preset == "thesis") {
    runs = {{"0.115", 0.115, ZetaFromPair(0.068, 0.052, 1)},
            {"0.234", 0.234, ZetaFromPair(0.176, 0.117, 1)},
            {"0.323", 0.323, ZetaFromPair(0.169, 0.110, 1)},
            {"0.405", 0.405, ZetaFromPair(0.293, 0.195, 1)},
            {"0.478", 0.478, ZetaFromPair(0.345, 0.273, 1)},
            {"0.598", 0.598, ZetaFromPair(0.416, 0.312, 1)},
            {"0.713", 0.713, ZetaFromPair(0.510, 0.411, 1)},
            {"1.519", 1.519, ZetaFromPair(0.679, 0.516, 1)}};
  } else {
    runs = {{"0.405", 0.405, 0.129}, {"0.713", 0.713, 0.0685}};
  }
  if (options.csv_run) runs.push_back({"csv-0.550", 0.55, 0.09, RunPlan::Form::kCsv});
  if (options.typed_run) runs.push_back({"typed-0.350", 0.35, 0.11, RunPlan::Form::kTyped});
  return runs;
}

// The 1-2-5 step at or above `raw`, as a scope's volts/div switch offers.
double NiceStep(double raw) {
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * decade >= raw * (1.0 - 1e-12)) return m * decade;
  }
  return 10.0 * decade;
}

// Volts/div and zero position that put [v_lo, v_hi] inside the band.
TraceSettings FitToBand(double v_lo, double v_hi, double band_lo, double band_hi,
                        double time_per_div, double t0_div) {
  TraceSettings s;
  s.time_per_div = time_per_div;
  s.t0_div = t0_div;
  s.band_div = {band_lo, band_hi};
  s.volts_per_div = NiceStep((v_hi - v_lo) / (0.85 * (band_hi - band_lo)));
  s.zero_div = 0.5 * (band_lo + band_hi) - 0.5 * (v_lo + v_hi) / s.volts_per_div;
  return s;
}

class Generator {
 public:
  Generator(std::filesystem::path folder, const SynthOptions& options)
      : folder_(std::move(folder)), options_(options), rng_(options.seed) {}

  SynthSummary Run();

 private:
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng_); }
  std::uint64_t NextSeed() { return rng_(); }

  std::vector<double> Noisy(const SimulatedPhotocell& cell, const std::vector<double>& x);
  // `beam` and `bands`: the randomised style's draws (bands only for run photos).
  std::string WritePhoto(const std::string& stem, const OscillographScene& scene, json& truth,
                         const BeamLook* beam = nullptr, const RunBands* bands = nullptr);
  void WriteRun(const RunPlan& plan);
  std::string CalibrationToml(const std::string& id, const std::string& cell, double x0,
                              const std::string& source, const TraceSettings& s);

  std::filesystem::path folder_;
  SynthOptions options_;
  std::mt19937_64 rng_;
  std::string manifest_;
  json truth_runs_ = json::array();
  json truth_calibrations_ = json::array();
  SynthSummary summary_;
};

std::string TraceToml(const std::string& table, const TraceSettings& s, const std::string& source) {
  std::string out = fmt::format("[{}]\n", table);
  if (!source.empty()) out += fmt::format("csv = \"{}\"\n", source);
  out += fmt::format(
      "time_per_div = {:.6g}\nvolts_per_div = {:.6g}\nzero_div = {:.6g}\nband_div = [{:.6g}, "
      "{:.6g}]\nt0_div = {:.10g}\n",
      s.time_per_div, s.volts_per_div, s.zero_div, s.band_div[0], s.band_div[1], s.t0_div);
  if (s.impact) out += fmt::format("impact = {}\n", *s.impact);
  return out;
}

json SettingsJson(const TraceSettings& s) {
  return {{"time_per_div", s.time_per_div},
          {"volts_per_div", s.volts_per_div},
          {"zero_div", s.zero_div},
          {"band_div", s.band_div},
          {"t0_div", s.t0_div}};
}

std::vector<double> Generator::Noisy(const SimulatedPhotocell& cell, const std::vector<double>& x) {
  const std::vector<double> v = cell.Volts(x);
  const double span = std::abs(cell.Volts(cell.x_hi()) - cell.Volts(cell.x_lo()));
  return AddGaussianNoise(v, options_.trace_noise * span, NextSeed());
}

std::string Generator::WritePhoto(const std::string& stem, const OscillographScene& scene,
                                  json& truth, const BeamLook* beam, const RunBands* bands) {
  RenderOptions render;
  render.style = options_.style;
  const bool randomised = beam != nullptr;
  // The randomised style draws its own size unless one is asked for.
  render.width_px = options_.width_px > 0 ? options_.width_px
                    : randomised          ? 0
                                          : (options_.preset == "quick" ? 1000 : 0);
  render.seed = NextSeed();
  // A real chopper switches at ~100 kHz, invisible at 0.5 s/div: 0.01 div
  // slots (a pixel or two) draw the traces chopped but nearly continuous, as
  // such a photo shows them. Long dashes would hide rebound peaks in the gaps.
  render.chop_dash_div = 0.01;
  // The randomised style draws the chopper anywhere from that to long dashes.
  if (randomised) ApplyBeamLook(*beam, render);
  const auto start = Clock::now();
  RenderedPhoto photo = RenderOscillograph(scene, render);
  // Prints and phone pictures come as JPEG; the others as lossless PNG. A
  // randomised photo is stored as it was drawn: JPEG at its own quality, else
  // PNG or (one in four) TIFF, 8 or 16 bits.
  bool jpeg = options_.style == PhotoStyle::kPolaroid || options_.style == PhotoStyle::kPhone ||
              options_.style == PhotoStyle::kLowres;
  int quality = 90;
  std::string lossless_ext = ".png";
  if (randomised) {
    jpeg = photo.jpeg_quality > 0;
    quality = photo.jpeg_quality;
    if (jpeg && photo.image.depth() == CV_16U) photo.image.convertTo(photo.image, CV_8U, 1.0 / 257);
    if (std::uniform_int_distribution<int>(0, 3)(rng_) == 0) lossless_ext = ".tif";
  }
  const std::string file = stem + (jpeg ? ".jpg" : lossless_ext);
  const std::vector<int> params = jpeg ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, quality}
                                       : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 6};
  if (!cv::imwrite((folder_ / file).string(), photo.image, params)) {
    throw InputError({folder_ / file, "", std::nullopt}, "cannot write the photo");
  }
  summary_.render_seconds += std::chrono::duration<double>(Clock::now() - start).count();
  ++summary_.photos;

  const CameraMapping& m = photo.mapping;
  json traces = json::array();
  for (const TraceTruth& t : photo.traces) {
    json points = json::array();
    const std::size_t stride = std::max<std::size_t>(1, t.time_s.size() / 400);
    for (std::size_t i = 0; i < t.time_s.size(); i += stride) {
      points.push_back({t.time_s[i], t.centre_px[i].x, t.centre_px[i].y});
    }
    traces.push_back({{"name", t.name}, {"points_t_x_y_px", points}});
  }
  truth = {{"file", file},
           {"width_px", photo.image.cols},
           {"height_px", photo.image.rows},
           {"mapping",
            {{"homography",
              {m.homography(0, 0), m.homography(0, 1), m.homography(0, 2), m.homography(1, 0),
               m.homography(1, 1), m.homography(1, 2), m.homography(2, 0), m.homography(2, 1),
               m.homography(2, 2)}},
             {"radial_k1", m.radial_k1},
             {"distortion_centre_px", {m.distortion_centre_px.x, m.distortion_centre_px.y}},
             {"distortion_radius_px", m.distortion_radius_px}}},
           {"traces", traces}};
  if (randomised) truth["look"] = LookJson(photo, *beam, bands, scene.divisions);
  return file;
}

std::string Generator::CalibrationToml(const std::string& id, const std::string& cell, double x0,
                                       const std::string& source, const TraceSettings& s) {
  std::string out = fmt::format("\n[[calibration]]\nid = \"{}\"\ncell = \"{}\"\n", id, cell);
  out += fmt::format("initial_displacement = {:.6g}\n", x0);
  const bool csv = source.rfind("traces/", 0) == 0;
  if (!csv) out += fmt::format("photo = \"{}\"\n", source);
  out += TraceToml("calibration.trace", s, csv ? source : "");
  return out;
}

void Generator::WriteRun(const RunPlan& plan) {
  const double mass = kWeight / kGravity;
  ExperimentOptions o;
  o.release_x_right = plan.x0 * (1.0 + Uniform(-0.004, 0.004));
  o.release_x_left = plan.x0 * (1.0 + Uniform(-0.004, 0.004));
  o.left_length_excess = Uniform(-0.0015, 0.0015);
  o.left_mass_excess = Uniform(-0.001, 0.001);
  o.left_release_delay_s = Uniform(-0.0005, 0.0005);
  o.kelvin_voigt.stiffness = kStiffness * (1.0 + Uniform(-0.01, 0.01));
  o.kelvin_voigt.damping = 2.0 * plan.zeta * std::sqrt(o.kelvin_voigt.stiffness * mass);
  const bool poynting_thomson = options_.contact_model == "poynting-thomson";
  if (poynting_thomson) {
    // A standard linear solid of about the same stiffness and restitution range.
    o.contact_model = ContactModelKind::kPoyntingThomson;
    o.poynting_thomson.stiffness_1 = 0.75 * o.kelvin_voigt.stiffness;
    o.poynting_thomson.stiffness_2 = 0.5 * o.kelvin_voigt.stiffness;
    o.poynting_thomson.damping = 2.0 * o.kelvin_voigt.damping;
  }
  o.impact_count = 7;
  o.sample_rate_hz = 2000.0;
  if (options_.wire_anomalies) {
    o.wires.enabled = true;
    o.wires.mass_per_length = SupportWireOptions::kThesisAnomalyMassPerLength;
  }
  const auto start = Clock::now();
  const ExperimentResult r = SimulateExperiment(o);
  summary_.simulate_seconds += std::chrono::duration<double>(Clock::now() - start).count();
  // The manifest's X0 is half the measured gap between the bars at release.
  const double x0 = 0.5 * (r.right.release_x + r.left.release_x);

  PhotocellOptions cell_options;
  cell_options.x_lo = -1.1 * plan.x0;  // the calibration swing passes to -X0
  cell_options.x_hi = 1.1 * plan.x0;
  cell_options.nonlinearity = options_.photocell_nonlinearity;
  cell_options.polarity = PhotocellPolarity::kRandom;
  const SimulatedPhotocell right = SimulatedPhotocell::FromSeed(NextSeed(), cell_options);
  const SimulatedPhotocell left = SimulatedPhotocell::FromSeed(NextSeed(), cell_options);

  json truth = {{"id", plan.id},
                {"form", plan.form == RunPlan::Form::kPhoto ? "photo"
                         : plan.form == RunPlan::Form::kCsv ? "csv"
                                                            : "typed-in"},
                {"initial_displacement", x0},
                {"first_rebound", 1},
                {"contact_model", ContactModelName(o.contact_model)},
                {"experiment", TruthJson(r)},
                {"photocells", {{"right", right}, {"left", left}}}};
  // Session numbering: first_rebound = 1, so rebound n is the experiment's n + 1.
  json xmax = json::array(), xmax_right = json::array(), xmax_left = json::array(),
       t_peak = json::array(), duration = json::array();
  for (std::size_t n = 1; n < r.rebounds_average.size(); ++n) {
    xmax.push_back(r.rebounds_average[n].xmax);
    xmax_right.push_back(r.rebounds_right[n].xmax);
    xmax_left.push_back(r.rebounds_left[n].xmax);
    t_peak.push_back(r.rebounds_average[n].peak_time_s);
    duration.push_back(r.rebounds_average[n].duration_s);
  }
  if (poynting_thomson) {
    truth["poynting_thomson"] = {{"mass", mass},
                                 {"stiffness_1", o.poynting_thomson.stiffness_1},
                                 {"stiffness_2", o.poynting_thomson.stiffness_2},
                                 {"damping", o.poynting_thomson.damping},
                                 {"separation", "kinematic"}};
  } else {
    truth["kelvin_voigt"] = {{"mass", mass},
                             {"stiffness", o.kelvin_voigt.stiffness},
                             {"damping", o.kelvin_voigt.damping},
                             {"zeta", plan.zeta},
                             {"separation", "kinematic"}};
  }
  const ImpactTruth& shown = r.impacts.at(kContactImpact - 1);
  truth["restitution"] = shown.restitution;
  truth["rebounds"] = {{"xmax", xmax},
                       {"xmax_right", xmax_right},
                       {"xmax_left", xmax_left},
                       {"t_peak", t_peak},
                       {"duration", duration}};
  truth["contact"] = {{"impact", kContactImpact},
                      {"start_s", shown.start_time_s},
                      {"duration_s", shown.duration_s}};

  manifest_ += fmt::format("\n[[run]]\nid = \"{}\"\ninitial_displacement = {:.6g}\n", plan.id, x0);
  if (plan.form == RunPlan::Form::kTyped) {
    std::string values;
    for (std::size_t n = 0; n < 5 && n < xmax.size(); ++n) {
      values += fmt::format("{}{:.3f}", n ? ", " : "", xmax[n].get<double>());
    }
    manifest_ +=
        fmt::format("rebounds = [{}]\ncontact_time = {:.4g}\nrebound_uncertainty = 0.0005\n",
                    values, shown.duration_s);
    truth_runs_.push_back(truth);
    return;
  }

  // The randomised style's scope settings for this run's photos follow from
  // a stream of their own, so that they never shift the experiment's draws.
  const bool randomised =
      options_.style == PhotoStyle::kRandomised && plan.form == RunPlan::Form::kPhoto;
  std::mt19937_64 look_rng(randomised ? NextSeed() : 0);

  // Calibrations: each bar released alone from its X0, sweep triggered at release.
  const bool csv = plan.form == RunPlan::Form::kCsv;
  const std::string ext_note = csv ? "csv" : "photo";
  json calibrations = json::array();
  for (const auto& [cell, curve, release] : {std::tuple{"right", &right, r.right.release_x},
                                             std::tuple{"left", &left, r.left.release_x}}) {
    CalibrationSweepOptions sweep_options;
    sweep_options.release_x = release;
    sweep_options.duration_s = 0.5;
    sweep_options.sample_rate_hz = 4000.0;
    const CalibrationSweep sweep = MakeCalibrationSweep(*curve, sweep_options);
    const std::vector<double> volts = Noisy(*curve, sweep.x);
    const auto [v_lo, v_hi] = std::minmax_element(volts.begin(), volts.end());
    const std::array<double, 2> band =
        randomised ? DrawCalibrationBand(look_rng) : std::array<double, 2>{-3.6, 3.6};
    const TraceSettings s = FitToBand(*v_lo, *v_hi, band[0], band[1], 0.05, 0.0);
    const std::string id = fmt::format("{}-{}", cell[0] == 'r' ? "R" : "L", plan.id);
    std::string source;
    json cal_truth = {{"id", id}, {"cell", cell}, {"release_x", release}, {"form", ext_note}};
    if (csv) {
      source = fmt::format("traces/{}.csv", id);
      WriteTraceCsv(folder_ / source, Trace{sweep.time_s, volts, {}});
    } else {
      OscillographScene scene;
      scene.traces.push_back({"calibration", sweep.time_s, volts, s, BeamMode::kContinuous, 0});
      json photo_truth;
      if (randomised) {
        const BeamLook beam = DrawBeamLook(look_rng);
        scene.traces.back().brightness = beam.contact_brightness;
        source = WritePhoto("calibration/" + id, scene, photo_truth, &beam);
      } else {
        source = WritePhoto("calibration/" + id, scene, photo_truth);
      }
      cal_truth["photo"] = photo_truth;
    }
    cal_truth["settings"] = SettingsJson(s);
    truth_calibrations_.push_back(cal_truth);
    manifest_ = manifest_.substr(0, manifest_.rfind("\n[[run]]")) +
                CalibrationToml(id, cell, release, source, s) +
                manifest_.substr(manifest_.rfind("\n[[run]]"));
    calibrations.push_back(id);
  }
  manifest_ += fmt::format("calibration = {{ right = \"{}\", left = \"{}\" }}\nfirst_rebound = 1\n",
                           calibrations[0].get<std::string>(), calibrations[1].get<std::string>());

  // Slow sweep: 0.5 s/div from 0.1 s before release, about six rebounds.
  std::vector<double> time = {-0.1}, xr = {r.right.release_x}, xl = {r.left.release_x};
  for (std::size_t i = 0; i < r.samples.time_s.size(); ++i) {
    time.push_back(r.samples.time_s[i]);
    xr.push_back(r.samples.x_right[i]);
    xl.push_back(r.samples.x_left[i]);
  }
  const std::vector<double> vr = Noisy(right, xr), vl = Noisy(left, xl);
  const auto [r_lo, r_hi] = std::minmax_element(vr.begin(), vr.end());
  const auto [l_lo, l_hi] = std::minmax_element(vl.begin(), vl.end());
  const RunBands bands = randomised ? DrawRunBands(look_rng) : FixedRunBands();
  const TraceSettings right_settings =
      FitToBand(*r_lo, *r_hi, bands.right[0], bands.right[1], 0.5, 0.2);
  const TraceSettings left_settings =
      FitToBand(*l_lo, *l_hi, bands.left[0], bands.left[1], 0.5, 0.2);

  // Fast delayed sweep on the second beam: 50 us/div from 100 us before the
  // shown impact; the contact circuit is high while the bars touch.
  const double window_start = shown.start_time_s - 100e-6;
  TraceSettings contact_settings;
  contact_settings.time_per_div = 50e-6;
  contact_settings.volts_per_div = 2.0;
  contact_settings.zero_div = -3.9;
  contact_settings.band_div = {bands.contact[0], bands.contact[1]};
  contact_settings.t0_div = -window_start / contact_settings.time_per_div;
  contact_settings.impact = kContactImpact;
  const double low = 0.05, high = 2.45, window_end = window_start + 10.5 * 50e-6;
  if (randomised) {
    // The step spans its drawn share of the band, its low level anywhere that
    // keeps the high one inside.
    const double height = bands.contact[1] - bands.contact[0];
    const double fraction = bands.contact_step_fraction;
    contact_settings.volts_per_div = NiceStep((high - low) / (fraction * height));
    contact_settings.zero_div =
        bands.contact[0] +
        std::uniform_real_distribution<double>(0.05, 0.95 - fraction)(look_rng) * height -
        low / contact_settings.volts_per_div;
  }
  const std::vector<double> contact_t = {window_start,     shown.start_time_s, shown.start_time_s,
                                         shown.end_time_s, shown.end_time_s,   window_end};
  const std::vector<double> contact_v = {low, low, high, high, low, low};

  if (csv) {
    const std::string base = fmt::format("traces/{}", plan.id);
    WriteTraceCsv(folder_ / (base + "-right.csv"), Trace{time, vr, {}});
    WriteTraceCsv(folder_ / (base + "-left.csv"), Trace{time, vl, {}});
    // A digital scope samples the contact circuit every 0.5 us.
    Trace contact;
    for (double t = window_start; t < window_end; t += 0.5e-6) {
      contact.time_s.push_back(t);
      const bool touching = t >= shown.start_time_s && t < shown.end_time_s;
      contact.volts.push_back(touching ? high : low);
    }
    WriteTraceCsv(folder_ / (base + "-contact.csv"), contact);
    manifest_ += TraceToml("run.traces.right", right_settings, base + "-right.csv");
    manifest_ += TraceToml("run.traces.left", left_settings, base + "-left.csv");
    manifest_ += TraceToml("run.traces.contact", contact_settings, base + "-contact.csv");
  } else {
    OscillographScene scene;
    scene.traces.push_back({"right", time, vr, right_settings, BeamMode::kChopped, 0});
    scene.traces.push_back({"left", time, vl, left_settings, BeamMode::kChopped, 0});
    scene.traces.push_back(
        {"contact", contact_t, contact_v, contact_settings, BeamMode::kContinuous, 1});
    json photo_truth;
    std::string file;
    if (randomised) {
      const BeamLook beam = DrawBeamLook(look_rng);
      scene.traces[0].brightness = scene.traces[1].brightness = beam.slow_brightness;
      scene.traces[2].brightness = beam.contact_brightness;
      file = WritePhoto("runs/" + plan.id, scene, photo_truth, &beam, &bands);
    } else {
      file = WritePhoto("runs/" + plan.id, scene, photo_truth);
    }
    // The photo key belongs before the trace tables.
    manifest_.insert(manifest_.rfind("calibration = {"), fmt::format("photo = \"{}\"\n", file));
    manifest_ += TraceToml("run.traces.right", right_settings, "");
    manifest_ += TraceToml("run.traces.left", left_settings, "");
    manifest_ += TraceToml("run.traces.contact", contact_settings, "");
    truth["photo"] = photo_truth;
  }
  truth["settings"] = {{"right", SettingsJson(right_settings)},
                       {"left", SettingsJson(left_settings)},
                       {"contact", SettingsJson(contact_settings)}};
  truth_runs_.push_back(truth);
}

SynthSummary Generator::Run() {
  std::error_code ec;
  if (std::filesystem::exists(folder_) && !std::filesystem::is_empty(folder_, ec)) {
    throw InputError({folder_, "", std::nullopt}, "the output folder exists and is not empty");
  }
  for (const char* sub : {"calibration", "runs", "traces"}) {
    std::filesystem::create_directories(folder_ / sub, ec);
    if (ec) throw InputError({folder_ / sub, "", std::nullopt}, "cannot create the folder");
  }
  manifest_ = fmt::format(
      "# Generated by `impactlab synth --preset {} --style {} --seed {}`: a simulated\n"
      "# experiment, not a measurement. Ground truth is in the truth file.\n"
      "format = 1\ntitle = \"Simulated steel bars ({} preset, {} photos, seed {})\"\n"
      "units = \"in-lbf-s\"\n\n[apparatus]\npendulum_length = {}\nweight = {}\narrangement = "
      "\"pair\"\n\n[scope]\ndivisions = [10, 8]\n",
      options_.preset, PhotoStyleName(options_.style), options_.seed, options_.preset,
      PhotoStyleName(options_.style), options_.seed, kLength, kWeight);
  for (const RunPlan& plan : PresetRuns(options_)) WriteRun(plan);
  std::ofstream(folder_ / "session.toml") << manifest_;
  for (const char* sub : {"calibration", "runs", "traces"}) {
    if (std::filesystem::is_empty(folder_ / sub, ec)) std::filesystem::remove(folder_ / sub, ec);
  }
  summary_.runs = static_cast<int>(truth_runs_.size());
  summary_.truth = {{"schema", "impactlab-synth-truth"},
                    {"version", 1},
                    {"preset", options_.preset},
                    {"style", PhotoStyleName(options_.style)},
                    {"seed", options_.seed},
                    {"units", "in-lbf-s"},
                    {"apparatus",
                     {{"pendulum_length", kLength},
                      {"gravity", kGravity},
                      {"weight", kWeight},
                      {"mass", kWeight / kGravity}}},
                    {"wire_anomalies", options_.wire_anomalies},
                    {"runs", truth_runs_},
                    {"calibrations", truth_calibrations_}};
  return summary_;
}

}  // namespace

bool SynthOptions::Check(std::string* error) const {
  if (preset != "thesis" && preset != "quick") {
    *error = fmt::format("preset must be \"thesis\" or \"quick\", got \"{}\"", preset);
    return false;
  }
  if (width_px != 0 && (width_px < 400 || width_px > 8000)) {
    *error = fmt::format("width must be 400..8000 px, got {}", width_px);
    return false;
  }
  if (!(photocell_nonlinearity >= 0.0 && photocell_nonlinearity <= 1.0)) {
    *error =
        fmt::format("photocell nonlinearity must be in [0, 1], got {}", photocell_nonlinearity);
    return false;
  }
  if (contact_model != "kelvin-voigt" && contact_model != "poynting-thomson") {
    *error = fmt::format("contact model must be kelvin-voigt or poynting-thomson, got \"{}\"",
                         contact_model);
    return false;
  }
  if (!(trace_noise >= 0.0 && trace_noise < 0.1)) {
    *error = fmt::format("trace noise must be in [0, 0.1), got {}", trace_noise);
    return false;
  }
  return true;
}

SynthSummary GenerateSession(const std::filesystem::path& folder, const SynthOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw std::invalid_argument(error);
  return Generator(folder, options).Run();
}

}  // namespace impactlab
