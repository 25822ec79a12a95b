// `impactlab fit two-link PARAMS.toml SESSION --log ID --free KEY,... -o DIR`:
// the two-link simulation fitted to one `[[log]]` of a session
// (docs/two-link-fit.md). DIR gets fitted.toml (the parameter file with the
// fitted values), fit.txt (what was determined, with uncertainties, and what
// was not) and a session whose log pairs the experiment with the fitted
// simulation, so `impactlab reduce DIR` shows fitted against measured. The
// fit itself is pipeline/two_link_fit_run.h; here are the flags, the reading
// and the writing.
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/commands.h"
#include "cli/progress_line.h"
#include "cli/two_link_parameter_file.h"
#include "io/atomic_file.h"
#include "io/errors.h"
#include "io/log_reader.h"
#include "io/manifest.h"
#include "multibody/two_link_toml.h"
#include "pipeline/two_link_fit_run.h"
#include "synth/manifest_writer.h"
#include "synth/two_link_logs.h"

namespace impactlab::cli {

namespace fs = std::filesystem;

void AddFitCommand(CLI::App& app, Action& action) {
  struct Args {
    fs::path parameters, session, out;
    std::string log_id;
    std::vector<std::string> free;
    TwoLinkFitOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* fit = app.add_subcommand("fit", "Fit a mechanism's simulation to a session's logs");
  fit->require_subcommand(1);
  CLI::App* cmd = fit->add_subcommand(
      "two-link", "The two-link flexible manipulator's simulation fitted to one [[log]]");
  cmd->add_option("parameters", args->parameters, "Start parameters (TOML, SI; docs/two-link.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("session", args->session, "Session folder (or its session.toml)")->required();
  cmd->add_option("--log", args->log_id, "The [[log]] id (default: the first)");
  cmd->add_option("--case", args->options.case_number, "The document's case the log is")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  cmd->add_option("--free", args->free,
                  "Parameters to fit, as section.key (e.g. beam1.flexural_rigidity_n_m2)")
      ->required()
      ->delimiter(',');
  cmd->add_option("--max-iterations", args->options.max_iterations, "Levenberg-Marquardt steps")
      ->capture_default_str();
  cmd->add_option("--starts", args->options.starts,
                  "Starts: 1 is the given parameters; more also start from each moved +-20 %")
      ->capture_default_str();
  cmd->add_option("--threads", args->options.threads, "Simulations run side by side")
      ->capture_default_str();
  cmd->add_option("-o,--out,--output", args->out, "Folder to create (must not exist or be empty)")
      ->required();
  cmd->callback([&action, args] {
    action = [args] {
      std::error_code ec;
      if (fs::exists(args->out) && !fs::is_empty(args->out, ec)) {
        throw InputError({args->out, "", std::nullopt},
                         "the output folder exists and is not empty");
      }
      const TwoLinkParameters start = ReadTwoLinkParameterFile(args->parameters);
      const ManifestReadResult manifest = ReadManifest(args->session);
      const Log* log = nullptr;
      for (const Log& l : manifest.session.logs) {
        if (args->log_id.empty() || l.id == args->log_id) {
          log = &l;
          break;
        }
      }
      if (!log) {
        throw InputError({SessionFolderOf(args->session) / "session.toml", "log", std::nullopt},
                         args->log_id.empty() ? "the session has no [[log]]"
                                              : "no [[log]] with id \"" + args->log_id + "\"");
      }
      TwoLinkFitOptions options = args->options;
      options.free = args->free;
      const LogSeries experiment =
          ReadLogSeries(log->experiment, log->time_column, log->channels, LogSource::kExperiment);
      fmt::print(stderr, "fitting {} parameter(s) to log {} ({} samples)...\n", options.free.size(),
                 log->id, experiment.time_s.size());
      ProgressLine line;
      if (line.Shown()) {
        options.on_progress = [&line](const TwoLinkFitProgress& p) {
          const std::string start =
              p.starts > 1 ? fmt::format("start {}/{}, ", p.start + 1, p.starts) : "";
          if (p.stage == p.stages) {
            line.Show(fmt::format("{}uncertainty: {} simulations, {:.1f} s", start, p.simulations,
                                  p.seconds));
            return;
          }
          line.Show(
              fmt::format("{}stage {}/{} ({}): iteration {}, chi2 {:.5g}, {} simulations, "
                          "{:.1f} s",
                          start, p.stage + 1, p.stages, p.stage_name, p.iteration, p.chi2,
                          p.simulations, p.seconds));
        };
      }
      const TwoLinkFitRun run = FitTwoLinkToLog(start, *log, experiment, options);
      const TwoLinkFitResult& result = run.fit;
      line.Clear();
      if (!result.ok) {
        // Nothing is written. A log the fit cannot take keeps the exit status
        // of a bad command line (docs/two-link-fit.md), a start it cannot
        // simulate that of the model's domain.
        fmt::print(stderr, "error: {}\n", result.reason);
        return result.refused == TwoLinkFitRefusal::kStartParameters ? kExitModelDomain
                                                                     : kExitUsage;
      }

      fs::create_directories(args->out / "logs", ec);
      if (ec) throw InputError({args->out, "", std::nullopt}, "cannot create: " + ec.message());
      WriteFileAtomically(args->out / "fitted.toml", TwoLinkParametersText(result.fitted));
      const std::string summary = fmt::format("# Two-link simulation fitted to log {} of {}\n\n{}",
                                              log->id, args->session.string(), result.Summary());
      WriteFileAtomically(args->out / "fit.txt", summary);
      if (!run.fitted_simulation.ok) {
        // The fit stands (fitted.toml, fit.txt); its case cannot be simulated whole.
        fmt::print("{}", summary);
        fmt::print(stderr,
                   "error: the fitted parameters' case {}: {}\nwritten: {}/fitted.toml, fit.txt\n",
                   options.case_number, run.fitted_simulation.reason, args->out.string());
        return kExitModelDomain;
      }
      // The session: the experiment as recorded beside the fitted simulation.
      Log pair = *log;
      pair.experiment = fs::path("logs") / (log->id + "-experiment.csv");
      pair.simulation = fs::path("logs") / (log->id + "-fitted.csv");
      fs::copy_file(log->experiment, args->out / pair.experiment, ec);
      if (ec) throw InputError({log->experiment, "", std::nullopt}, ec.message());
      WriteTwoLinkSimulationCsv(args->out / *pair.simulation, run.fitted_simulation);
      SessionManifest out;
      out.comment = {"The experiment of " + args->session.string() + " against the fitted",
                     "two-link simulation (impactlab fit two-link; see fit.txt)."};
      out.title = "Two-link simulation fitted to log " + log->id;
      out.units = UnitSystem::kSI;
      out.logs.push_back(pair);
      WriteManifest(args->out / "session.toml", out);
      fmt::print("{}", summary);
      fmt::print(stderr, "written: {}/fitted.toml, fit.txt, session.toml (impactlab reduce {})\n",
                 args->out.string(), args->out.string());
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
