// `impactlab simulate two-link`: a session folder of encoder and accelerometer
// logs from the two-link manipulator's simulator (multibody/, docs/two-link.md),
// in the format `reduce` reads (docs/session-format.md, "Logs").
//
// Per case N (a log id of its own, where given, replaces caseN):
// logs/caseN-experiment.csv, the logger's view (encoder counts on
// the motors, accelerometer volts with Gaussian noise in 16-bit steps) of the
// `experiment` parameters; logs/caseN-simulation.csv, the `simulation`
// parameters' clean record in SI; and, unless left out, state/caseN-*.csv,
// the full state history of each. Columns: t, enc1, enc2 (q1, q4),
// acc1..acc4 (mid beam 1, RB2, mid beam 2, RB4).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fit/two_link_fit.h"
#include "multibody/two_link_parameters.h"
#include "multibody/two_link_simulation.h"

namespace impactlab {

// A simulation done, for TwoLinkLogOptions::on_progress.
struct TwoLinkLogProgress {
  int case_number = 1;
  std::string source;  // "experiment" or "simulation"
  std::size_t done = 0, total = 0;
};

struct TwoLinkLogOptions {
  std::vector<int> cases = {1};  // of 1, 2, 3
  TwoLinkParameters simulation = TwoLinkParameters::Nominal();
  TwoLinkParameters experiment = TwoLinkParameters::Nominal();  // its logger adds the noise
  std::uint64_t seed = 1;
  bool write_state = true;
  TwoLinkSimulationOptions integration;
  std::string title;                 // the manifest's; empty: a default
  std::vector<std::string> comment;  // the manifest's opening comment; empty: a default
  // With one case: its log's id, which names its files and its truth (empty:
  // "caseN").
  std::string log_id;
  // A NaN (acc1), a duplicated row and a missing row in each experiment log,
  // a fifth, two fifths and three fifths of the way in; the truth lists them
  // under the log's "defects".
  bool inject_defects = false;
  // Called after each simulation (seconds each: the command shows it on a terminal).
  std::function<void(const TwoLinkLogProgress&)> on_progress;
};

struct TwoLinkLogSummary {
  nlohmann::json truth;               // per case: impact times, events, the parameters
  std::vector<int> rows;              // per case, in each of its files
  std::vector<std::string> warnings;  // "case N source: ..." where the model was stretched
};

// Writes `folder`/session.toml, logs/ and state/. The folder must not exist
// or be empty; a run that fails removes what it wrote. Throws std::invalid_argument for bad
// options, InputError for a folder that cannot be written, std::domain_error when the model
// refuses a case's motion (its record's reason).
TwoLinkLogSummary WriteTwoLinkSession(const std::filesystem::path& folder,
                                      const TwoLinkLogOptions& options);

// What the experiment's logger records of a record (the counts and volts
// caseN-experiment.csv holds, noise from `seed`), in SI as `reduce` reads
// them: the fit's input without the files. A session's case N uses the seed
// CaseSeed(seed, N).
TwoLinkMeasurement LoggedMeasurement(const TwoLinkParameters& parameters,
                                     const TwoLinkRecord& record, std::uint64_t seed);
std::uint64_t CaseSeed(std::uint64_t seed, int case_number);

// A simulation's log in SI (angles in rad, accelerations in m/s^2), the
// columns above. Throws InputError when the file cannot be written.
void WriteTwoLinkSimulationCsv(const std::filesystem::path& file, const TwoLinkRecord& record);

}  // namespace impactlab
