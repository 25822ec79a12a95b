// impactlab: data reduction for impact experiments (docs/commands.md).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glog/logging.h>
#include <CLI/CLI.hpp>
#include <opencv2/core/utility.hpp>

#include "cli/command_line_mistakes.h"
#include "cli/commands.h"
#include "cli/version.h"
#include "fit/least_squares.h"
#include "io/atomic_file.h"
#include "io/errors.h"
#include "io/hdf5_file.h"
#include "pipeline/process_memory.h"
#include "pipeline/stage_options.h"

namespace {

using namespace impactlab::cli;

// `--version`: this build and the libraries its numbers rest on.
std::string VersionText() {
  return fmt::format("impactlab {}\nOpenCV {}, Ceres Solver {}, HDF5 {}", kVersion,
                     cv::getVersionString(), impactlab::CeresVersion(), impactlab::Hdf5Version());
}

// The whole command's help (App::help() of a parsed app gives its chosen
// subcommand's).
std::string Usage(const CLI::App& app) {
  return app.get_formatter()->make_help(&app, "impactlab", CLI::AppFormatMode::Normal);
}

// `impactlab help [COMMAND [SUBCOMMAND]]`: the same text as `impactlab COMMAND
// SUBCOMMAND --help`.
void AddHelpCommand(CLI::App& app, Action& action) {
  CLI::App* cmd = app.add_subcommand("help", "Show the commands, or one command's options");
  auto topic = std::make_shared<std::vector<std::string>>();
  cmd->add_option("command", *topic, "The command to explain, e.g. reduce or model kv");
  cmd->callback([&app, &action, topic] {
    action = [&app, topic] {
      const CLI::App* command = &app;
      std::string words;    // "model kv"
      std::string parents;  // "impactlab model": CLI11's help names the command from them
      for (const std::string& word : *topic) {
        const CLI::App* sub = FindSubcommand(*command, word);
        if (sub == nullptr) {
          fmt::print(stderr, "{}\n", UnknownSubcommand(*command, words, word));
          return kExitUsage;
        }
        parents = words.empty() ? "impactlab" : "impactlab " + words;
        words += (words.empty() ? "" : " ") + sub->get_name();
        command = sub;
      }
      if (command == &app) {
        fmt::print("{}", Usage(app));
      } else {
        fmt::print("{}", command->help(parents));
      }
      return kExitOk;
    };
  });
}

// The first argument, when it is neither an option nor a command: a typo,
// most likely, said with the nearest command.
std::optional<std::string> UnknownCommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-' || FindSubcommand(app, argv[1]) != nullptr) {
    return std::nullopt;
  }
  return UnknownSubcommand(app, "", argv[1]);
}

}  // namespace

int main(int argc, char** argv) {
  impactlab::KeepFreedMemoryForReuse();
  impactlab::HeapInHugePages();
  // A temporary output file being written is removed on Ctrl-C and kill.
  impactlab::InstallTemporaryFileCleanup();
  // Ceres logs a trial point whose residuals cannot be evaluated (a contact
  // law outside its domain in a profile interval's search) through glog as
  // an error; the fits say what failed in their own status, so stderr stays
  // the command's own.
  FLAGS_minloglevel = google::GLOG_FATAL;
  CLI::App app{"impactlab: reduce impact experiments (pendulum rebounds, contact models, logs)"};
  app.name("impactlab");
  app.set_version_flag("-V,--version", VersionText());
  app.require_subcommand(0, 1);
  Action action;
  AddReduceCommand(app, action);
  AddReportCommand(app, action);
  AddCampaignCommand(app, action);
  AddModelCommand(app, action);
  AddPendulCommand(app, action);
  AddDigitizeCommand(app, action);
  AddSynthCommand(app, action);
  AddSynthLogsCommand(app, action);
  AddSynthCampaignCommand(app, action);
  AddSimulateCommand(app, action);
  AddFitCommand(app, action);
  AddSettingsCommand(app, action);
  AddHelpCommand(app, action);
  if (const auto unknown = UnknownCommand(app, argc, argv)) {
    fmt::print(stderr, "{}\n", *unknown);
    return kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" too, of code 0.
    if (e.get_exit_code() != 0) {
      if (const auto mistake = ExplainParseError(app)) {
        fmt::print(stderr, "{}\n", *mistake);
        return kExitUsage;
      }
    }
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  if (!action) {  // a bare call: what there is to do
    fmt::print("{}", Usage(app));
    return kExitUsage;
  }
  try {
    return action();
  } catch (const impactlab::InputError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    // A stage setting's flag is located at the command line: a bad command line.
    return e.where().file == impactlab::kCommandLine ? kExitUsage : kExitInputError;
  } catch (const std::domain_error& e) {  // includes NoSeparationError
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitModelDomain;
  } catch (const std::invalid_argument& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    fmt::print(stderr, "internal error: {}\n", e.what());
    return kExitInternal;
  }
}
