// impactlab: data reduction for impact experiments (docs/commands.md).
#include <cstdio>
#include <stdexcept>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "cli/version.h"
#include "io/atomic_file.h"
#include "io/errors.h"
#include "pipeline/process_memory.h"

int main(int argc, char** argv) {
  using namespace impactlab::cli;
  impactlab::KeepFreedMemoryForReuse();
  // A temporary output file being written is removed on Ctrl-C and kill.
  impactlab::InstallTemporaryFileCleanup();
  CLI::App app{"impactlab: reduce impact experiments (pendulum rebounds, contact models, logs)"};
  app.set_version_flag("--version", std::string("impactlab ") + kVersion);
  app.require_subcommand(1);
  Action action;
  AddReduceCommand(app, action);
  AddReportCommand(app, action);
  AddModelCommand(app, action);
  AddPendulCommand(app, action);
  AddDigitizeCommand(app, action);
  AddSynthCommand(app, action);
  AddSynthLogsCommand(app, action);
  AddSettingsCommand(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  try {
    return action ? action() : kExitUsage;
  } catch (const impactlab::InputError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitInputError;
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
