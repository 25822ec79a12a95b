#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

#include <fmt/core.h>

#include "cli/commands.h"
#include "cli/stage_flags.h"
#include "cli/version.h"
#include "io/atomic_file.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "pipeline/run_fingerprint.h"

namespace impactlab::cli {
namespace {

// An earlier results file of the same session, if there is a readable one,
// without the runs whose values must not be reused (a note for each: a
// hand-edited or corrupted file is never trusted). Typed-in runs never reuse,
// so their values there are not looked at.
std::optional<SessionResult> PreviousResults(const std::filesystem::path& path, bool quiet,
                                             const Session& session) {
  if (!std::filesystem::exists(path)) return std::nullopt;
  SessionResult previous;
  try {
    previous = ReadResults(path);
  } catch (const std::exception& e) {
    if (!quiet) fmt::print(stderr, "note: not reusing {}: {}\n", path.string(), e.what());
    return std::nullopt;
  }
  std::erase_if(previous.runs, [&](const RunResult& run) {
    const auto in_session = std::find_if(session.runs.begin(), session.runs.end(),
                                         [&](const Run& r) { return r.id == run.id; });
    if (in_session == session.runs.end() || in_session->HasTypedRebounds()) return false;
    if (run.measured.xmax.empty()) return false;  // nothing measured there: nothing to reuse
    const std::string problem = ReuseProblem(run.measured);
    if (problem.empty()) return false;
    if (!quiet) {
      fmt::print(stderr, "note: not reusing run {} from {}: {}\n", run.id, path.string(), problem);
    }
    return true;
  });
  return previous;
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
  cmd->add_option("-o,--output", args->output, "Results file (written atomically)")
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
      const auto start = std::chrono::steady_clock::now();
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
          args->fresh ? std::nullopt : PreviousResults(args->output, args->quiet, manifest.session);
      if (previous) options.previous = &*previous;
      // Progress on a terminal only: logs and pipes get the summary alone.
      const bool show_progress = !args->quiet && isatty(fileno(stderr)) != 0;
      if (show_progress) {
        // One line, rewritten: count, elapsed, an estimate of what is left, the last item.
        options.on_progress = [start](const ReduceProgress& p) {
          const double elapsed =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          const double left =
              elapsed / static_cast<double>(p.done) * static_cast<double>(p.total - p.done);
          fmt::print(stderr, "\r\033[K[{}/{}] {:.1f} s, ~{:.0f} s left: {} {}{}", p.done, p.total,
                     elapsed, left, p.item, p.ok ? "ok" : "failed", p.reused ? " (reused)" : "");
          if (p.done == p.total) fmt::print(stderr, "\r\033[K");
        };
      }
      SessionResult result = ReduceSession(manifest.session, options);
      for (const ManifestWarning& w : manifest.warnings) {
        result.warnings.insert(result.warnings.begin(),
                               fmt::format("{}: {}", FormatLocation(w.where), w.message));
      }
      WriteResults(result, args->output);
      for (const std::string& w : result.warnings) fmt::print(stderr, "warning: {}\n", w);
      for (const RunResult& run : result.runs) {
        if (!run.ok) fmt::print(stderr, "run {} failed: {}\n", run.id, run.reason);
      }
      for (const LogResult& log : result.logs) {
        if (!log.ok) fmt::print(stderr, "log {} {}\n", log.id, log.Status());
      }
      const int failed = result.FailedRuns();
      const auto reused = std::count_if(result.runs.begin(), result.runs.end(),
                                        [](const RunResult& r) { return r.reused; });
      if (!args->quiet) {
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (options.products == Products::kCalibration) {
          fmt::print(stderr, "{} calibration(s); results in {} ({:.2f} s)\n",
                     result.calibrations.size(), args->output.string(), seconds);
        } else {
          const auto failed_logs = std::count_if(result.logs.begin(), result.logs.end(),
                                                 [](const LogResult& l) { return !l.ok; });
          const auto failed_runs = failed - failed_logs;
          fmt::print(stderr,
                     "{} run(s): {} ok ({} reused), {} failed; {} log(s): {} failed; results in "
                     "{} ({:.2f} s)\n",
                     result.runs.size(), result.runs.size() - failed_runs, reused, failed_runs,
                     result.logs.size(), failed_logs, args->output.string(), seconds);
        }
      }
      // A calibration or prediction the manifest rejected fails nothing else,
      // but the user must still hear of it through the exit status.
      const bool rejected = !manifest.session.rejected.empty();
      return failed > 0 || rejected ? kExitRunsFailed : kExitOk;
    };
  });
}

}  // namespace impactlab::cli
