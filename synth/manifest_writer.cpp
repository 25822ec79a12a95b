#include "synth/manifest_writer.h"

#include <fstream>
#include <iterator>
#include <sstream>
#include <string_view>

#include <toml++/toml.h>

#include "io/errors.h"
#include "synth/experiment.h"  // ArrangementName

namespace impactlab {
namespace {

toml::array Pair(const std::array<double, 2>& values) { return toml::array{values[0], values[1]}; }

toml::array PixelPoints(const std::vector<std::array<double, 2>>& points) {
  toml::array out;
  for (const auto& point : points) out.push_back(Pair(point));
  return out;
}

toml::table TraceTable(const TraceSettings& trace) {
  toml::table table{{"time_per_div", trace.time_per_div},
                    {"volts_per_div", trace.volts_per_div},
                    {"zero_div", trace.zero_div},
                    {"band_div", Pair(trace.band_div)},
                    {"t0_div", trace.t0_div}};
  if (trace.csv) table.insert("csv", trace.csv->generic_string());
  if (trace.impact) table.insert("impact", *trace.impact);
  if (!trace.points_px.empty()) table.insert("points", PixelPoints(trace.points_px));
  return table;
}

void InsertPhoto(toml::table& table, const std::optional<std::filesystem::path>& photo,
                 const std::optional<GraticuleCorners>& corners) {
  if (photo) table.insert("photo", photo->generic_string());
  if (corners) {
    table.insert("graticule_corners",
                 PixelPoints(std::vector<std::array<double, 2>>(corners->begin(), corners->end())));
  }
}

// [specimen]'s keys are its fields' names (io/specimen.h), each written when
// it holds something.
toml::table SpecimenTable(Specimen specimen) {
  toml::table table;
  struct Insert {
    toml::table& table;
    void operator()(const char* name, IfAnyField<std::string> text, Quantity, const char*) const {
      if (!text.field.empty()) table.insert(name, text.field);
    }
    void operator()(const char* name, const std::optional<double>& number, Quantity,
                    const char*) const {
      if (number) table.insert(name, *number);
    }
  };
  Specimen::VisitFields(specimen, Insert{table});
  return table;
}

// A calibration's keys; its trace is a table of its own (PrintCalibration).
toml::table CalibrationTable(const Calibration& calibration) {
  toml::table table{{"id", calibration.id},
                    {"cell", calibration.cell},
                    {"initial_displacement", calibration.initial_displacement}};
  InsertPhoto(table, calibration.photo, calibration.graticule_corners_px);
  return table;
}

// A run's keys; its traces are tables of their own (PrintRun).
toml::table RunTable(const Run& run) {
  toml::table table{{"id", run.id},
                    {"initial_displacement", run.initial_displacement},
                    {"first_rebound", run.first_rebound}};
  InsertPhoto(table, run.photo, run.graticule_corners_px);
  if (!run.calibration.empty()) {
    toml::table cells;
    for (const auto& [cell, id] : run.calibration) cells.insert(cell, id);
    cells.is_inline(true);
    table.insert("calibration", std::move(cells));
  }
  if (run.HasTypedRebounds()) {
    toml::array rebounds;
    for (double xmax : run.rebounds) rebounds.push_back(xmax);
    table.insert("rebounds", std::move(rebounds));
    table.insert("fit_rebounds", toml::array{run.fit_rebounds[0], run.fit_rebounds[1]});
  }
  if (run.contact_time) table.insert("contact_time", *run.contact_time);
  if (run.rebound_uncertainty) table.insert("rebound_uncertainty", *run.rebound_uncertainty);
  if (run.contact_time_uncertainty) {
    table.insert("contact_time_uncertainty", *run.contact_time_uncertainty);
  }
  return table;
}

toml::table LogTable(const Log& log) {
  toml::table table{{"id", log.id},
                    {"experiment", log.experiment.generic_string()},
                    {"time_column", log.time_column}};
  if (log.simulation) table.insert("simulation", log.simulation->generic_string());
  return table;
}

toml::table ChannelTable(const LogChannel& channel) {
  toml::table table{{"column", channel.column}};
  if (channel.counts_per_rev) {
    table.insert("counts_per_rev", *channel.counts_per_rev);
    table.insert("gear_ratio", channel.gear_ratio);
  }
  if (channel.sensitivity) table.insert("sensitivity", *channel.sensitivity);
  return table;
}

// `leaf` under the keys of `path`: {a: {b: leaf}} prints as [a.b].
toml::table Nested(std::initializer_list<std::string_view> path, toml::table leaf) {
  toml::table table = std::move(leaf);
  for (auto key = std::rbegin(path); key != std::rend(path); ++key) {
    table = toml::table{{*key, std::move(table)}};
  }
  return table;
}

// Prints `table` and a blank line after it, with double-quoted strings and no
// indentation, as docs/manifest.md writes its examples. toml++ prints a float
// with 6 significant digits when asked for relaxed precision, else with 17
// (Debian's build formats floats with iostreams): the table is printed with 6
// when that reads back to the same values, as anything written down to 6
// digits does, and with 17 otherwise.
void Print(std::ostream& out, const toml::table& table) {
  std::ostringstream relaxed;
  relaxed << toml::toml_formatter(table, toml::format_flags::relaxed_float_precision);
  if (toml::parse(relaxed.str()) == table) {
    out << relaxed.str() << "\n\n";
  } else {
    out << toml::toml_formatter(table, toml::format_flags::none) << "\n\n";
  }
}

// An entry of an array of tables, then each of its sub-tables on its own: so
// each is printed as precisely as it needs, and a log's channels keep their
// order (in one table toml++ sorts the keys; the reader lists channels in the
// file's order). A header such as [run.traces.left] after [[run]] belongs to
// that run.
void PrintCalibration(std::ostream& out, const Calibration& calibration) {
  Print(out, toml::table{{"calibration", toml::array{CalibrationTable(calibration)}}});
  Print(out, Nested({"calibration", "trace"}, TraceTable(calibration.trace)));
}

void PrintRun(std::ostream& out, const Run& run) {
  Print(out, toml::table{{"run", toml::array{RunTable(run)}}});
  for (const auto& [name, trace] : run.traces) {
    Print(out, Nested({"run", "traces", name}, TraceTable(trace)));
  }
}

void PrintLog(std::ostream& out, const Log& log) {
  Print(out, toml::table{{"log", toml::array{LogTable(log)}}});
  for (const LogChannel& channel : log.channels) {
    Print(out, Nested({"log", "channels", channel.name}, ChannelTable(channel)));
  }
}

}  // namespace

std::string ManifestText(const SessionManifest& manifest) {
  std::ostringstream out;
  for (const std::string& line : manifest.comment) out << "# " << line << "\n";
  toml::table header{{"format", 1}, {"units", std::string(UnitSystemName(manifest.units))}};
  if (!manifest.title.empty()) header.insert("title", manifest.title);
  Print(out, header);

  toml::table setup;
  if (manifest.apparatus) {
    setup.insert("apparatus",
                 toml::table{{"pendulum_length", manifest.apparatus->pendulum_length},
                             {"weight", manifest.apparatus->weight},
                             {"arrangement", ArrangementName(manifest.apparatus->arrangement)}});
  }
  if (manifest.divisions) {
    setup.insert("scope", toml::table{{"divisions", toml::array{(*manifest.divisions)[0],
                                                                (*manifest.divisions)[1]}}});
  }
  if (!setup.empty()) Print(out, setup);
  if (manifest.specimen) Print(out, toml::table{{"specimen", SpecimenTable(*manifest.specimen)}});

  for (const Calibration& calibration : manifest.calibrations) PrintCalibration(out, calibration);
  for (const Run& run : manifest.runs) PrintRun(out, run);
  for (const Log& log : manifest.logs) PrintLog(out, log);

  std::string text = std::move(out).str();
  text.pop_back();  // one newline at the end, not a blank line
  return text;
}

void WriteManifest(const std::filesystem::path& file, const SessionManifest& manifest) {
  std::ofstream out(file, std::ios::binary);
  out << ManifestText(manifest);
  out.close();
  if (!out) throw InputError({file, "", std::nullopt}, "cannot write the manifest");
}

}  // namespace impactlab
