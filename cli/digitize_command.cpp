// `impactlab digitize`: one photo's traces to CSV (docs/digitizing.md).
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <fmt/core.h>
#include <fmt/format.h>

#include "cli/commands.h"
#include "cli/stage_flags.h"
#include "digitize/digitize.h"
#include "io/errors.h"
#include "io/manifest.h"
#include "io/session_file.h"

namespace impactlab::cli {
namespace {

// The traces and the photo the manifest gives for a run or a calibration.
struct Target {
  std::string id;
  std::vector<TraceRequest> requests;
  std::optional<std::filesystem::path> photo;
  std::optional<GraticuleCorners> corners_px;  // the manifest's hint for that photo
  StageSettings settings;                      // the entry's own, e.g. [run.digitize]
};

Target FindTarget(const Session& session, const std::string& run_id,
                  const std::string& calibration_id) {
  // An entry the manifest rejected: its own reason, not "no such id".
  const std::string& wanted = run_id.empty() ? calibration_id : run_id;
  for (const RejectedEntry& entry : session.Rejected(run_id.empty() ? "calibration" : "run")) {
    if (entry.id == wanted) throw InputError(entry.where, entry.problem);
  }
  if (!run_id.empty()) {
    for (const Run& run : session.runs) {
      if (run.id == run_id) {
        return {run.id, TraceRequestsOf(run), run.photo, run.graticule_corners_px, run.settings};
      }
    }
    throw InputError({session.manifest, "run", std::nullopt},
                     fmt::format("no run with id \"{}\"", run_id));
  }
  for (const Calibration& calibration : session.calibrations) {
    if (calibration.id == calibration_id) {
      return {calibration.id, TraceRequestsOf(calibration), calibration.photo,
              calibration.graticule_corners_px, calibration.settings};
    }
  }
  throw InputError({session.manifest, "calibration", std::nullopt},
                   fmt::format("no calibration with id \"{}\"", calibration_id));
}

// time_s,volts as the trace format (io/trace.h), then the per-sample
// uncertainty and confidence, which readers of that format ignore.
void WriteDigitizedCsv(const std::filesystem::path& path, const DigitizedTrace& trace) {
  std::ofstream out(path);
  out << "time_s,volts,sigma_volts,confidence\n";
  for (std::size_t i = 0; i < trace.trace.time_s.size(); ++i) {
    out << fmt::format("{:.12g},{:.9g},{:.3g},{:.3f}\n", trace.trace.time_s[i],
                       trace.trace.volts[i], trace.trace.sigma_volts[i], trace.confidence[i]);
  }
  if (!out) throw InputError({path, "", std::nullopt}, "cannot write the trace file");
}

}  // namespace

void AddDigitizeCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path photo;
    std::filesystem::path manifest;
    std::string run, calibration;
    std::filesystem::path out_dir = ".";
    std::filesystem::path overlay;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "digitize", "Recover the traces of an oscillograph photo as CSV (time_s,volts)");
  cmd->add_option("photo", args->photo,
                  "The photo (default: the run's or calibration's photo in the manifest)");
  cmd->add_option("-m,--manifest", args->manifest, "session.toml, or the session folder")
      ->required();
  auto* run = cmd->add_option("--run", args->run, "Run id: digitize its traces");
  auto* calibration =
      cmd->add_option("--calibration", args->calibration, "Calibration id: digitize its trace");
  run->excludes(calibration);
  cmd->add_option("-o,--out,--out-dir,--output", args->out_dir,
                  "Folder for the CSV files (ID-TRACE.csv)")
      ->capture_default_str();
  cmd->add_option("--overlay", args->overlay, "Write the photo with what was found drawn on it");
  cmd->add_flag("-q,--quiet", args->quiet, "Print only errors");
  // The settings `reduce` would digitize this photo with: the manifest's, the
  // entry's own, and these flags over both.
  const auto stage_flags = std::make_shared<StageFlags>(*cmd, std::vector<std::string>{"digitize"});
  cmd->callback([&action, args, stage_flags] {
    action = [args, stage_flags] {
      if (args->run.empty() == args->calibration.empty()) {
        throw std::invalid_argument("digitize: give exactly one of --run ID or --calibration ID");
      }
      const ManifestReadResult manifest = ReadManifest(args->manifest);
      const Session& session = manifest.session;
      const Target target = FindTarget(session, args->run, args->calibration);
      if (target.requests.empty()) {
        throw InputError({session.manifest, target.id, std::nullopt},
                         "no trace to digitize: every trace comes from a CSV file");
      }
      std::filesystem::path photo_path = args->photo;
      if (photo_path.empty()) {
        if (!target.photo) {
          throw InputError({session.manifest, target.id, std::nullopt},
                           "no photo given and the manifest names none");
        }
        photo_path = *target.photo;
      }
      // A photo the manifest names is read from inside the session only; one
      // named on the command line is the user's own choice.
      const Photo photo = args->photo.empty()
                              ? DecodePhoto(ReadSessionFile(session.folder, photo_path), photo_path)
                              : LoadPhoto(photo_path);
      const StageSettings flags = stage_flags->Given();
      DigitizeOptions options =
          EntryStageOptions(SessionStageOptions({}, session, flags), target.settings, flags)
              .digitize;
      // The manifest's corners are pixels of the manifest's photo, not of
      // another one named on the command line.
      if (args->photo.empty()) options.graticule.corners_px = target.corners_px;
      const DigitizeResult result =
          DigitizePhoto(photo, session.divisions, target.requests, options);

      // A photo not read still gets its overlay: what was found, and why not.
      if (!args->overlay.empty()) WriteImage(args->overlay, DrawOverlay(photo, result));
      if (!result.ok) throw InputError(result.failed_at, result.reason);
      std::filesystem::create_directories(args->out_dir);
      for (const DigitizedTrace& trace : result.traces) {
        WriteDigitizedCsv(args->out_dir / fmt::format("{}-{}.csv", target.id, trace.name), trace);
      }
      if (!args->quiet) {
        const GraticuleFit& g = result.graticule;
        fmt::print(
            "{}: graticule {}x{}, residual {:.3f} px RMS over {} line samples, {:.1f} px/div{}\n",
            photo_path.string(), g.divisions[0], g.divisions[1], g.residual_px, g.samples_used,
            g.px_per_div,
            g.radial_fitted ? fmt::format(", radial k1 {:.4f}", g.mapping.radial_k1) : "");
        for (std::size_t i = 0; i < result.traces.size(); ++i) {
          const DigitizedTrace& t = result.traces[i];
          fmt::print(
              "  {}: {} samples over {:.0f} % of the sweep, centre scatter {:.2f} px{}\n", t.name,
              t.trace.time_s.size(), 100.0 * t.coverage, t.noise_px,
              t.spread_px2 > 0.0
                  ? fmt::format(", spread {:.2f} px^2 (its curvature pull undone)", t.spread_px2)
                  : "");
          for (const auto& [from, to] : t.mark_stretches_div) {
            fmt::print("  {}: samples on a hand mark dropped over x = {:.2f} .. {:.2f} div\n",
                       t.name, from, to);
          }
          if (result.pulses[i]) {
            const ContactPulseFit& p = *result.pulses[i];
            fmt::print("  {}: contact pulse {:.3f} +- {:.3f} us (rise {:.3f} us, fall {:.3f} us)\n",
                       t.name, p.pulse.width_s.value * 1e6, p.pulse.width_s.sigma * 1e6,
                       p.pulse.rise_s.value * 1e6, p.pulse.fall_s.value * 1e6);
          } else if (t.settings.impact) {
            fmt::print("  {}: no complete contact pulse seen\n", t.name);
          }
        }
        if (!result.mark_outlines_px.empty()) {
          fmt::print(
              "  {} hand mark(s) kept from the traces (outlined in magenta on the overlay)\n",
              result.mark_outlines_px.size());
        }
        if (const std::string hints = HintsUsed(result); !hints.empty()) {
          fmt::print("  manual hints used: {}\n", hints);
        }
        fmt::print("  {:.1f} ms beyond decoding\n", result.ProcessingMs());
      }
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
