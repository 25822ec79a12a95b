#include <algorithm>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "campaign/campaign.h"
#include "cli/commands.h"
#include "cli/version.h"
#include "io/atomic_file.h"
#include "io/errors.h"
#include "report/campaign_report.h"
#include "report/tables.h"

namespace impactlab::cli {

void AddCampaignCommand(CLI::App& app, Action& action) {
  struct Args {
    std::vector<std::filesystem::path> inputs;
    std::filesystem::path output;
    std::filesystem::path report;
    std::string format = "html";
    std::filesystem::path figures;
    std::filesystem::path reduced;
    int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "campaign",
      "Read many sessions' results together: their estimates by material and the "
      "constants a material's sessions share");
  cmd->add_option("inputs", args->inputs, "Results files (.h5) or session folders (reduced first)")
      ->required();
  cmd->add_option("-o,--out,--output", args->output, "The campaign file (HDF5)")->required();
  cmd->add_option("--report", args->report,
                  "Also write the report to this file (with csv, an existing folder gets one file "
                  "per table)");
  cmd->add_option("-f,--format", args->format, "The report's format: md, csv, tex or html")
      ->check(CLI::IsMember({"md", "csv", "tex", "html"}))
      ->capture_default_str();
  cmd->add_option("--figures", args->figures,
                  "Also write every figure as an SVG file into this folder (created if missing)");
  cmd->add_option("--reduced", args->reduced,
                  "Where a session folder's results file is written and reused from (default: "
                  "the campaign file's name with _sessions)");
  cmd->add_option("-j,--jobs", args->jobs, "Runs reduced in parallel, for a session folder")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("-q,--quiet", args->quiet, "Print only errors");
  cmd->callback([&action, args] {
    action = [args] {
      CheckOutputPath(args->output);
      CampaignOptions options;
      options.producer = std::string("impactlab ") + kVersion;
      options.jobs = args->jobs;
      options.reduced_folder =
          args->reduced.empty()
              ? args->output.parent_path() / (args->output.stem().string() + "_sessions")
              : args->reduced;
      const Campaign campaign = MakeCampaign(args->inputs, options);
      WriteCampaign(campaign, args->output);
      for (const CampaignFailure& f : campaign.failures) {
        fmt::print(stderr, "{}: not read: {}\n", f.input, f.reason);
      }
      if (!args->figures.empty()) {
        std::filesystem::create_directories(args->figures);
        for (const auto& [name, svg] : RenderCampaignFigures(campaign)) {
          WriteFileAtomically(args->figures / name, svg);
        }
      }
      if (!args->report.empty()) {
        const ReportFormat format = *ParseReportFormat(args->format);
        const std::vector<Table> tables = BuildCampaignTables(campaign);
        if (format == ReportFormat::kCsv && std::filesystem::is_directory(args->report)) {
          for (const Table& t : tables) {
            WriteFileAtomically(args->report / (t.name + ".csv"), RenderTable(t, format));
          }
        } else {
          WriteFileAtomically(args->report, format == ReportFormat::kHtml
                                                ? RenderCampaignHtml(campaign)
                                                : RenderTables("Campaign", tables, format));
        }
      }
      if (!args->quiet) {
        std::size_t away = 0, pairs = 0;
        for (const MaterialFit& m : campaign.fits) {
          away += m.pulling_away.size();
          pairs += m.disagreeing_pairs.size();
        }
        fmt::print(stderr,
                   "{} of {} inputs read, {} shared-constant fits, {} session(s) pulling away, "
                   "{} disagreement(s) between two sessions alone; campaign in {}\n",
                   campaign.sessions.size(), campaign.inputs.size(), campaign.fits.size(), away,
                   pairs, args->output.string());
      }
      return campaign.failures.empty() ? kExitOk : kExitRunsFailed;
    };
  });
}

}  // namespace impactlab::cli
