// Measuring a run from its traces (CSV or photo): calibrate each photocell,
// convert both displacement traces, average them as the thesis did, extract
// the rebounds, and measure the contact pulse.
#pragma once

#include <exception>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "calibration/photocell_calibration.h"
#include "io/errors.h"
#include "io/session.h"
#include "io/trace.h"
#include "pipeline/session_result.h"
#include "pipeline/stage_options.h"

namespace impactlab {

// A photocell calibration as reduce computed it, with its photo's overlay.
// When it cannot be made, `ok` is false, and `failed_at` (the file, and the
// manifest key a user can fix) and `reason` say why, as DigitizeResult does.
struct CalibratedCell {
  bool ok = false;
  InputLocation failed_at;
  std::string reason;
  CalibrationResult calibration;
  std::optional<PhotoOverlay> overlay;  // photo calibrations only
  StageSeconds cost;                    // its digitizing (load) and fitting (calibrate)
  SettingValues settings;               // the stage settings it was made with

  // "FILE: KEY: reason", as an InputError names it; empty when ok.
  std::string Failure() const;
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
  // A calibration that cannot be made (no such entry, a file that cannot be
  // read, a photo not read, a trace that does not calibrate) is a cell with
  // `ok` false; only a programming error is thrown, to every caller that asks.
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

// A run measured from its traces, and the time each stage took. When the
// measurement stops part way, `ok` is false, `failed_at` (the file, and the
// manifest key a user can fix) and `reason` say why, as DigitizeResult does,
// and `measured` keeps what was measured before (the digitized photo's
// overlay, the calibrations), which the results file and the report show
// beside the reason. A contact trace that cannot be read (not found on the
// photo, a CSV that cannot be read, no pulse on it) fails alone: the run is
// measured without a contact time, and `warnings` says why.
struct MeasuredTraceRun {
  bool ok = false;
  InputLocation failed_at;
  std::string reason;
  RunMeasurement measured;
  StageSeconds seconds;
  // What was not measured and why, "FILE: KEY: reason" each (a contact
  // trace that cannot be read); the rest of the run stands.
  std::vector<std::string> warnings;

  // "FILE: KEY: reason", as an InputError names it; empty when ok.
  std::string Failure() const;
};

// Why a run failed, as its results say it, from the exception `error` holds:
// an InputError names its own file and key; anything else is said with the
// manifest and the run's key.
std::string RunFailureReason(const std::exception_ptr& error, const Session& session,
                             const Run& run);

// The run's calibrations, rebounds and contact pulse, measured with the
// run's `options`. A run that cannot be measured (a bad manifest entry, a
// file that cannot be read, a photo not read, traces without enough
// rebounds) is a result with `ok` false; one whose contact trace alone
// cannot be read is measured without a contact time, with a warning; only a
// programming error is thrown.
MeasuredTraceRun MeasureTraceRun(const Run& run, const Session& session, const Pendulum& pendulum,
                                 const StageOptions& options, CalibrationCache& calibrations);

}  // namespace impactlab
