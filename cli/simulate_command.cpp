// `impactlab simulate two-link PARAMS.toml --case 1|2|3 -o DIR`: the two-link
// manipulator's simulator (multibody/, docs/two-link.md) writes a session of
// experiment-style logs that `reduce` reads, and the full state histories.
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/commands.h"
#include "cli/progress_line.h"
#include "cli/two_link_parameter_file.h"
#include "io/errors.h"
#include "multibody/two_link_toml.h"
#include "synth/two_link_logs.h"

namespace impactlab::cli {

void AddSimulateCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path parameters, experiment, out, truth;
    std::vector<int> cases = {1};
    TwoLinkLogOptions options;
    bool no_state = false;
    bool print = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* simulate =
      app.add_subcommand("simulate", "Simulate a mechanism and write its logs as a session");
  simulate->require_subcommand(1);
  CLI::App* cmd = simulate->add_subcommand(
      "two-link", "The two-link flexible manipulator of the second source document");
  cmd->add_option("parameters", args->parameters,
                  "Parameter file (TOML, SI; docs/two-link.md); default: the nominal set")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--print-parameters", args->print,
                "Print the parameters in effect as a parameter file, and stop");
  cmd->add_option("--case", args->cases, "The document's case(s): 1, 2, 3")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  cmd->add_option("-o,--out,--output", args->out,
                  "Session folder to create (must not exist or be empty)");
  cmd->add_option("--experiment", args->experiment,
                  "Parameters of the experiment (default: the same file); keys left out keep "
                  "the simulation's values")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", args->options.seed, "Noise seed: the same seed, the same files")
      ->capture_default_str();
  cmd->add_option("--truth", args->truth, "Truth JSON (default: OUT.truth.json beside it)");
  cmd->add_flag("--no-state", args->no_state, "Leave out the full state histories (state/)");
  cmd->callback([&action, args] {
    action = [args] {
      TwoLinkLogOptions options = args->options;
      options.cases = args->cases;
      options.simulation = args->parameters.empty() ? TwoLinkParameters::Nominal()
                                                    : ReadTwoLinkParameterFile(args->parameters);
      if (args->print) {
        fmt::print("{}", TwoLinkParametersText(options.simulation));
        return kExitOk;
      }
      if (args->out.empty()) throw std::invalid_argument("simulate two-link: -o DIR is required");
      options.experiment = args->experiment.empty()
                               ? options.simulation
                               : ReadTwoLinkParameterFile(args->experiment, options.simulation);
      options.write_state = !args->no_state;
      ProgressLine line;
      if (line.Shown()) {
        options.on_progress = [&line](const TwoLinkLogProgress& p) {
          // The last case's files are written after its last simulation.
          line.Show(fmt::format("{}: case {} {}{}", line.Count(p.done, p.total), p.case_number,
                                p.source, p.done == p.total ? "; writing its logs" : ""));
        };
      }
      const TwoLinkLogSummary summary = WriteTwoLinkSession(args->out, options);
      line.Clear();
      std::filesystem::path truth = args->truth;
      if (truth.empty()) {
        truth = args->out.lexically_normal();
        if (truth.filename().empty()) truth = truth.parent_path();
        truth += ".truth.json";
      }
      std::ofstream out(truth);
      out << summary.truth.dump(1) << "\n";
      if (!out) throw InputError({truth, "", std::nullopt}, "cannot write the truth file");
      for (std::size_t i = 0; i < options.cases.size(); ++i) {
        const int number = options.cases[i];
        const auto& c = summary.truth[fmt::format("case{}", number)];
        fmt::print(
            stderr,
            "case {}: {} rows; first impact at {:.4f} s (experiment), {:.4f} s (simulation)\n",
            number, summary.rows[i], c["experiment"]["impact_time_s"].get<double>(),
            c["simulation"]["impact_time_s"].get<double>());
      }
      for (const std::string& warning : summary.warnings) {
        fmt::print(stderr, "warning: {}\n", warning);
      }
      fmt::print(stderr, "session in {}; truth in {}\n", args->out.string(), truth.string());
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
