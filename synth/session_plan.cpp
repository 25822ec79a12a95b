#include "synth/session_plan.h"

#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

namespace impactlab {
namespace {

// One run of a preset: its release displacement and damping ratio.
struct PresetRun {
  std::string id;
  double x0 = 0.0;
  double zeta = 0.0;
  RunForm form = RunForm::kPhoto;
};

// Damping ratio of Table 2's starred pair (a, b): e = (X_b/X_a)^(1/(b-a)).
double ZetaFromPair(double xa, double xb, int impacts) {
  const double log_e = std::log(xb / xa) / impacts;
  return -log_e / std::hypot(log_e, std::numbers::pi);
}

std::vector<PresetRun> PresetRuns(const SynthOptions& options) {
  std::vector<PresetRun> runs;
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
  if (options.csv_run) runs.push_back({"csv-0.550", 0.55, 0.09, RunForm::kCsv});
  if (options.typed_run) runs.push_back({"typed-0.350", 0.35, 0.11, RunForm::kTyped});
  return runs;
}

// The session's random stream: every draw but the randomised style's scope
// settings, which each run draws from a stream of its own.
class SessionDraws {
 public:
  explicit SessionDraws(std::uint64_t seed) : random_(seed) {}
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(random_); }
  std::uint64_t Seed() { return random_(); }
  bool OneInFour() { return std::uniform_int_distribution<int>(0, 3)(random_) == 0; }

 private:
  std::mt19937_64 random_;
};

// `look`: the run's scope-settings stream, for the randomised style only.
PhotoPlan PlanPhoto(std::string stem, SessionDraws& draws, std::mt19937_64* look) {
  PhotoPlan photo;
  photo.stem = std::move(stem);
  if (look) photo.look = DrawBeamLook(*look);
  photo.render_seed = draws.Seed();
  if (look) photo.tiff_if_lossless = draws.OneInFour();
  return photo;
}

ExperimentOptions PlanExperiment(const PresetRun& preset, const SynthOptions& options,
                                 SessionDraws& draws) {
  const double mass = kSynthWeight / kSynthGravity;
  ExperimentOptions o;
  o.release_x_right = preset.x0 * (1.0 + draws.Uniform(-0.004, 0.004));
  o.release_x_left = preset.x0 * (1.0 + draws.Uniform(-0.004, 0.004));
  o.left_length_excess = draws.Uniform(-0.0015, 0.0015);
  o.left_mass_excess = draws.Uniform(-0.001, 0.001);
  o.left_release_delay_s = draws.Uniform(-0.0005, 0.0005);
  o.kelvin_voigt.stiffness = kSynthStiffness * (1.0 + draws.Uniform(-0.01, 0.01));
  o.kelvin_voigt.damping = 2.0 * preset.zeta * std::sqrt(o.kelvin_voigt.stiffness * mass);
  if (options.contact_model == "poynting-thomson") {
    // A standard linear solid of about the same stiffness and restitution range.
    o.contact_model = ContactModelKind::kPoyntingThomson;
    o.poynting_thomson.stiffness_1 = 0.75 * o.kelvin_voigt.stiffness;
    o.poynting_thomson.stiffness_2 = 0.5 * o.kelvin_voigt.stiffness;
    o.poynting_thomson.damping = 2.0 * o.kelvin_voigt.damping;
  }
  o.impact_count = 7;
  o.sample_rate_hz = 2000.0;
  if (options.wire_anomalies) {
    o.wires.enabled = true;
    o.wires.mass_per_length = SupportWireOptions::kThesisAnomalyMassPerLength;
  }
  return o;
}

RunPlan PlanRun(const PresetRun& preset, const SynthOptions& options, SessionDraws& draws) {
  RunPlan run;
  run.id = preset.id;
  run.form = preset.form;
  run.zeta = preset.zeta;
  run.experiment = PlanExperiment(preset, options, draws);
  run.photocells.x_lo = -1.1 * preset.x0;  // the calibration swing passes to -X0
  run.photocells.x_hi = 1.1 * preset.x0;
  run.photocells.nonlinearity = options.photocell_nonlinearity;
  run.photocells.polarity = PhotocellPolarity::kRandom;
  run.right_cell_seed = draws.Seed();
  run.left_cell_seed = draws.Seed();
  run.trace_noise = options.trace_noise;
  if (run.form == RunForm::kTyped) return run;

  // The randomised style's scope settings for this run's photos follow from
  // a stream of their own, so that they never shift the experiment's draws.
  const bool randomised = options.style == PhotoStyle::kRandomised && run.form == RunForm::kPhoto;
  std::mt19937_64 look_random(randomised ? draws.Seed() : 0);
  std::mt19937_64* look = randomised ? &look_random : nullptr;
  for (const char* cell : {"right", "left"}) {
    CalibrationPlan calibration;
    calibration.id = fmt::format("{}-{}", cell[0] == 'r' ? "R" : "L", run.id);
    calibration.cell = cell;
    calibration.noise_seed = draws.Seed();
    if (randomised) calibration.band_div = DrawCalibrationBand(look_random);
    if (run.form == RunForm::kPhoto) {
      calibration.photo = PlanPhoto("calibration/" + calibration.id, draws, look);
    } else {
      calibration.csv_file = fmt::format("traces/{}.csv", calibration.id);
    }
    run.calibrations.push_back(calibration);
  }
  run.right_noise_seed = draws.Seed();
  run.left_noise_seed = draws.Seed();
  if (randomised) {
    run.bands = DrawRunBands(look_random);
    // The step spans its drawn share of the band, its low level anywhere that
    // keeps the high one inside.
    run.contact_low_position = std::uniform_real_distribution<double>(
        0.05, 0.95 - run.bands.contact_step_fraction)(look_random);
  }
  if (run.form == RunForm::kPhoto) {
    run.photo = PlanPhoto("runs/" + run.id, draws, look);
  } else {
    for (const char* trace : {"right", "left", "contact"}) {
      run.csv_files[trace] = fmt::format("traces/{}-{}.csv", run.id, trace);
    }
  }
  return run;
}

}  // namespace

const char* RunFormName(RunForm form) {
  switch (form) {
    case RunForm::kPhoto:
      return "photo";
    case RunForm::kCsv:
      return "csv";
    case RunForm::kTyped:
      return "typed-in";
  }
  return "photo";
}

SessionPlan PlanSession(const SynthOptions& options) {
  SessionPlan plan;
  plan.options = options;
  SessionDraws draws(options.seed);
  for (const PresetRun& preset : PresetRuns(options)) {
    plan.runs.push_back(PlanRun(preset, options, draws));
  }
  return plan;
}

}  // namespace impactlab
