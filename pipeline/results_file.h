// The results file, layout 2 (docs/results.md; minimum in results-layout.md).
// Written atomically (temporary file, then rename); read back for the report
// and for the measurements `reduce` reuses, from files of layout 1 or 2.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "pipeline/session_result.h"

namespace impactlab {

inline constexpr int kResultsLayout = 2;

// Throws InputError naming the file if it cannot be written; an earlier file
// at `path` is then left as it was.
void WriteResults(const SessionResult& result, const std::filesystem::path& path);

// How much of a results file to read.
enum class ResultsReading {
  kEverything,
  // What a campaign tabulates (campaign/campaign.h): the session's own fields,
  // apparatus, specimen and settings; each run's status, maxima, contact time
  // and specimen; the contact laws and the model comparison. Not the runs'
  // own fits, curves, photos and calibrations, the joint fits, the logs or
  // the predictions, which are most of a file's objects.
  kEstimates,
  // What a later reduce reuses (ReadRunMeasurements): each run's status,
  // fingerprint and measurement, with its bars, photos and calibrations, but
  // not its fits.
  kRunMeasurements,
};

// Reads a results file of layout 1 or 2. Throws InputError naming the file
// and object for a file that is neither.
SessionResult ReadResults(const std::filesystem::path& path,
                          ResultsReading reading = ResultsReading::kEverything);

// Only what a later reduce reuses: the session's settings and, for each run
// `wanted` names, its status, fingerprint and measurement (no fits, no
// session-level results). Throws as ReadResults does.
SessionResult ReadRunMeasurements(const std::filesystem::path& path,
                                  const std::function<bool(const std::string&)>& wanted);

}  // namespace impactlab
