// `impactlab synth-logs`: a session folder with an experiment/simulation pair of
// encoder and accelerometer logs of the two-link flexible arm, the experiment
// with hidden differences, and its truth (synth/arm_logs.h, docs/logs.md).
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "cli/commands.h"
#include "io/errors.h"
#include "synth/arm_logs.h"

namespace impactlab::cli {

void AddSynthLogsCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path out, truth;
    ArmLogOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "synth-logs",
      "Simulate encoder/accelerometer logs of the two-link flexible arm striking a surface, "
      "with truth");
  cmd->add_option("-o,--out,--output", args->out,
                  "Session folder to create (must not exist or be empty)")
      ->required();
  cmd->add_option("--seed", args->options.seed, "Random seed: the same seed, the same files")
      ->capture_default_str();
  cmd->add_option("--truth", args->truth, "Ground-truth JSON (default: OUT.truth.json beside it)");
  cmd->add_option("--case", args->options.case_number, "The document's case: 1, 2 or 3")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  cmd->add_option("--rate", args->options.sample_rate_hz, "Sampling rate, Hz")
      ->capture_default_str();
  cmd->add_option("--duration", args->options.duration_s, "Record length, s")
      ->capture_default_str();
  cmd->add_option("--noise", args->options.noise_factor,
                  "Accelerometer noise, as a multiple of the default (0: none)")
      ->capture_default_str();
  cmd->add_option("--id", args->options.log_id, "The log's id in the manifest")
      ->capture_default_str();
  cmd->add_flag("--defects", args->options.inject_defects,
                "Put a NaN, a duplicated row and a missing row into the experiment log");
  cmd->callback([&action, args] {
    action = [args] {
      std::filesystem::path truth = args->truth;
      if (truth.empty()) {
        truth = args->out.lexically_normal();
        if (truth.filename().empty()) truth = truth.parent_path();
        truth += ".truth.json";
      }
      const TwoLinkLogSummary summary =
          WriteTwoLinkSession(args->out, ArmLogSession(args->options));
      std::ofstream out(truth);
      out << summary.truth.dump(1) << "\n";
      if (!out) throw InputError({truth, "", std::nullopt}, "cannot write the truth file");
      const nlohmann::json& log = summary.truth[args->options.log_id];
      fmt::print(stderr,
                 "2 logs of {} rows in {}; first impact at {:.4f} s (experiment), {:.4f} s "
                 "(simulation); truth in {}\n",
                 summary.rows.at(0), args->out.string(),
                 log["experiment"]["impact_time_s"].get<double>(),
                 log["simulation"]["impact_time_s"].get<double>(), truth.string());
      for (const std::string& warning : summary.warnings) {
        fmt::print(stderr, "warning: {}\n", warning);
      }
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
