// Measuring a run from its traces (CSV or photo): calibrate each photocell,
// convert both displacement traces, average them as the thesis did, extract
// the rebounds, and measure the contact pulse.
#pragma once

#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "calibration/photocell_calibration.h"
#include "io/session.h"
#include "io/trace.h"
#include "pipeline/session_result.h"
#include "pipeline/stage_options.h"

namespace impactlab {

// A photocell calibration as reduce computed it, with its photo's overlay.
struct CalibratedCell {
  CalibrationResult calibration;
  std::optional<PhotoOverlay> overlay;  // photo calibrations only
  StageSeconds cost;                    // its digitizing (load) and fitting (calibrate)
  SettingValues settings;               // the stage settings it was made with
};

// Calibrations are shared by runs; each is computed once per reduce, by
// whichever thread asks first (reduce asks ahead of the runs), while others
// wait for it, with the calibration's own options.
class CalibrationCache {
 public:
  // `options_of` gives a calibration's options (it may throw InputError: the
  // calibration then fails with it).
  using OptionsOf = std::function<StageOptions(const Calibration&)>;
  CalibrationCache(const Session& session, const Pendulum& pendulum, OptionsOf options_of)
      : session_(session), pendulum_(pendulum), options_of_(std::move(options_of)) {}
  // Throws InputError (file, key, reason) when the calibration cannot be made.
  // The first caller that passes `charge` is charged the calibration's cost;
  // later ones are not, so a session's stage times add up.
  const CalibratedCell& Get(const std::string& calibration_id, StageSeconds* charge = nullptr);

 private:
  using Entry = std::shared_future<std::shared_ptr<const CalibratedCell>>;
  std::shared_ptr<const CalibratedCell> Compute(const std::string& calibration_id) const;

  const Session& session_;
  const Pendulum& pendulum_;
  OptionsOf options_of_;
  std::mutex mutex_;
  std::map<std::string, Entry> entries_;
  std::set<std::string> charged_;
};

// The calibration as the results file keeps it (points decimated to <= 500).
CellCalibration SummariseCalibration(const std::string& id, const std::string& cell,
                                     double release_x, const CalibratedCell& calibrated);

// A run measured from its traces, and the time each stage took.
struct MeasuredTraceRun {
  RunMeasurement measured;
  StageSeconds seconds;
};

// Why a run failed, as its results say it: an InputError (and an
// IncompleteMeasurement) names its own file and key; anything else is said
// with the manifest and the run's key.
std::string RunFailureReason(const std::exception& error, const Session& session, const Run& run);

// A run whose measurement failed part way: its reason (file, key), and what
// was measured before (the digitized photo's overlay, the calibrations),
// which the results file and the report keep beside the reason.
class IncompleteMeasurement : public std::runtime_error {
 public:
  IncompleteMeasurement(std::string reason, RunMeasurement partial);
  const RunMeasurement& partial() const { return partial_; }

 private:
  RunMeasurement partial_;
};

// The run's calibrations, rebounds and contact pulse, measured with the
// run's `options`. Throws IncompleteMeasurement when the run fails after its
// photo was digitized or a calibration was used, else InputError or
// std::exception with the reason.
MeasuredTraceRun MeasureTraceRun(const Run& run, const Session& session, const Pendulum& pendulum,
                                 const StageOptions& options, CalibrationCache& calibrations);

}  // namespace impactlab
