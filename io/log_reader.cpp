#include "io/log_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string_view>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/session_file.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kReadChunkBytes = std::size_t{1} << 22;

std::string_view TrimAndUnquote(std::string_view s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) {
    s.remove_suffix(1);
  }
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

// Parses one field [begin, end) as a finite double; false for anything else
// (empty, text, NaN, inf). Leading '+' and surrounding blanks are allowed.
bool ParseField(const char* begin, const char* end, double& value) {
  while (begin < end && (*begin == ' ' || *begin == '\t')) ++begin;
  while (end > begin && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r')) --end;
  if (begin < end && *begin == '+') ++begin;
  if (begin == end) return false;
  const auto [stop, error] = std::from_chars(begin, end, value);
  return error == std::errc() && stop == end && std::isfinite(value);
}

// Factor from the file's unit to SI for one channel.
double ScaleToSi(const LogChannel& channel, LogSource source) {
  if (source == LogSource::kSimulation) return 1.0;
  switch (KindOf(channel)) {
    case LogChannelKind::kAngle:
      return 2.0 * std::numbers::pi / (*channel.counts_per_rev * channel.gear_ratio);
    case LogChannelKind::kAcceleration:
      return kStandardGravity / *channel.sensitivity;
    case LogChannelKind::kOther:
      return 1.0;
  }
  return 1.0;
}

// Applies the reading rules (log_reader.h) to the rows that parsed, and hands
// the uniform record on block by block.
class Sequencer {
 public:
  Sequencer(const fs::path& file, std::size_t channels, const LogReadOptions& options,
            LogReadReport& report, const LogBlockCallback& on_block)
      : file_(file),
        channels_(channels),
        options_(options),
        report_(report),
        on_block_(on_block),
        prev_values_(channels) {
    block_.values.resize(channels);
  }

  // A row whose values all parsed; `row` holds the time then the channels (SI).
  void Add(long long line, const double* row) {
    if (report_.sample_interval_s > 0.0) {
      Accept(line, row);
      return;
    }
    pending_lines_.push_back(line);
    pending_rows_.insert(pending_rows_.end(), row, row + 1 + channels_);
    if (pending_lines_.size() >= options_.rate_estimate_rows) ReleasePending();
  }

  void Finish() {
    ReleasePending();
    Flush();
  }

  void set_estimated_samples(long long n) { estimated_samples_ = n; }

  // Records an issue; `detail` is formatted only for the listed ones.
  template <typename Detail>
  void Report(LogIssueKind kind, long long line, std::string_view column, Detail&& detail) {
    ++report_.issue_counts[static_cast<int>(kind)];
    if (report_.issues.size() < options_.max_listed_issues) {
      report_.issues.push_back({kind, line, std::string(column), detail()});
    }
  }

 private:
  // The nominal interval: the median positive step of the buffered rows.
  void ReleasePending() {
    if (pending_lines_.empty()) return;
    const std::size_t width = 1 + channels_;
    std::vector<double> steps;
    for (std::size_t i = 1; i < pending_lines_.size(); ++i) {
      const double step = pending_rows_[i * width] - pending_rows_[(i - 1) * width];
      if (step > 0.0) steps.push_back(step);
    }
    if (steps.empty()) {
      throw InputError({file_, "", pending_lines_.back()},
                       "the log needs at least two rows with increasing time");
    }
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    report_.sample_interval_s = steps[steps.size() / 2];
    block_.sample_interval_s = report_.sample_interval_s;
    for (std::size_t i = 0; i < pending_lines_.size(); ++i) {
      Accept(pending_lines_[i], &pending_rows_[i * width]);
    }
    pending_lines_.clear();
    pending_rows_.clear();
  }

  void Accept(long long line, const double* row) {
    const double t = row[0];
    if (!have_prev_) {
      report_.first_time_s = t;
      Emit(t, row + 1);
      return;
    }
    const double dt = report_.sample_interval_s;
    const double step = t - prev_time_;
    if (step == 0.0) {
      ++report_.dropped_rows;
      Report(LogIssueKind::kDuplicateTime, line, "",
             [&] { return fmt::format("time {} repeats the previous row's (row dropped)", t); });
      return;
    }
    if (step < 0.0) {
      ++report_.dropped_rows;
      Report(LogIssueKind::kBackwardTime, line, "", [&] {
        return fmt::format("time {} is before the previous row's {} (row dropped)", t, prev_time_);
      });
      return;
    }
    const double intervals = step / dt;
    const long long k = std::llround(intervals);
    if (k == 0) {
      ++report_.dropped_rows;
      Report(LogIssueKind::kIrregularStep, line, "", [&] {
        return fmt::format("step {} s is under half the interval {} s (row dropped)", step, dt);
      });
      return;
    }
    if (std::abs(intervals - static_cast<double>(k)) > options_.jitter_tolerance) {
      Report(LogIssueKind::kIrregularStep, line, "", [&] {
        return fmt::format("step {} s is {:.3f} intervals of {} s (kept as {})", step, intervals,
                           dt, k);
      });
    }
    if (k >= 2) {
      const long long missing = k - 1;
      if (missing > static_cast<long long>(options_.max_fill_samples)) {
        throw InputError(
            {file_, "", line},
            fmt::format("a gap of {} s ({} missing samples) after time {}; at most {} are "
                        "filled by interpolation (the analyses need uniform sampling)",
                        step, missing, prev_time_, options_.max_fill_samples));
      }
      Report(LogIssueKind::kMissingSamples, line, "", [&] {
        return fmt::format("{} sample(s) missing between {} and {} s (interpolated)", missing,
                           prev_time_, t);
      });
      std::vector<double> filled(channels_);
      const double t0 = prev_time_;
      const std::vector<double> v0 = prev_values_;
      for (long long j = 1; j < k; ++j) {
        const double f = static_cast<double>(j) / static_cast<double>(k);
        for (std::size_t c = 0; c < channels_; ++c) filled[c] = v0[c] + f * (row[1 + c] - v0[c]);
        Emit(t0 + f * step, filled.data());
        ++report_.filled_samples;
      }
    }
    Emit(t, row + 1);
  }

  void Emit(double t, const double* values) {
    block_.time_s.push_back(t);
    for (std::size_t c = 0; c < channels_; ++c) block_.values[c].push_back(values[c]);
    prev_time_ = t;
    std::copy(values, values + channels_, prev_values_.begin());
    have_prev_ = true;
    ++report_.samples;
    report_.last_time_s = t;
    if (block_.time_s.size() >= options_.block_rows) Flush();
  }

  void Flush() {
    if (block_.time_s.empty()) return;
    block_.estimated_samples = std::max(estimated_samples_, report_.samples);
    on_block_(block_);
    block_.first_sample += static_cast<long long>(block_.time_s.size());
    block_.time_s.clear();
    for (auto& v : block_.values) v.clear();
  }

  const fs::path& file_;
  std::size_t channels_;
  const LogReadOptions& options_;
  LogReadReport& report_;
  const LogBlockCallback& on_block_;

  std::vector<long long> pending_lines_;
  std::vector<double> pending_rows_;  // rows of (time, channels...)
  bool have_prev_ = false;
  double prev_time_ = 0.0;
  std::vector<double> prev_values_;
  long long estimated_samples_ = 0;
  LogBlock block_;
};

// Which field of a row feeds which slot: 0 the time, 1 + c channel c.
struct ColumnMap {
  std::vector<int> slot_of_field;  // -1: not used
  std::size_t fields_needed = 0;   // the last used field + 1
};

ColumnMap MapHeader(std::string_view header, const fs::path& file, const std::string& time_column,
                    const std::vector<LogChannel>& channels) {
  std::vector<std::string> names;
  while (true) {
    const std::size_t comma = header.find(',');
    names.emplace_back(TrimAndUnquote(header.substr(0, comma)));
    if (comma == std::string_view::npos) break;
    header.remove_prefix(comma + 1);
  }
  // A UTF-8 byte-order mark, which some loggers write, is not part of the name.
  if (names[0].rfind("\xEF\xBB\xBF", 0) == 0) names[0].erase(0, 3);

  ColumnMap map;
  map.slot_of_field.assign(names.size(), -1);
  auto find = [&](const std::string& column, const std::string& key, int slot) {
    const auto count = std::count(names.begin(), names.end(), column);
    if (count != 1) {
      throw InputError({file, key, 1}, fmt::format("{} column \"{}\" in the header \"{}\"",
                                                   count == 0 ? "no" : "more than one", column,
                                                   fmt::join(names, ",")));
    }
    const auto field =
        static_cast<std::size_t>(std::find(names.begin(), names.end(), column) - names.begin());
    if (map.slot_of_field[field] != -1) {
      throw InputError({file, key, 1},
                       fmt::format("column \"{}\" is used twice by the manifest", column));
    }
    map.slot_of_field[field] = slot;
    map.fields_needed = std::max(map.fields_needed, field + 1);
  };
  find(time_column, "time_column", 0);
  for (std::size_t c = 0; c < channels.size(); ++c) {
    find(channels[c].column, "channels." + channels[c].name, static_cast<int>(c + 1));
  }
  return map;
}

}  // namespace

LogChannelKind KindOf(const LogChannel& channel) {
  if (channel.counts_per_rev) return LogChannelKind::kAngle;
  if (channel.sensitivity) return LogChannelKind::kAcceleration;
  return LogChannelKind::kOther;
}

const char* UnitsOf(LogChannelKind kind) {
  switch (kind) {
    case LogChannelKind::kAngle:
      return "rad";
    case LogChannelKind::kAcceleration:
      return "m/s^2";
    case LogChannelKind::kOther:
      return "SI";
  }
  return "SI";
}

const char* NameOf(LogSource source) {
  return source == LogSource::kExperiment ? "experiment" : "simulation";
}

const char* NameOf(LogIssueKind kind) {
  switch (kind) {
    case LogIssueKind::kBadValue:
      return "bad value";
    case LogIssueKind::kDuplicateTime:
      return "duplicated time";
    case LogIssueKind::kBackwardTime:
      return "time going back";
    case LogIssueKind::kIrregularStep:
      return "irregular step";
    case LogIssueKind::kMissingSamples:
      return "missing samples";
  }
  return "?";
}

bool LogReadOptions::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (block_rows < 1) return fail("block_rows must be at least 1");
  if (rate_estimate_rows < 2) return fail("rate_estimate_rows must be at least 2");
  if (!(jitter_tolerance > 0.0 && jitter_tolerance < 0.5)) {
    return fail("jitter_tolerance must lie in (0, 0.5) intervals");
  }
  if (!(max_bad_fraction >= 0.0 && max_bad_fraction <= 1.0)) {
    return fail("max_bad_fraction must lie in [0, 1]");
  }
  return true;
}

long long LogReadReport::IssueCount() const {
  long long n = 0;
  for (long long c : issue_counts) n += c;
  return n;
}

std::string LogReadReport::Summary() const {
  std::string text = fmt::format(
      "{}: {} rows, {} samples at {:.6g} s; {} dropped, {} interpolated\n", file.string(),
      data_rows, samples, sample_interval_s, dropped_rows, filled_samples);
  for (int k = 0; k < kLogIssueKinds; ++k) {
    if (issue_counts[k] > 0) {
      text += fmt::format("  {}: {}\n", NameOf(static_cast<LogIssueKind>(k)), issue_counts[k]);
    }
  }
  for (const LogIssue& issue : issues) {
    text += fmt::format("  {}\n",
                        FormatLocation({file, issue.column, issue.line}) + ": " + issue.detail);
  }
  return text;
}

LogReadReport ReadLogCsv(const fs::path& file, const std::string& time_column,
                         const std::vector<LogChannel>& channels, LogSource source,
                         const LogReadOptions& options, const LogBlockCallback& on_block) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("LogReadOptions: " + error);
  }
  // Opened without blocking and refused unless a regular file inside the session.
  SessionFile opened(options.session_folder, file);
  const auto file_bytes = static_cast<double>(opened.size());
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(::fdopen(opened.descriptor(), "rb"),
                                                     &std::fclose);
  if (!in) throw InputError({file, "", std::nullopt}, "cannot open the log file");
  opened.Release();  // the stream owns the descriptor now

  LogReadReport report;
  report.file = file;
  Sequencer sequencer(file, channels.size(), options, report, on_block);
  std::vector<double> scale(channels.size());
  for (std::size_t c = 0; c < channels.size(); ++c) scale[c] = ScaleToSi(channels[c], source);

  std::vector<double> row(1 + channels.size());
  ColumnMap map;
  bool have_header = false;
  long long line_number = 0;
  double bytes_read = 0.0;

  auto handle_line = [&](const char* begin, const char* end) {
    ++line_number;
    if (end > begin && end[-1] == '\r') --end;
    const char* first = begin;
    while (first < end && (*first == ' ' || *first == '\t')) ++first;
    if (first == end || *first == '#') return;
    if (!have_header) {
      map = MapHeader(std::string_view(begin, static_cast<std::size_t>(end - begin)), file,
                      time_column, channels);
      have_header = true;
      return;
    }
    ++report.data_rows;
    const char* p = begin;
    for (std::size_t field = 0; field < map.fields_needed; ++field) {
      const char* comma =
          static_cast<const char*>(std::memchr(p, ',', static_cast<std::size_t>(end - p)));
      if (comma == nullptr) comma = end;
      const int slot = map.slot_of_field[field];
      if (slot >= 0 && !ParseField(p, comma, row[static_cast<std::size_t>(slot)])) {
        ++report.dropped_rows;
        const std::string& column =
            slot == 0 ? time_column : channels[static_cast<std::size_t>(slot - 1)].column;
        sequencer.Report(LogIssueKind::kBadValue, line_number, column, [&] {
          return fmt::format(
              "expected a finite number, found \"{}\" (row dropped)",
              TrimAndUnquote(std::string_view(p, static_cast<std::size_t>(comma - p))));
        });
        return;
      }
      if (comma == end && field + 1 < map.fields_needed) {
        ++report.dropped_rows;
        sequencer.Report(LogIssueKind::kBadValue, line_number, "", [&] {
          return fmt::format("expected at least {} columns, found {} (row dropped)",
                             map.fields_needed, field + 1);
        });
        return;
      }
      p = comma + 1;
    }
    for (std::size_t c = 0; c < channels.size(); ++c) row[c + 1] *= scale[c];
    sequencer.Add(line_number, row.data());
  };

  // Whole lines are parsed in place; a line split by the chunk boundary moves
  // to the front of the buffer and the next chunk is read behind it.
  std::vector<char> buffer(kReadChunkBytes);
  std::size_t kept = 0;
  while (true) {
    if (buffer.size() - kept < kReadChunkBytes / 2) buffer.resize(buffer.size() * 2);
    const std::size_t got = std::fread(buffer.data() + kept, 1, buffer.size() - kept, in.get());
    const std::size_t filled = kept + got;
    const char* p = buffer.data();
    const char* end = buffer.data() + filled;
    if (bytes_read == 0.0 && filled > 0) {
      // The first blocks go out while this chunk is parsed: estimate the
      // log's length from the chunk's lines before that.
      const auto lines = static_cast<double>(std::count(p, end, '\n'));
      sequencer.set_estimated_samples(static_cast<long long>(file_bytes / filled * lines));
    }
    while (true) {
      const char* newline =
          static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
      if (newline == nullptr) break;
      handle_line(p, newline);
      p = newline + 1;
    }
    bytes_read += static_cast<double>(p - buffer.data());
    if (report.data_rows > 0) {
      sequencer.set_estimated_samples(
          static_cast<long long>(file_bytes / bytes_read * static_cast<double>(report.data_rows)));
    }
    kept = static_cast<std::size_t>(end - p);
    std::memmove(buffer.data(), p, kept);
    if (got == 0) {
      if (kept > 0) handle_line(buffer.data(), buffer.data() + kept);
      break;
    }
  }
  if (std::ferror(in.get())) throw InputError({file, "", std::nullopt}, "cannot read the log");
  if (!have_header) throw InputError({file, "", 1}, "the log is empty: expected a header line");

  sequencer.set_estimated_samples(report.samples);
  sequencer.Finish();
  if (report.samples < 2) {
    throw InputError({file, "", line_number},
                     fmt::format("the log needs at least two good rows, found {}", report.samples));
  }
  if (static_cast<double>(report.dropped_rows) >
      options.max_bad_fraction * static_cast<double>(report.data_rows)) {
    throw InputError({file, "", std::nullopt},
                     fmt::format("{} of {} rows were dropped, more than the {} % allowed:\n{}",
                                 report.dropped_rows, report.data_rows,
                                 100.0 * options.max_bad_fraction, report.Summary()));
  }
  report.mean_interval_s =
      (report.last_time_s - report.first_time_s) / static_cast<double>(report.samples - 1);
  return report;
}

LogRecords LogFileRecords(const Log& log, const LogReadOptions& options) {
  LogReadOptions read = options;
  read.session_folder = log.folder;
  const auto record = [&](const fs::path& file, LogSource source) -> LogRecord {
    return [file, source, read, time_column = log.time_column,
            channels = log.channels](const LogBlockCallback& on_block) {
      return ReadLogCsv(file, time_column, channels, source, read, on_block);
    };
  };
  LogRecords records{record(log.experiment, LogSource::kExperiment), std::nullopt};
  if (log.simulation) records.simulation = record(*log.simulation, LogSource::kSimulation);
  return records;
}

LogSeries ReadLogSeries(const fs::path& file, const std::string& time_column,
                        const std::vector<LogChannel>& channels, LogSource source,
                        const LogReadOptions& options) {
  LogSeries series;
  series.values.resize(channels.size());
  series.report =
      ReadLogCsv(file, time_column, channels, source, options, [&](const LogBlock& block) {
        series.time_s.insert(series.time_s.end(), block.time_s.begin(), block.time_s.end());
        for (std::size_t c = 0; c < channels.size(); ++c) {
          series.values[c].insert(series.values[c].end(), block.values[c].begin(),
                                  block.values[c].end());
        }
      });
  return series;
}

}  // namespace impactlab
