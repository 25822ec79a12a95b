#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/commands.h"
#include "cli/progress_line.h"
#include "io/atomic_file.h"
#include "io/errors.h"
#include "io/spelling.h"
#include "pipeline/results_file.h"
#include "report/html_report.h"
#include "report/tables.h"

namespace impactlab::cli {
namespace {

// The report must not replace the results file it is read from.
void CheckReportOutput(const std::filesystem::path& output, const std::filesystem::path& results) {
  CheckOutputPath(output);
  std::error_code ec;
  if (std::filesystem::equivalent(output, results, ec)) {
    throw InputError({output, "", std::nullopt},
                     "is the results file the report is read from; give another output file");
  }
}

}  // namespace

void AddReportCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path results;
    std::string format = "md";
    std::filesystem::path output;
    std::filesystem::path figures;
    std::vector<std::string> tables;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("report", "Write the report tables of a results file");
  cmd->add_option("results", args->results, "Results file written by `impactlab reduce`")
      ->required();
  cmd->add_option("-f,--format", args->format, "md, csv, tex or html (a self-contained page)")
      ->check(CLI::IsMember({"md", "csv", "tex", "html"}))
      ->capture_default_str();
  cmd->add_option("-o,--out,--output", args->output,
                  "Output file, - for standard output (default: standard output; for html, the "
                  "results file's name with .html); with csv, an existing folder gets one file "
                  "per table");
  cmd->add_option("--table", args->tables,
                  "Only this table (by name, e.g. table2_deviations; may be repeated)");
  cmd->add_option("--figures", args->figures,
                  "Also write every figure of the HTML report as an SVG file into this folder "
                  "(created if missing; for papers)");
  cmd->callback([&action, args] {
    action = [args] {
      const ReportFormat format = *ParseReportFormat(args->format);
      // A page of megabytes is no use on a terminal: it goes beside the results.
      if (format == ReportFormat::kHtml && args->output.empty()) {
        args->output = std::filesystem::path(args->results).replace_extension(".html");
        fmt::print(stderr, "writing {}\n", args->output.string());
      }
      if (args->output == "-") args->output.clear();
      const bool csv_folder = format == ReportFormat::kCsv && !args->output.empty() &&
                              std::filesystem::is_directory(args->output);
      if (!args->output.empty() && !csv_folder) CheckReportOutput(args->output, args->results);
      if (!args->figures.empty() && std::filesystem::exists(args->figures) &&
          !std::filesystem::is_directory(args->figures)) {
        throw InputError({args->figures, "", std::nullopt},
                         "--figures: is a file; give a folder for the SVG files");
      }
      // A photo session's page takes a second or two: said on a terminal.
      ProgressLine line;
      line.Show(fmt::format("reading {}", args->results.string()));
      const SessionResult result = ReadResults(args->results);
      line.Show(fmt::format("{:.1f} s: {}", line.Seconds(),
                            format == ReportFormat::kHtml || !args->figures.empty()
                                ? "drawing the figures"
                                : "making the tables"));
      if (!args->figures.empty()) {
        // Made only once the results could be read: a failed report leaves no empty folder.
        std::error_code ec;
        std::filesystem::create_directories(args->figures, ec);
        if (ec) {
          throw InputError({args->figures, "", std::nullopt},
                           "--figures: cannot create the folder: " + ec.message());
        }
        for (const auto& [name, svg] : RenderStaticFigures(result)) {
          WriteFileAtomically(args->figures / name, svg);
        }
      }
      std::vector<Table> tables = BuildTables(result);
      if (!args->tables.empty()) {
        std::vector<std::string> names;
        for (const Table& t : tables) names.push_back(t.name);
        for (const std::string& wanted : args->tables) {
          if (std::find(names.begin(), names.end(), wanted) == names.end()) {
            throw std::invalid_argument(fmt::format(
                "--table {}: no such table in {}{}; its tables are: {}", wanted,
                args->results.string(), DidYouMean(wanted, names), fmt::join(names, ", ")));
          }
        }
        std::erase_if(tables, [&](const Table& t) {
          return std::find(args->tables.begin(), args->tables.end(), t.name) == args->tables.end();
        });
      }
      if (csv_folder) {
        for (const Table& t : tables) {
          WriteFileAtomically(args->output / (t.name + ".csv"), RenderTable(t, format));
        }
        return kExitOk;
      }
      const std::string text = format == ReportFormat::kHtml
                                   ? RenderHtmlReport(result)
                                   : RenderTables(result.title, tables, format);
      line.Clear();  // before the text, which may go to the same terminal
      if (args->output.empty()) {
        fmt::print("{}", text);
      } else {
        WriteFileAtomically(args->output, text);
      }
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
