#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "cli/commands.h"
#include "cli/progress_line.h"
#include "cli/stage_flags.h"
#include "cli/version.h"
#include "io/atomic_file.h"
#include "io/manifest.h"
#include "pipeline/previous_results.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"

namespace impactlab::cli {
namespace {

// The earlier results file at `path` to reuse unchanged runs from, its notes
// said unless quiet.
std::optional<SessionResult> EarlierResults(const std::filesystem::path& path, bool quiet,
                                            const Session& session) {
  std::vector<std::string> notes;
  std::optional<SessionResult> previous = PreviousResults(path, session, &notes);
  if (!quiet) {
    for (const std::string& note : notes) fmt::print(stderr, "note: {}\n", note);
  }
  return previous;
}

// What a reduce could not do, entry by entry: every kind the manifest has.
struct FailureCount {
  std::size_t runs = 0, reused = 0, logs = 0;
  std::size_t predictions_asked = 0, predictions_failed = 0;  // with products = fit only
  // Entries the manifest rejected that no count above holds (a calibration,
  // whose runs fail too; a run, log or prediction a shorter --only skips), as
  // "calibration R".
  std::vector<std::string> rejected;
  Products products = Products::kFit;

  std::size_t Total() const { return runs + logs + predictions_failed + rejected.size(); }
  // "8 run(s): 8 ok (0 reused), 0 failed; 1 prediction(s): 0 made, 1 failed; 0 log(s): 0
  // failed" (and "; rejected by the manifest: calibration R" when one was).
  std::string Summary(const SessionResult& result) const {
    std::string text;
    if (products == Products::kCalibration) {
      text = fmt::format("{} calibration(s)", result.calibrations.size());
    } else {
      text = fmt::format("{} run(s): {} ok ({} reused), {} failed", result.runs.size(),
                         result.runs.size() - runs, reused, runs);
      if (predictions_asked > 0) {
        text += fmt::format("; {} prediction(s): {} made, {} failed", predictions_asked,
                            predictions_asked - predictions_failed, predictions_failed);
      }
      text += fmt::format("; {} log(s): {} failed", result.logs.size(), logs);
    }
    if (!rejected.empty())
      text += fmt::format("; rejected by the manifest: {}", fmt::join(rejected, ", "));
    return text;
  }
};

// A prediction is asked for by each [[prediction]] of the manifest, read or
// rejected, and made only with --only fit; one asked for and not in the
// results failed (the warnings say why).
FailureCount CountFailures(const Session& session, Products products, const SessionResult& result) {
  FailureCount count;
  count.products = products;
  for (const RunResult& run : result.runs) {
    count.runs += run.ok ? 0 : 1;
    count.reused += run.reused ? 1 : 0;
  }
  for (const LogResult& log : result.logs) count.logs += log.ok ? 0 : 1;
  if (products == Products::kFit) {
    count.predictions_asked = session.predictions.size() + session.Rejected("prediction").size();
    count.predictions_failed =
        count.predictions_asked - std::min(count.predictions_asked, result.predictions.size());
  }
  for (const RejectedEntry& entry : session.rejected) {
    const bool counted =
        (entry.table == "run" && products != Products::kCalibration) ||
        ((entry.table == "log" || entry.table == "prediction") && products == Products::kFit);
    if (!counted) count.rejected.push_back(entry.table + " " + entry.id);
  }
  return count;
}

}  // namespace

void AddReduceCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path session;
    std::filesystem::path output = "results.h5";
    std::string convention, separation, only = "fit";
    int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    bool quiet = false, fresh = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("reduce", "Reduce a lab session folder to an HDF5 results file");
  cmd->add_option("session", args->session,
                  "Session folder (with session.toml), or its session.toml")
      ->required();
  cmd->add_option("-o,--out,--output", args->output, "Results file (written atomically)")
      ->capture_default_str();
  cmd->add_option("--convention", args->convention,
                  "Pendulum: exact or thesis (overrides [reduction] convention)")
      ->check(CLI::IsMember({"exact", "thesis"}));
  cmd->add_option("--separation", args->separation,
                  "Kelvin-Voigt contact end: kinematic or force (overrides the manifest)")
      ->check(CLI::IsMember({"kinematic", "force"}));
  cmd->add_option("--only", args->only,
                  "Products: calibration, rebounds (and calibration) or fit (everything)")
      ->check(CLI::IsMember({"calibration", "rebounds", "fit"}))
      ->capture_default_str();
  cmd->add_option("-j,--jobs", args->jobs, "Runs reduced in parallel")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_flag("--fresh", args->fresh,
                "Measure every run again instead of reusing unchanged runs from the output file");
  cmd->add_flag("-q,--quiet", args->quiet, "Print only errors");
  const auto stage_flags = std::make_shared<StageFlags>(*cmd);
  cmd->callback([&action, args, stage_flags] {
    action = [args, stage_flags] {
      // Its clock is the command's: the summary's seconds are the line's.
      ProgressLine line(args->quiet);
      CheckOutputPath(args->output, SessionFolderOf(args->session));  // before any work
      const ManifestReadResult manifest = ReadManifest(args->session);
      ReduceOptions options;
      if (!args->convention.empty()) options.convention = ParseConvention(args->convention);
      if (!args->separation.empty()) options.separation = ParseSeparation(args->separation);
      options.producer = std::string("impactlab ") + kVersion;
      options.products = args->only == "calibration" ? Products::kCalibration
                         : args->only == "rebounds"  ? Products::kRebounds
                                                     : Products::kFit;
      options.jobs = args->jobs;
      options.overrides = stage_flags->Given();
      const std::optional<SessionResult> previous =
          args->fresh ? std::nullopt : EarlierResults(args->output, args->quiet, manifest.session);
      if (previous) options.previous = &*previous;
      // Measuring the runs is counted item by item; the fits across them and
      // writing the file come after, and the line says when they do.
      const bool fits_follow = options.products == Products::kFit && !manifest.session.runs.empty();
      if (line.Shown()) {
        options.on_progress = [&line, fits_follow](const ReduceProgress& p) {
          const std::string item =
              fmt::format("{} {}{}", p.item, p.ok ? "ok" : "failed", p.reused ? " (reused)" : "");
          if (p.done == p.total && fits_follow && p.item.starts_with("run ")) {
            line.Show(
                fmt::format("{}: {}; fitting across the runs", line.Count(p.done, p.total), item));
          } else {
            line.Show(fmt::format("{}: {}", line.Count(p.done, p.total, "left to measure"), item));
          }
        };
      }
      SessionResult result = ReduceSession(manifest.session, options);
      for (const ManifestWarning& w : manifest.warnings) {
        result.warnings.insert(result.warnings.begin(),
                               fmt::format("{}: {}", FormatLocation(w.where), w.message));
      }
      line.Show(fmt::format("{:.1f} s: writing {}", line.Seconds(), args->output.string()));
      WriteResults(result, args->output);
      line.Clear();
      for (const std::string& w : result.warnings) fmt::print(stderr, "warning: {}\n", w);
      for (const RunResult& run : result.runs) {
        if (!run.ok) fmt::print(stderr, "run {} failed: {}\n", run.id, run.reason);
      }
      for (const LogResult& log : result.logs) {
        if (!log.ok) fmt::print(stderr, "log {} {}\n", log.id, log.Status());
      }
      const FailureCount count = CountFailures(manifest.session, options.products, result);
      if (!args->quiet) {
        fmt::print(stderr, "{}; results in {} ({:.2f} s)\n", count.Summary(result),
                   args->output.string(), line.Seconds());
      }
      // The exit status says what the summary counts: anything failed.
      return count.Total() > 0 ? kExitRunsFailed : kExitOk;
    };
  });
}

}  // namespace impactlab::cli
