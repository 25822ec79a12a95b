// plan -> simulate -> write: PlanSession draws every random choice
// (synth/session_plan.h); per run, SimulateRun and PhotographRun compute values
// (synth/session_simulation.h, synth/session_photos.h), the manifest's and the
// truth's entries follow from them (synth/session_records.h), and
// synth/session_writer.h writes the files. A run is written before the next is
// simulated, so a thesis session holds one run's photos in memory at a time.
#include "synth/session_generator.h"

#include <chrono>
#include <stdexcept>

#include <fmt/format.h>

#include "synth/session_photos.h"
#include "synth/session_plan.h"
#include "synth/session_records.h"
#include "synth/session_simulation.h"
#include "synth/session_writer.h"

namespace impactlab {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
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
  const SessionPlan plan = PlanSession(options);
  CreateSessionFolder(folder);

  SynthSummary summary;
  summary.manifest = ManifestHeader(options);
  nlohmann::json truth_runs = nlohmann::json::array();
  nlohmann::json truth_calibrations = nlohmann::json::array();
  for (const RunPlan& run_plan : plan.runs) {
    auto start = Clock::now();
    const SimulatedRun run = SimulateRun(run_plan);
    summary.simulate_seconds += SecondsSince(start);
    start = Clock::now();
    const RunPhotos photos = PhotographRun(run_plan, run, options);
    WritePhotos(folder, photos);
    summary.render_seconds += SecondsSince(start);
    WriteCsvTraces(folder, run_plan, run);

    for (Calibration& calibration : ManifestCalibrations(run_plan, run, photos)) {
      summary.manifest.calibrations.push_back(std::move(calibration));
    }
    summary.manifest.runs.push_back(ManifestRun(run_plan, run, photos));
    truth_runs.push_back(RunTruth(run_plan, run, photos));
    for (nlohmann::json& truth : CalibrationTruths(run_plan, run, photos)) {
      truth_calibrations.push_back(std::move(truth));
    }
    int run_photos = static_cast<int>(photos.run.has_value());
    for (const auto& photo : photos.calibrations) run_photos += photo.has_value();
    summary.photos += run_photos;
    if (options.on_progress) {
      options.on_progress(
          {run_plan.id, run_photos, summary.manifest.runs.size(), plan.runs.size()});
    }
  }
  FinishSessionFolder(folder, summary.manifest);
  summary.runs = static_cast<int>(plan.runs.size());
  summary.truth = SessionTruth(options, std::move(truth_runs), std::move(truth_calibrations));
  return summary;
}

}  // namespace impactlab
