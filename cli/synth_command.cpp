#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/core.h>

#include "cli/commands.h"
#include "cli/progress_line.h"
#include "io/errors.h"
#include "synth/session_generator.h"

namespace impactlab::cli {

void AddSynthCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path out, truth;
    std::string style = "polaroid";
    SynthOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "synth", "Simulate a lab session: photos (or CSV traces) of simulated impacts, with truth");
  cmd->add_option("-o,--out,--output", args->out,
                  "Session folder to create (must not exist or be empty)")
      ->required();
  cmd->add_option("--preset", args->options.preset, "thesis (8 runs) or quick (2 small runs)")
      ->check(CLI::IsMember({"thesis", "quick"}))
      ->capture_default_str();
  cmd->add_option("--style", args->style,
                  "clean, polaroid, phone, negative, lowres, randomised or digital (a digital "
                  "scope's screen)")
      ->check(CLI::IsMember(
          {"clean", "polaroid", "phone", "negative", "lowres", "randomised", "digital"}))
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "Random seed: the same seed, the same session")
      ->capture_default_str();
  cmd->add_option("--truth", args->truth, "Ground-truth JSON (default: OUT.truth.json beside it)");
  cmd->add_option("--width", args->options.width_px, "Photo width in pixels (default: preset's)");
  cmd->add_flag("--wire-anomalies", args->options.wire_anomalies,
                "Heavy support-wire forcing: rebounds that exceed their predecessor");
  cmd->add_option("--nonlinearity", args->options.photocell_nonlinearity,
                  "Photocell curves: 0 linear .. 1 strongly nonlinear")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--contact-model", args->options.contact_model,
                  "kelvin-voigt or poynting-thomson (docs/synth.md)")
      ->check(CLI::IsMember({"kelvin-voigt", "poynting-thomson"}))
      ->capture_default_str();
  cmd->add_flag("--csv-run", args->options.csv_run, "Add a run given as CSV traces");
  cmd->add_flag("--typed-run", args->options.typed_run, "Add a run with typed-in maxima");
  cmd->add_flag("!--no-photo-handling", args->options.photo_handling,
                "Randomised style: no hand marks about traces, tape or print reproductions");
  cmd->callback([&action, args] {
    action = [args] {
      args->options.style = *ParsePhotoStyle(args->style);
      std::filesystem::path truth = args->truth;
      if (truth.empty()) {
        truth = args->out.lexically_normal();
        if (truth.filename().empty()) truth = truth.parent_path();
        truth += ".truth.json";
      }
      ProgressLine line;
      SynthOptions options = args->options;
      if (line.Shown()) {
        options.on_progress = [&line](const SynthProgress& p) {
          line.Show(
              fmt::format("{}: run {}, {} photo(s)", line.Count(p.done, p.total), p.run, p.photos));
        };
      }
      const SynthSummary summary = GenerateSession(args->out, options);
      line.Clear();
      std::ofstream out(truth);
      out << summary.truth.dump(1) << "\n";
      if (!out) throw InputError({truth, "", std::nullopt}, "cannot write the truth file");
      fmt::print(stderr,
                 "{} run(s), {} photo(s) in {}; truth in {}\nsimulation {:.2f} s, rendering {:.2f} "
                 "s ({:.0f} ms per photo)\n",
                 summary.runs, summary.photos, args->out.string(), truth.string(),
                 summary.simulate_seconds, summary.render_seconds,
                 summary.photos ? 1e3 * summary.render_seconds / summary.photos : 0.0);
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
