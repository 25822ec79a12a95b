#include <filesystem>
#include <string>

#include <fmt/core.h>

#include "cli/commands.h"
#include "cli/version.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"

namespace impactlab::cli {

void AddReduceCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path session;
    std::filesystem::path output = "results.h5";
    std::string convention, separation;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("reduce", "Reduce a lab session folder to an HDF5 results file");
  cmd->add_option("session", args->session, "Session folder (with session.toml)")->required();
  cmd->add_option("-o,--output", args->output, "Results file (written atomically)")
      ->capture_default_str();
  cmd->add_option("--convention", args->convention,
                  "Pendulum: exact or thesis (overrides [reduction] convention)")
      ->check(CLI::IsMember({"exact", "thesis"}));
  cmd->add_option("--separation", args->separation,
                  "Kelvin-Voigt contact end: kinematic or force (overrides the manifest)")
      ->check(CLI::IsMember({"kinematic", "force"}));
  cmd->add_flag("-q,--quiet", args->quiet, "Print only errors");
  cmd->callback([&action, args] {
    action = [args] {
      const ManifestReadResult manifest = ReadManifest(args->session);
      ReduceOptions options;
      if (!args->convention.empty()) options.convention = ParseConvention(args->convention);
      if (!args->separation.empty()) options.separation = ParseSeparation(args->separation);
      options.producer = std::string("impactlab ") + kVersion;
      SessionResult result = ReduceSession(manifest.session, options);
      for (const ManifestWarning& w : manifest.warnings) {
        result.warnings.insert(result.warnings.begin(),
                               fmt::format("{}: {}", FormatLocation(w.where), w.message));
      }
      WriteResults(result, args->output);
      for (const std::string& w : result.warnings) fmt::print(stderr, "warning: {}\n", w);
      for (const RunResult& run : result.runs) {
        if (!run.ok) fmt::print(stderr, "run {} failed: {}\n", run.id, run.failure);
      }
      const int failed = result.FailedRuns();
      if (!args->quiet) {
        fmt::print(stderr, "{} run(s): {} ok, {} failed; results in {}\n", result.runs.size(),
                   result.runs.size() - failed, failed, args->output.string());
      }
      return failed > 0 ? kExitRunsFailed : kExitOk;
    };
  });
}

}  // namespace impactlab::cli
