// Every result a reduce produces survives the results file: the bundled
// sessions of typed-in maxima and of logs, and a generated session of photos,
// CSV traces and typed-in maxima, reduced, written, read, written again and
// read again. Every listed field (options/result_fields.h) of every result is
// compared, the reduce's own against the first reading and the two readings
// against each other, so a field added to a list is compared with nothing
// added here.
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <typeinfo>
#include <vector>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "synth/session_generator.h"
#include "tests/pipeline/every_field.h"
#include "tests/support/temp_dir.h"
#include "tests/support/text_file.h"

namespace impactlab {
namespace {

// Every listed field of every result a session holds, one line each named by
// where the result is, and the listed types met. A result is compared where
// the file holds its fields: a fit's only when it ran (a failed two-point
// fit, a least-squares fit or a law that could not run, a model not fitted
// keep only their status).
struct SessionFields {
  std::vector<std::string> lines;
  std::set<std::string> types;

  template <typename Result>
  void Add(const Result& result, const std::string& where) {
    types.insert(typeid(Result).name());
    const std::vector<std::string> more = testing::EveryField(result, where + ": ");
    lines.insert(lines.end(), more.begin(), more.end());
  }
  void AddCalibration(const CellCalibration& c, const std::string& where) {
    Add(c, where);
    if (c.overlay) Add(*c.overlay, where + "/digitized");
  }
  // A bar's fields and its rows' rebounds (the file's dimension scale).
  void AddBar(const BarRebounds& bar, const std::string& where) {
    Add(bar, where);
    std::string numbers = where + ": rebound";
    for (std::size_t i = 0; i < bar.xmax.size(); ++i) {
      numbers += ' ';
      numbers += std::to_string(bar.Number(i));
    }
    lines.push_back(numbers);
  }
  template <typename Fit>
  void AddLeastSquares(const std::optional<Fit>& fit, const std::string& where) {
    if (fit && fit->status.Ran()) Add(*fit, where);
  }
  void AddRun(const RunResult& run) {
    const std::string g = "runs/" + run.id;
    Add(run, g);
    Add(run.seconds, g + "/stage_seconds");
    if (!run.specimen.empty()) Add(run.specimen, g + "/specimen");
    Add(run.measured, g);
    if (run.measured.right) AddBar(*run.measured.right, g + "/rebounds/right");
    if (run.measured.left) AddBar(*run.measured.left, g + "/rebounds/left");
    for (const CellCalibration& c : run.measured.calibrations) {
      AddCalibration(c, g + "/calibration/" + c.cell);
    }
    for (std::size_t i = 0; i < run.measured.overlays.size(); ++i) {
      Add(run.measured.overlays[i], g + "/digitized/" + std::to_string(i));
    }
    if (run.fits.kelvin_voigt && run.fits.kelvin_voigt->ok) {
      Add(*run.fits.kelvin_voigt, g + "/fit/kelvin_voigt");
      Add(run.fits, g + "/fit/kelvin_voigt");
    }
    AddLeastSquares(run.fits.kelvin_voigt_least_squares, g + "/fit/kelvin_voigt_least_squares");
    AddLeastSquares(run.fits.poynting_thomson, g + "/fit/poynting_thomson");
  }
  void AddLog(const LogResult& log) {
    const std::string g = "logs/" + log.id;
    for (const LogSourceResult& s : log.sources) {
      Add(s, g + "/" + s.source);
      for (const ChannelAnalysis& c : s.channels) Add(c, g + "/" + s.source + "/" + c.name);
    }
    if (!log.comparison) return;
    Add(*log.comparison, g + "/comparison");
    for (const ChannelComparison& c : log.comparison->channels) {
      Add(c, g + "/comparison/" + c.channel);
    }
  }

  explicit SessionFields(const SessionResult& r) {
    Add(r, "");
    if (!r.runs.empty() || !r.calibrations.empty()) Add(r.apparatus, "apparatus");
    if (!r.specimen.empty()) Add(r.specimen, "specimen");
    for (const RunResult& run : r.runs) AddRun(run);
    for (const CellCalibration& c : r.calibrations) AddCalibration(c, "calibrations");
    if (r.kelvin_voigt) {
      Add(*r.kelvin_voigt, "session/kelvin_voigt");
      if (r.kelvin_voigt->damping_line) {
        Add(*r.kelvin_voigt->damping_line, "session/kelvin_voigt/damping_line");
      }
    }
    for (const PoyntingThomsonLeastSquaresFit& fit : r.joint_fits) {
      AddLeastSquares(std::optional(fit), "session/joint_fits/poynting_thomson");
    }
    if (r.model_comparison) {
      Add(*r.model_comparison, "session/model_comparison");
      for (const ComparedRestitutionModel& m : r.model_comparison->restitution_models) {
        if (m.Ran()) Add(m, "session/model_comparison/" + m.Name());
      }
      for (const ComparedContactLaw& m : r.model_comparison->contact_laws) {
        if (m.Ran()) Add(m, "session/model_comparison/" + m.Name());
      }
    }
    for (const ContactLawFit& law : r.contact_laws) {
      if (!law.parameters.empty() || law.maxima > 0) Add(law, "session/contact_laws/" + law.law);
    }
    for (const LogResult& log : r.logs) AddLog(log);
    for (const RunPrediction& p : r.predictions) Add(p, "predictions");
  }
};

// Reduces `folder`, writes and reads it twice, and compares every listed
// field; returns the listed types the session holds.
std::set<std::string> CheckSessionRoundTrip(const std::filesystem::path& folder) {
  testing::TempDir dir;
  ReduceOptions options;
  options.jobs = 2;
  const SessionResult reduced = ReduceSession(ReadManifest(folder).session, options);
  WriteResults(reduced, dir.path() / "first.h5");
  const SessionResult first = ReadResults(dir.path() / "first.h5");
  WriteResults(first, dir.path() / "second.h5");
  const SessionResult second = ReadResults(dir.path() / "second.h5");

  const SessionFields original(reduced), once(first), twice(second);
  CHECK(once.lines.size() > 10);
  CHECK(once.lines == original.lines);
  CHECK(twice.lines == once.lines);
  // Where they differ, the first line that does.
  for (std::size_t i = 0; i < once.lines.size() && i < original.lines.size(); ++i) {
    if (once.lines[i] != original.lines[i]) {
      FAIL_CHECK(original.lines[i] << "  read back as  " << once.lines[i]);
      break;
    }
  }
  return once.types;
}

const std::filesystem::path kSamples = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data";

TEST_CASE("results_round_trip: every listed field of every result survives the file twice") {
  std::set<std::string> met;
  for (const char* session : {"thesis-1969", "logs-two-link"}) {
    INFO(session);
    met.merge(CheckSessionRoundTrip(kSamples / session));
  }
  {
    INFO("the thesis's session with its bars' [specimen], one run's own [run.specimen]");
    testing::TempDir dir;
    std::filesystem::create_directories(dir.path() / "s");
    std::string manifest = testing::ReadText(kSamples / "thesis-1969" / "session.toml");
    // [run.specimen] after the runs belongs to the last of them.
    manifest +=
        "\n[specimen]\nmaterial = \"steel\"\nend_shape = \"plane\"\nedge_radius = 0.01\n"
        "bar_length = 10.1\nbar_diameter = 1.0\nmodulus = 30e6\npoisson_ratio = 0.29\n"
        "\n[run.specimen]\nend_shape = \"sphere\"\nsphere_radius = 2.0\n";
    std::ofstream(dir.path() / "s" / "session.toml") << manifest;
    const Session session = ReadManifest(dir.path() / "s").session;
    REQUIRE(session.specimen.modulus == 30e6);
    REQUIRE(session.runs.back().specimen.sphere_radius == 2.0);
    met.merge(CheckSessionRoundTrip(dir.path() / "s"));
  }
  {
    INFO("a generated session of photos, CSV traces and typed-in maxima");
    testing::TempDir dir;
    SynthOptions synth;
    synth.preset = "quick";
    synth.style = PhotoStyle::kClean;
    synth.seed = 11;
    synth.csv_run = true;
    synth.typed_run = true;
    GenerateSession(dir.path() / "s", synth);
    met.merge(CheckSessionRoundTrip(dir.path() / "s"));
  }
  // No listed type is left out of the comparison.
  testing::ForEachListedResult([&]<typename Result>() {
    INFO(typeid(Result).name());
    CHECK(met.contains(typeid(Result).name()));
  });
}

TEST_CASE("results_round_trip: the restitution models' covariance survives the file") {
  testing::TempDir dir;
  const SessionResult reduced = ReduceSession(ReadManifest(kSamples / "thesis-1969").session, {});
  REQUIRE(reduced.model_comparison);
  WriteResults(reduced, dir.path() / "first.h5");
  const SessionResult first = ReadResults(dir.path() / "first.h5");
  REQUIRE(first.model_comparison);
  const std::vector<ComparedRestitutionModel>& reduced_models =
      reduced.model_comparison->restitution_models;
  const std::vector<ComparedRestitutionModel>& read_models =
      first.model_comparison->restitution_models;
  REQUIRE(read_models.size() == reduced_models.size());
  int compared = 0;
  for (std::size_t i = 0; i < reduced_models.size(); ++i) {
    const JointModelFit &a = reduced_models[i].fit, &b = read_models[i].fit;
    INFO(a.name);
    CHECK(b.covariance.names == a.covariance.names);
    REQUIRE(b.covariance.matrix.size() == a.covariance.matrix.size());
    for (std::size_t k = 0; k < a.covariance.matrix.size(); ++k) {
      CHECK(b.covariance.matrix[k] == Approx(a.covariance.matrix[k]).epsilon(1e-12).margin(1e-300));
    }
    if (a.name == "linear-in-speed") {
      // a and b are correlated: u_ref is the runs' mean speed, not the fit's centre.
      REQUIRE(a.covariance.names == std::vector<std::string>{"a", "b"});
      CHECK(a.covariance.matrix[1] != 0.0);
      ++compared;
    }
  }
  CHECK(compared == 1);
}

}  // namespace
}  // namespace impactlab
