// The synthetic session's plan (synth/session_plan.h) holds every random
// choice, so the simulation follows from it alone.
#include "synth/session_plan.h"

#include <catch2/catch.hpp>

#include "synth/session_simulation.h"

namespace impactlab {
namespace {

SynthOptions QuickSeed11(PhotoStyle style) {
  SynthOptions options;
  options.preset = "quick";
  options.style = style;
  options.seed = 11;
  options.csv_run = true;
  options.typed_run = true;
  return options;
}

TEST_CASE(
    "synth: a randomised plan draws its first experiment as the other styles do, and its scope "
    "besides") {
  const SessionPlan clean = PlanSession(QuickSeed11(PhotoStyle::kClean));
  const SessionPlan randomised = PlanSession(QuickSeed11(PhotoStyle::kRandomised));
  REQUIRE(clean.runs.size() == 4);
  REQUIRE(randomised.runs.size() == clean.runs.size());
  // The first run's draws come before any photo's; later runs follow the
  // photos' draws, which the randomised style adds to.
  const ExperimentOptions& a = clean.runs[0].experiment;
  const ExperimentOptions& b = randomised.runs[0].experiment;
  CHECK(a.release_x_right == b.release_x_right);
  CHECK(a.left_release_delay_s == b.left_release_delay_s);
  CHECK(a.kelvin_voigt.stiffness == b.kelvin_voigt.stiffness);
  CHECK(clean.runs[0].right_cell_seed == randomised.runs[0].right_cell_seed);
  CHECK_FALSE(clean.runs[0].photo->look.has_value());
  CHECK(randomised.runs[0].photo->look.has_value());
  CHECK(randomised.runs[0].contact_low_position.has_value());
}

TEST_CASE("synth: a plan names each run's files and photographs only photo runs") {
  const SessionPlan plan = PlanSession(QuickSeed11(PhotoStyle::kPolaroid));
  const RunPlan& photo = plan.runs[0];
  CHECK(photo.form == RunForm::kPhoto);
  CHECK(photo.photo->stem == "runs/0.405");
  REQUIRE(photo.calibrations.size() == 2);
  CHECK(photo.calibrations[0].id == "R-0.405");
  CHECK(photo.calibrations[1].photo->stem == "calibration/L-0.405");
  CHECK(photo.csv_files.empty());
  const RunPlan& csv = plan.runs[2];
  CHECK(csv.form == RunForm::kCsv);
  CHECK_FALSE(csv.photo.has_value());
  CHECK(csv.csv_files.at("contact") == "traces/csv-0.550-contact.csv");
  CHECK(*csv.calibrations[0].csv_file == "traces/R-csv-0.550.csv");
  const RunPlan& typed = plan.runs[3];
  CHECK(typed.form == RunForm::kTyped);
  CHECK(typed.calibrations.empty());
}

TEST_CASE("synth: simulating a plan twice gives the same values") {
  const SessionPlan plan = PlanSession(QuickSeed11(PhotoStyle::kClean));
  const SimulatedRun a = SimulateRun(plan.runs[2]);
  const SimulatedRun b = SimulateRun(plan.runs[2]);
  CHECK(a.initial_displacement == b.initial_displacement);
  CHECK(a.right.volts == b.right.volts);
  CHECK(a.calibrations[1].trace.volts == b.calibrations[1].trace.volts);
  CHECK(a.contact_samples.volts == b.contact_samples.volts);
  // The scope's settings keep every trace inside its band.
  for (const ScopeTrace* trace : {&a.right, &a.left}) {
    for (double v : trace->volts) {
      const double y = trace->settings.zero_div + v / trace->settings.volts_per_div;
      CHECK(y >= trace->settings.band_div[0]);
      CHECK(y <= trace->settings.band_div[1]);
    }
  }
}

}  // namespace
}  // namespace impactlab
