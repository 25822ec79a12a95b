// The `impactlab` command's subcommands. Each Add*Command registers its
// options on `app` and sets `action` to the work it does when chosen; the work
// returns an exit code (docs/commands.md).
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace impactlab::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitRunsFailed = 1,   // reduce: some runs could not be reduced (the others were); campaign:
                         // some inputs could not be read (the others were combined)
  kExitUsage = 2,        // bad command line
  kExitInputError = 3,   // bad input file: manifest, results file, photo, log
  kExitModelDomain = 4,  // parameters outside the model's domain (e.g. zeta >= 1, kinematic)
  kExitInternal = 5,     // a bug: please report it
};

using Action = std::function<int()>;

void AddReduceCommand(CLI::App& app, Action& action);
void AddReportCommand(CLI::App& app, Action& action);
void AddModelCommand(CLI::App& app, Action& action);
void AddPendulCommand(CLI::App& app, Action& action);
void AddDigitizeCommand(CLI::App& app, Action& action);
void AddSynthCommand(CLI::App& app, Action& action);
void AddSynthLogsCommand(CLI::App& app, Action& action);
void AddSynthCampaignCommand(CLI::App& app, Action& action);
void AddSettingsCommand(CLI::App& app, Action& action);
void AddSimulateCommand(CLI::App& app, Action& action);
void AddFitCommand(CLI::App& app, Action& action);
void AddCampaignCommand(CLI::App& app, Action& action);

}  // namespace impactlab::cli
