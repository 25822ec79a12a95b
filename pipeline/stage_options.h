// Every stage's options as `reduce` uses them, and where their settings come
// from: the defaults, then the manifest's stage tables ([digitize],
// [photocell], [rebound_extraction], [fit], [log_analysis], [products]: the
// session-level products to make, pipeline/products.h), then an entry's own
// ([run.digitize], [calibration.photocell], [log.log_analysis], ...), then
// the command line's. One list per options struct (options/settings.h) gives
// the keys of all four, the fingerprint and the results file's attributes.
#pragma once

#include <string>

#include "calibration/photocell_calibration.h"
#include "digitize/options.h"
#include "fit/fit_options.h"
#include "io/session.h"
#include "pipeline/products.h"
#include "rebounds/rebound_extraction.h"
#include "signal/log_analysis.h"

namespace impactlab {

struct StageOptions {
  DigitizeOptions digitize;                     // photos: the graticule and the traces
  CalibrationOptions photocell;                 // each photocell's V(X) curve
  ReboundExtractionOptions rebound_extraction;  // the maxima from a displacement history
  FitOptions fit;                               // the least-squares fits
  LogAnalysisOptions log_analysis;              // encoder/accelerometer logs
  ProductOptions products;                      // the session-level products asked for

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("digitize", self.digitize, "");
    visit("photocell", self.photocell, "");
    visit("rebound_extraction", self.rebound_extraction, "");
    visit("fit", self.fit, "");
    visit("log_analysis", self.log_analysis, "");
    visit("products", self.products, "");
  }

  // False with `why` naming the first setting out of range ("digitize.traces.min_coverage ...").
  bool Check(std::string* why) const;
};

// `options` with `settings` applied in key order. Throws InputError at the
// setting's own location (manifest key and line, or command-line flag) for a
// key that names no setting, a value of the wrong kind, or options that then
// fail their Check.
StageOptions WithSettings(StageOptions options, const StageSettings& settings);

// The options one entry is reduced with: the session's (defaults and the
// stage tables), the entry's own, then `overrides` (the command line).
StageOptions SessionStageOptions(const StageOptions& defaults, const Session& session,
                                 const StageSettings& overrides);
StageOptions EntryStageOptions(const StageOptions& session_options, const StageSettings& entry,
                               const StageSettings& overrides);

// The settings of the stages named (e.g. {"digitize", "fit"}), by key.
SettingValues SettingsOfStages(const StageOptions& options,
                               std::initializer_list<std::string_view> stages);

// Every setting as a Markdown table (key, kind, default, meaning), for
// `impactlab settings` and docs/settings.md.
std::string SettingsTable(const StageOptions& defaults = {});

// Where a setting from the command line is located (InputLocation::file), so
// that an error about it reads as a bad command line, not a bad file.
inline constexpr char kCommandLine[] = "command line";

// Settings from the command line: `key=value` texts (io/manifest.h
// ParseSettingText), each located at the flag `--key` of kCommandLine.
StageSettings CommandLineSettings(
    const std::vector<std::pair<std::string, std::string>>& assignments);

}  // namespace impactlab
