// A run whose contact trace cannot be read fails alone: its maxima stand
// without a contact time, and a warning names the file, the key and why
// (pipeline/trace_run.h). Pinned on a CSV run whose contact trace shows no
// step, and on a generated photo session whose contact trace is not found.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "model/kelvin_voigt.h"
#include "model/rebound_history.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "report/tables.h"
#include "synth/session_generator.h"
#include "tests/pipeline/csv_session.h"
#include "tests/support/temp_dir.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

double ContactLostRightCell(double x) { return 2.4 - 3.1 * x + 0.9 * x * x; }
double ContactLostLeftCell(double x) { return 0.2 + 2.2 * x - 0.35 * x * x; }

// A CSV session from the Kelvin-Voigt model (noiseless), its contact trace
// flat at the rest level: no pulse on it. Returns the true sequence.
ReboundSequence WriteSessionWithFlatContact(const std::filesystem::path& dir, double x0) {
  using testing::kPendulum;
  std::filesystem::create_directories(dir / "traces");
  const double quarter = 0.5 * HalfPeriod(kPendulum, x0);
  using Cell = double (*)(double);
  for (const auto& [name, cell] : {std::pair<const char*, Cell>{"R", ContactLostRightCell},
                                   std::pair<const char*, Cell>{"L", ContactLostLeftCell}}) {
    std::vector<double> t, v;
    for (double s = -0.01; s <= 1.05 * quarter; s += 2e-4) {
      const double x = s < 0 ? x0 : ReleaseSwingDisplacement(kPendulum, x0, std::min(s, quarter));
      t.push_back(s);
      v.push_back(cell(std::max(x, 0.0)));
    }
    testing::WriteCsv(dir / "traces" / (std::string(name) + ".csv"), t, v);
  }
  const KelvinVoigtContactLaw law({testing::kBarMass, 462000.0, 9.0}, Separation::kKinematic);
  const ReboundSequence truth = SimulateRebounds(kPendulum, law, x0, 6);
  const SampledHistory h = SampleHistory(truth, kPendulum, law, 5e-4);
  std::vector<double> vr, vl;
  for (double x : h.displacement) {
    vr.push_back(ContactLostRightCell(std::max(x, 0.0)));
    vl.push_back(ContactLostLeftCell(std::max(x, 0.0)));
  }
  testing::WriteCsv(dir / "traces" / "run-right.csv", h.time, vr);
  testing::WriteCsv(dir / "traces" / "run-left.csv", h.time, vl);
  // The scope triggered, but the contact circuit's lead was off: the rest
  // level alone, with a little noise.
  std::vector<double> tc, vc;
  for (int k = 0; k < 2000; ++k) {
    tc.push_back(0.5e-6 * k);
    vc.push_back(0.1 + 0.001 * std::sin(0.7 * k));
  }
  testing::WriteCsv(dir / "traces" / "run-contact.csv", tc, vc);
  testing::WriteCsvManifest(dir, "A contact trace without a pulse", testing::kL, x0,
                            "fit_rebounds = [0, 2]\n",
                            "[run.traces.contact]\ncsv = \"traces/run-contact.csv\"\nimpact = 2\n");
  return truth;
}

// The session's warnings that name `key`.
std::vector<std::string> WarningsNaming(const SessionResult& result, const std::string& key) {
  std::vector<std::string> out;
  for (const std::string& w : result.warnings) {
    if (w.find(key) != std::string::npos) out.push_back(w);
  }
  return out;
}

TEST_CASE("contact lost: a CSV contact trace without a pulse keeps the run's maxima and warns") {
  testing::TempDir dir;
  const ReboundSequence truth = WriteSessionWithFlatContact(dir.path(), 0.6);
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE(result.runs.size() == 1);
  const RunResult& run = result.runs[0];
  INFO(run.Status());
  // The maxima as if the contact trace were not there.
  REQUIRE(run.ok);
  REQUIRE(run.measured.xmax.size() >= 4);
  for (std::size_t n = 0; n < run.measured.xmax.size(); ++n) {
    CHECK(run.measured.xmax[n] == Approx(truth.xmax[n + 1]).epsilon(1e-6));
  }
  // No contact time, so no stiffness; the damping ratio from the maxima stands.
  CHECK_FALSE(run.measured.contact_time.has_value());
  CHECK(run.measured.contact_time_source.empty());
  REQUIRE(run.fits.kelvin_voigt.has_value());
  CHECK(run.fits.kelvin_voigt->ok);
  CHECK_FALSE(run.fits.kelvin_voigt->stiffness.has_value());
  // Said with the file, the key and why.
  const std::vector<std::string> said = WarningsNaming(result, "run \"run\".traces.contact");
  REQUIRE(said.size() == 1);
  CHECK_THAT(said[0], Catch::StartsWith((dir.path() / "traces" / "run-contact.csv").string() +
                                        ": run \"run\".traces.contact: "));
  CHECK_THAT(said[0], Catch::Contains("the contact trace shows no step above its noise"));
  CHECK_THAT(said[0], Catch::Contains("maxima are kept without its contact time"));
  // Measured in part: a later reduce measures it again (and says why again).
  CHECK(run.fingerprint.empty());
  // The results file and the report hold no contact time for it, and no NaN.
  WriteResults(result, dir.path() / "r.h5");
  const SessionResult read = ReadResults(dir.path() / "r.h5");
  REQUIRE(read.FindRun("run") != nullptr);
  CHECK(read.FindRun("run")->ok);
  CHECK_FALSE(read.FindRun("run")->measured.contact_time.has_value());
  CHECK(read.FindRun("run")->measured.xmax == run.measured.xmax);
  CHECK(WarningsNaming(read, "run \"run\".traces.contact").size() == 1);
  // The report's tables: the run's contact time "-", the warning on the
  // list of what to check, no NaN anywhere.
  for (const ReportFormat format : {ReportFormat::kMarkdown, ReportFormat::kCsv}) {
    std::string text = RenderTables("t", BuildTables(read), format);
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) {
      return static_cast<char>(std::tolower(c));
    });
    CHECK(text.find("nan") == std::string::npos);
    CHECK(text.find("traces.contact") != std::string::npos);
  }
}

TEST_CASE("contact lost: a contact trace not found on the photo keeps the run's maxima and warns") {
  testing::TempDir dir;
  SynthOptions synth;
  synth.preset = "quick";
  synth.style = PhotoStyle::kClean;
  synth.seed = 7;
  const SynthSummary summary = GenerateSession(dir.path() / "s", synth);
  // The first photo run's contact trace given a point far off its band: the
  // digitizer refuses the trace (traces.contact.points[0]), as it refuses one
  // it cannot find, before it reads the bars.
  const std::filesystem::path manifest = dir.path() / "s" / "session.toml";
  std::string text;
  {
    std::ifstream in(manifest);
    std::stringstream all;
    all << in.rdbuf();
    text = all.str();
  }
  const std::string table = "[run.traces.contact]\n";
  const std::size_t at = text.find(table);
  REQUIRE(at != std::string::npos);
  text.insert(at + table.size(), "points = [[2, 2], [3, 3]]\n");
  std::ofstream(manifest) << text;
  const Session session = ReadManifest(dir.path() / "s").session;
  const Run& victim = *std::find_if(session.runs.begin(), session.runs.end(), [](const Run& r) {
    return r.traces.count("contact") && !r.traces.at("contact").points_px.empty();
  });

  ReduceOptions options;
  options.products = Products::kRebounds;
  const SessionResult result = ReduceSession(session, options);
  int with_contact = 0;
  for (const auto& truth : summary.truth["runs"]) {
    const RunResult* run = result.FindRun(truth["id"]);
    REQUIRE(run != nullptr);
    INFO("run " << run->id << ": " << run->Status());
    REQUIRE(run->ok);
    const double x0 = truth["initial_displacement"];
    const auto& xmax = truth["rebounds"]["xmax"];
    REQUIRE(run->measured.xmax.size() >= 3);
    for (std::size_t n = 0; n < run->measured.xmax.size() && n < xmax.size(); ++n) {
      CHECK(std::abs(run->measured.xmax[n] - xmax[n].get<double>()) / x0 < 0.005);
    }
    if (run->id == victim.id) {
      CHECK_FALSE(run->measured.contact_time.has_value());
    } else {
      with_contact += run->measured.contact_time.has_value();
    }
  }
  CHECK(with_contact >= 1);  // the other photo run's contact trace is read
  const std::string key = "run \"" + victim.id + "\".traces.contact";
  const std::vector<std::string> said = WarningsNaming(result, key);
  REQUIRE(said.size() == 1);
  CHECK_THAT(said[0], Catch::StartsWith(victim.photo->string() + ": " + key + ".points[0]: "));
  CHECK_THAT(said[0], Catch::Contains("outside its band"));
}

}  // namespace
}  // namespace impactlab
