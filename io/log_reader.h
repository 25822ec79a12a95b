// Streaming reader of encoder / accelerometer logs: the `[[log]]` CSV files of
// session-format.md (docs/logs.md, "Reading rules").
//
// A log is a CSV file with a header line naming its columns, then one row per
// scan: the time column (s) and any number of channels. The reader converts the
// channels the manifest names to SI (encoder counts -> rad, accelerometer volts
// -> m/s^2) and hands them on in blocks of at most `block_rows` samples, so a log
// of tens of millions of rows is read in bounded memory.
//
// The analyses need one uniformly sampled record. Every departure from it is
// reported with the file and line, and handled by one rule:
//   - a row with a missing, non-numeric or non-finite value (NaN, inf), or too
//     few columns: dropped (its sample then counts as missing, below);
//   - a row whose time equals the previous row's: dropped (the first is kept);
//   - a row whose time is before the previous row's: dropped;
//   - a row closer than half an interval to the previous one: dropped;
//   - a step between kept rows of k intervals (k >= 2): the k - 1 missing
//     samples are filled by linear interpolation when k - 1 <= max_fill_samples,
//     else the log is refused (InputError at that line);
//   - a step further than `jitter_tolerance` intervals from a whole number of
//     intervals: kept at its index, reported as irregular.
// More dropped rows than `max_bad_fraction` of the data rows refuse the log.
// The nominal interval is the median step of the first `rate_estimate_rows` rows.
// Empty lines and lines starting with '#' are skipped.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "io/session.h"

namespace impactlab {

inline constexpr double kStandardGravity = 9.80665;  // m/s^2, converts accelerometer V/g

// What a channel measures, from its manifest keys.
enum class LogChannelKind {
  kAngle,         // encoder: `counts_per_rev` given; rad
  kAcceleration,  // accelerometer: `sensitivity` given; m/s^2
  kOther,         // neither: taken in SI as it stands
};

LogChannelKind KindOf(const LogChannel& channel);
const char* UnitsOf(LogChannelKind kind);  // "rad", "m/s^2", "SI"

// An experiment log holds raw counts and volts; a simulation log is in SI already
// (session-format.md).
enum class LogSource { kExperiment, kSimulation };
const char* NameOf(LogSource source);  // "experiment", "simulation"

struct LogReadOptions {
  std::size_t block_rows = 65536;         // samples per block handed to the callback
  std::size_t rate_estimate_rows = 1024;  // leading rows whose median step is the interval
  double jitter_tolerance = 0.25;         // intervals a step may stray from a whole number before
                                          // it is reported as irregular
  std::size_t max_fill_samples = 16;      // longest run of missing samples filled by interpolation
  double max_bad_fraction = 0.01;         // largest fraction of data rows that may be dropped
  std::size_t max_listed_issues = 50;     // issues kept with their line; the rest only counted
  // When set, the file must lie inside this folder and is opened beneath it
  // (io/session_file.h); a log named by a manifest is read so.
  std::filesystem::path session_folder = {};

  // The settings (options/settings.h); the folder is the session's.
  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("block_rows", self.block_rows, "samples per block read");
    visit("rate_estimate_rows", self.rate_estimate_rows, "leading rows the interval is taken from");
    visit("jitter_tolerance", self.jitter_tolerance, "intervals a step may stray, 1");
    visit("max_fill_samples", self.max_fill_samples, "longest run of missing samples filled");
    visit("max_bad_fraction", self.max_bad_fraction, "largest fraction of rows dropped, 1");
    visit("max_listed_issues", self.max_listed_issues, "issues kept with their line");
  }

  bool Check(std::string* error) const;
};

enum class LogIssueKind : int {
  kBadValue = 0,    // missing, non-numeric or non-finite value, or too few columns: dropped
  kDuplicateTime,   // same time as the previous row: dropped
  kBackwardTime,    // time before the previous row: dropped
  kIrregularStep,   // step off the grid by more than the tolerance (dropped if < 1/2 step)
  kMissingSamples,  // a gap; the missing samples were interpolated
};
inline constexpr int kLogIssueKinds = 5;
const char* NameOf(LogIssueKind kind);

struct LogIssue {
  LogIssueKind kind = LogIssueKind::kBadValue;
  long long line = 0;  // 1-based line in the file
  std::string column;  // the column at fault, when one is
  std::string detail;
};

struct LogReadReport {
  std::filesystem::path file;
  long long data_rows = 0;         // rows after the header (blank and comment lines excluded)
  long long samples = 0;           // samples delivered: kept rows plus filled samples
  long long dropped_rows = 0;      // rows left out by the rules above
  long long filled_samples = 0;    // samples interpolated into gaps
  double sample_interval_s = 0.0;  // nominal interval (median of the leading steps)
  double mean_interval_s = 0.0;    // (last time - first time) / (samples - 1)
  double first_time_s = 0.0;
  double last_time_s = 0.0;
  std::array<long long, kLogIssueKinds> issue_counts{};  // per LogIssueKind
  std::vector<LogIssue> issues;  // the first max_listed_issues, in file order

  long long IssueCount() const;
  // One line per issue kind with a count, and the listed issues as FILE:LINE: text.
  std::string Summary() const;
};

// Samples [first_sample, first_sample + time_s.size()) of the uniform record.
struct LogBlock {
  long long first_sample = 0;
  double sample_interval_s = 0.0;           // the nominal interval
  long long estimated_samples = 0;          // whole log, from the file size (exact at the end)
  std::vector<double> time_s;               // s, as in the file (interpolated in filled gaps)
  std::vector<std::vector<double>> values;  // [channel][sample], SI, channels' order
};

using LogBlockCallback = std::function<void(const LogBlock&)>;

// Reads `file`, calling `on_block` for every block in order. Throws InputError
// (file, column, line) for a missing file or column, a gap too long to fill, too
// many bad rows or fewer than two samples; std::invalid_argument for bad options.
LogReadReport ReadLogCsv(const std::filesystem::path& file, const std::string& time_column,
                         const std::vector<LogChannel>& channels, LogSource source,
                         const LogReadOptions& options, const LogBlockCallback& on_block);

// A log's record, streamed: each call reads it from its start, hands every
// block to `on_block` in order and returns what reading found. The analysis
// of a long log reads it twice (whole and decimated, then around the impact at
// full rate), so it is handed the record to read, not the samples.
using LogRecord = std::function<LogReadReport(const LogBlockCallback& on_block)>;

// A log's records: its experiment's and, when it has one, its simulation's.
struct LogRecords {
  LogRecord experiment;
  std::optional<LogRecord> simulation;
};

// The records of a manifest's `[[log]]`: its CSV files, read with
// `options` from inside the log's session folder.
LogRecords LogFileRecords(const Log& log, const LogReadOptions& options);

// The whole log in memory (small logs, tests).
struct LogSeries {
  std::vector<double> time_s;
  std::vector<std::vector<double>> values;  // [channel][sample]
  LogReadReport report;
};
LogSeries ReadLogSeries(const std::filesystem::path& file, const std::string& time_column,
                        const std::vector<LogChannel>& channels, LogSource source,
                        const LogReadOptions& options = {});

}  // namespace impactlab
