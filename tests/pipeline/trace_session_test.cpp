// A session whose runs come as CSV traces (digital scope), made from the
// model with known photocell curves: reduce recovers the maxima, the contact
// time and the Kelvin-Voigt parameters.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include <iterator>

#include <string>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "io/trace.h"
#include "model/kelvin_voigt.h"
#include "model/rebound_history.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "pipeline/run_fingerprint.h"
#include "pipeline/trace_run.h"
#include "tests/pipeline/csv_session.h"
#include "tests/support/temp_dir.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kBarMass;
using testing::kL;
using testing::kPendulum;
constexpr double kK = 462000.0, kC = 9.0;

double RightCell(double x) { return 2.4 - 3.1 * x + 0.9 * x * x; }  // falls with X (x < 1.5)
double LeftCell(double x) { return 0.2 + 2.2 * x - 0.35 * x * x; }  // inverted amplifier

struct Written {
  ReboundSequence truth;
};

using testing::WriteCsv;

// The calibration sweep of one cell and the run's three traces.
Written WriteSession(const std::filesystem::path& dir, double x0, double noise_volts) {
  std::filesystem::create_directories(dir / "traces");
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, noise_volts);
  const double quarter = 0.5 * HalfPeriod(kPendulum, x0);
  using Cell = double (*)(double);
  for (const auto& [name, cell] : {std::pair<const char*, Cell>{"R", RightCell},
                                   std::pair<const char*, Cell>{"L", LeftCell}}) {
    std::vector<double> t, v;
    for (double s = -0.01; s <= 1.05 * quarter; s += 2e-4) {
      const double x = s < 0 ? x0 : ReleaseSwingDisplacement(kPendulum, x0, std::min(s, quarter));
      t.push_back(s);
      v.push_back(cell(std::max(x, 0.0)) + noise(rng));
    }
    WriteCsv(dir / "traces" / (std::string(name) + ".csv"), t, v);
  }
  const KelvinVoigtContactLaw law({kBarMass, kK, kC}, Separation::kKinematic);
  Written w{SimulateRebounds(kPendulum, law, x0, 6)};
  const SampledHistory h = SampleHistory(w.truth, kPendulum, law, 5e-4);
  std::vector<double> vr, vl;
  for (double x : h.displacement) {
    vr.push_back(RightCell(std::max(x, 0.0)) + noise(rng));
    vl.push_back(LeftCell(std::max(x, 0.0)) + noise(rng));
  }
  WriteCsv(dir / "traces" / "run-right.csv", h.time, vr);
  WriteCsv(dir / "traces" / "run-left.csv", h.time, vl);
  // The delayed sweep's time axis starts 100 us before the second impact.
  std::vector<double> tc, vc;
  const double tau_c = w.truth.contact.contact_time;
  for (double s = 0.0; s < 1e-3; s += 0.5e-6) {
    tc.push_back(s);
    vc.push_back((s >= 100e-6 && s < 100e-6 + tau_c ? 2.5 : 0.1) + noise(rng) * 0.1);
  }
  WriteCsv(dir / "traces" / "run-contact.csv", tc, vc);
  testing::WriteCsvManifest(dir, "CSV traces from the model", kL, x0, "fit_rebounds = [0, 2]\n",
                            "[run.traces.contact]\ncsv = \"traces/run-contact.csv\"\nimpact = 2\n");
  return w;
}

TEST_CASE("trace_session: CSV traces reduce to the model's maxima, contact time and K, C") {
  testing::TempDir dir;
  const Written w = WriteSession(dir.path(), 0.6, 0.0);
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE(result.runs.size() == 1);
  const RunResult& run = result.runs[0];
  INFO(run.Status());
  REQUIRE(run.ok);
  CHECK(run.measured.source == "csv");
  REQUIRE(run.measured.xmax.size() >= 4);
  for (std::size_t n = 0; n < run.measured.xmax.size(); ++n) {
    // Session rebound n is PENDUL rebound n + 1 (first_rebound = 1).
    CHECK(run.measured.xmax[n] == Approx(w.truth.xmax[n + 1]).epsilon(1e-6));
    CHECK(run.measured.t_peak[n] == Approx(w.truth.peak_time[n + 1]).margin(1e-5));
  }
  CHECK(run.measured.contact_time_source == "contact trace");
  CHECK(*run.measured.contact_time == Approx(w.truth.contact.contact_time).margin(1e-6));
  CHECK(run.fits.kelvin_voigt->stiffness->value == Approx(kK).epsilon(1e-2));
  CHECK(run.fits.kelvin_voigt->damping->value == Approx(kC).epsilon(2e-2));
  REQUIRE(run.measured.calibrations.size() == 2);
  CHECK(run.measured.calibrations[0].residual_rms_volts < 1e-6);
}

TEST_CASE("trace_session: with noisy traces the maxima stay within their reported uncertainty") {
  testing::TempDir dir;
  const Written w = WriteSession(dir.path(), 0.405, 0.005);
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  const RunResult& run = result.runs[0];
  INFO(run.Status());
  REQUIRE(run.ok);
  for (std::size_t n = 0; n < run.measured.xmax.size(); ++n) {
    INFO("rebound " << n);
    CHECK(run.measured.xmax_sigma[n] > 0.0);
    CHECK(std::abs(run.measured.xmax[n] - w.truth.xmax[n + 1]) < 5.0 * run.measured.xmax_sigma[n]);
    CHECK(std::abs(run.measured.xmax[n] - w.truth.xmax[n + 1]) < 5e-4 * 0.405);  // 0.05 % of X0
  }
}

// The session in `dir` with its calibration `id` ("R" or "L") swung from
// `x0` instead (its trace and its X0 replaced).
Session WithCellCalibratedAt(const std::filesystem::path& dir, const std::string& id, double x0,
                             double noise_volts) {
  WriteSession(dir / "other", x0, noise_volts);
  const std::string file = id + ".csv";
  std::filesystem::copy_file(dir / "other" / "traces" / file, dir / "traces" / file,
                             std::filesystem::copy_options::overwrite_existing);
  Session session = ReadManifest(dir).session;
  for (Calibration& c : session.calibrations) {
    if (c.id == id) c.initial_displacement = x0;
  }
  return session;
}

// The warnings of a reduce of the session in `dir` that mention `about`.
std::vector<std::string> WarningsAbout(const std::filesystem::path& dir, const std::string& about) {
  std::vector<std::string> found;
  for (const std::string& w : ReduceSession(ReadManifest(dir).session, {}).warnings) {
    if (w.find(about) != std::string::npos) found.push_back(w);
  }
  return found;
}

TEST_CASE(
    "trace_session: a calibration sweep read off a mark for a stretch reduces without it, and "
    "says so") {
  testing::TempDir dir;
  const double x0 = 0.405;
  const Written w = WriteSession(dir.path(), x0, 0.002);
  // The right cell's sweep 0.15 V off where the bar passes X = 0.05 .. 0.12 X0
  // (fast: a few milliseconds), as a tracking that followed a mark would be.
  const std::filesystem::path sweep = dir.path() / "traces" / "R.csv";
  Trace trace = ReadTraceCsv(sweep);
  const double quarter = 0.5 * HalfPeriod(kPendulum, x0);
  double from = 1e9, to = -1e9;
  for (std::size_t i = 0; i < trace.time_s.size(); ++i) {
    const double t = trace.time_s[i];
    if (t < 0.0 || t > quarter) continue;
    const double s = ReleaseSwingDisplacement(kPendulum, x0, t) / x0;
    if (s < 0.05 || s > 0.12) continue;
    trace.volts[i] += 0.15;
    from = std::min(from, t);
    to = std::max(to, t);
  }
  WriteTraceCsv(sweep, trace);

  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE(result.runs.size() == 1);
  const RunResult& run = result.runs[0];
  INFO(run.Status());
  REQUIRE(run.ok);
  const CellCalibration& right = run.measured.calibrations.at(0);
  REQUIRE(right.calibration_id == "R");
  REQUIRE(right.left_out_from_s.size() == 1);
  CHECK(right.left_out_from_s[0] == Approx(from).margin(5e-4));
  CHECK(right.left_out_to_s[0] == Approx(to).margin(5e-4));
  CHECK(std::any_of(result.warnings.begin(), result.warnings.end(), [](const std::string& w) {
    return w.find("calibration \"R\"") != std::string::npos &&
           w.find("left out as misread") != std::string::npos;
  }));
  for (std::size_t n = 0; n < run.measured.xmax.size(); ++n) {
    CHECK(std::abs(run.measured.xmax[n] - w.truth.xmax[n + 1]) < 3.0 * run.measured.xmax_sigma[n]);
  }
}

TEST_CASE("trace_session: a typed X0 the traces' own release contradicts is warned about") {
  // The traces read X0 = 0.405 (through calibrations typed right); the run's
  // X0 typed 10 % high is named with both values, the right one passes.
  testing::TempDir dir;
  WriteSession(dir.path(), 0.405, 0.005);
  const auto x0_warnings = [&] { return WarningsAbout(dir.path(), "initial_displacement"); };
  CHECK(x0_warnings().empty());
  std::string manifest;
  {
    std::ifstream in(dir.path() / "session.toml");
    manifest.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string typed = "initial_displacement = 0.405";
  manifest.replace(manifest.rfind(typed), typed.size(), "initial_displacement = 0.4455");
  std::ofstream(dir.path() / "session.toml") << manifest;
  const std::vector<std::string> found = x0_warnings();
  REQUIRE(found.size() == 1);
  INFO(found[0]);
  CHECK(found[0].find("run \"run\": initial_displacement = 0.4455") != std::string::npos);
  CHECK(found[0].find("release at 0.40") != std::string::npos);
}

TEST_CASE("trace_session: one bar's release off while the other's agrees names that bar's trace") {
  // The left cell calibrated over a larger swing (0.5), so that the run's
  // left volts shifted by +0.05 V (a zero_div slip) stay in range: the left
  // bar then releases 6 % high while the right bar agrees with X0. The
  // warning names the left trace's voltage scale and its calibration, not X0.
  testing::TempDir dir;
  WriteSession(dir.path(), 0.405, 0.005);
  const Session session = WithCellCalibratedAt(dir.path(), "L", 0.5, 0.005);
  const auto release_warnings = [&] {
    std::vector<std::string> found;
    for (const std::string& w : ReduceSession(session, {}).warnings) {
      if (w.find("release") != std::string::npos) found.push_back(w);
    }
    return found;
  };
  CHECK(release_warnings().empty());
  Trace left = ReadTraceCsv(dir.path() / "traces" / "run-left.csv");
  for (double& v : left.volts) v += 0.05;
  WriteTraceCsv(dir.path() / "traces" / "run-left.csv", left);
  const std::vector<std::string> found = release_warnings();
  REQUIRE(found.size() == 1);
  INFO(found[0]);
  CHECK_THAT(found[0], Catch::Contains("run \"run\": the left bar's trace releases at 0.427") &&
                           Catch::Contains("traces.left's voltage scale") &&
                           Catch::Contains("calibration \"L\"") && !Catch::Contains("X0 mistyped"));
}

TEST_CASE("trace_session: run volts on another scale than the calibration's say so") {
  // The right bar's volts 0.8 times what its calibration reads (a CSV in
  // another unit, a volts_per_div typed low): both ends of its range miss the
  // calibration's by that factor, and the refusal says it.
  testing::TempDir dir;
  WriteSession(dir.path(), 0.405, 0.005);
  Trace right = ReadTraceCsv(dir.path() / "traces" / "run-right.csv");
  for (double& v : right.volts) v *= 0.8;
  WriteTraceCsv(dir.path() / "traces" / "run-right.csv", right);
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE_FALSE(result.runs[0].ok);
  CHECK_THAT(result.runs[0].reason, Catch::Contains("traces.right") &&
                                        Catch::Contains("does not cover") &&
                                        Catch::Contains("0.799 times the calibration's"));
}

TEST_CASE("trace_session: a line followed far outside the calibration is left out and said") {
  // The left trace's reading leaves it 0.1 s before session rebound 1's
  // crest and follows a scratch down, far below the volts of X = 0, for
  // 0.15 s, then jumps back to the trace: that stretch is left out whole,
  // the bar's crest with it, and the run reads on its other samples and the
  // right bar's, each maximum within its error of the model's.
  testing::TempDir dir;
  const Written w = WriteSession(dir.path(), 0.405, 0.005);
  Trace left = ReadTraceCsv(dir.path() / "traces" / "run-left.csv");
  const double from_s = w.truth.peak_time[2] - 0.1, to_s = from_s + 0.15;
  const double low = LeftCell(0.0) - 0.5 * (LeftCell(0.405) - LeftCell(0.0));
  double from_volts = 0.0;
  for (std::size_t i = 0; i < left.time_s.size(); ++i) {
    const double t = left.time_s[i];
    if (t < from_s) from_volts = left.volts[i];
    if (t >= from_s && t <= to_s) {
      left.volts[i] = from_volts + (low - from_volts) * (t - from_s) / (to_s - from_s);
    }
  }
  WriteTraceCsv(dir.path() / "traces" / "run-left.csv", left);
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  const RunResult& run = result.runs[0];
  INFO(run.Status());
  REQUIRE(run.ok);
  REQUIRE(run.measured.left);
  REQUIRE(run.measured.left->left_out_from_s.size() == 1);
  // From where the trace, falling back in time from the scratch, falls 3
  // sigma below it (some 20 ms).
  CHECK(run.measured.left->left_out_from_s[0] < from_s);
  CHECK(run.measured.left->left_out_from_s[0] > from_s - 0.04);
  CHECK(run.measured.left->left_out_to_s[0] == Approx(to_s).margin(1e-3));
  CHECK(run.measured.right->left_out_from_s.empty());
  REQUIRE(run.measured.xmax.size() >= 4);
  for (std::size_t n = 0; n < run.measured.xmax.size(); ++n) {
    INFO("rebound " << n);
    CHECK(std::abs(run.measured.xmax[n] - w.truth.xmax[n + 1]) < 5.0 * run.measured.xmax_sigma[n]);
    CHECK(std::abs(run.measured.xmax[n] - w.truth.xmax[n + 1]) < 5e-4 * 0.405);  // 0.05 % of X0
  }
  const auto said = std::find_if(result.warnings.begin(), result.warnings.end(), [](auto& w) {
    return w.find("left out as misread") != std::string::npos;
  });
  REQUIRE(said != result.warnings.end());
  CHECK_THAT(*said, Catch::Contains("run \"run\": its left trace lies far outside"));
}

TEST_CASE("trace_session: a run time axis the pendulum's period contradicts is warned about") {
  // Durations read to ~0.05 %: the run's traces on a time axis 2 % slow (a
  // mistyped time_per_div or time unit) are named with the ratio; as
  // written, nothing.
  testing::TempDir dir;
  WriteSession(dir.path(), 0.405, 0.005);
  const auto sweep_warnings = [&] { return WarningsAbout(dir.path(), "half period"); };
  CHECK(sweep_warnings().empty());
  for (const char* bar : {"run-right.csv", "run-left.csv"}) {
    Trace trace = ReadTraceCsv(dir.path() / "traces" / bar);
    for (double& t : trace.time_s) t *= 1.02;
    WriteTraceCsv(dir.path() / "traces" / bar, trace);
  }
  const std::vector<std::string> found = sweep_warnings();
  REQUIRE(found.size() == 1);
  INFO(found[0]);
  CHECK(found[0].find("run \"run\"") != std::string::npos);
  CHECK(found[0].find("last 1.02") != std::string::npos);
}

TEST_CASE("trace_session: a missing trace file is refused when the manifest is read, naming it") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  std::filesystem::remove(dir.path() / "traces" / "L.csv");
  // The calibration whose trace it is fails, and so does the run that needs it.
  const Session session = ReadManifest(dir.path()).session;
  REQUIRE_FALSE(session.rejected.empty());
  for (const RejectedEntry& entry : session.rejected) {
    CHECK_THAT(entry.Reason(), Catch::Contains("L.csv"));
  }
  CHECK(session.runs.empty());
}

TEST_CASE("trace_session: a calibration that does not cover the run is refused") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  // Recalibrate from a smaller swing: the run's larger displacements fall outside.
  const Session session = WithCellCalibratedAt(dir.path(), "R", 0.2, 0.0);
  const SessionResult result = ReduceSession(session, {});
  CHECK_FALSE(result.runs[0].ok);
  CHECK_THAT(result.runs[0].reason, Catch::Contains("does not cover"));
}

// The left calibration's trace from a 0.6 in release through a cell that
// folds over (not monotone): its output peaks at X = 0.37 in.
void WriteLeftCellFoldingOver(const std::filesystem::path& folder) {
  const double quarter = 0.5 * HalfPeriod(kPendulum, 0.6);
  std::vector<double> t, v;
  for (double s = -0.01; s <= 1.05 * quarter; s += 2e-4) {
    const double x = s < 0 ? 0.6 : ReleaseSwingDisplacement(kPendulum, 0.6, std::min(s, quarter));
    t.push_back(s);
    v.push_back(0.2 + 2.2 * std::max(x, 0.0) - 3.0 * x * x);
  }
  WriteCsv(folder / "traces" / "L.csv", t, v);
}

TEST_CASE("trace_session: a broken calibration no run reached is still reported") {
  // The run fails on its right trace (a calibration from a smaller swing)
  // before it asks for its left calibration, whose cell folds over (not
  // monotone): the left calibration's failure is a warning of its own.
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  WriteLeftCellFoldingOver(dir.path());
  const Session session = WithCellCalibratedAt(dir.path(), "R", 0.2, 0.0);
  const SessionResult result = ReduceSession(session, {});
  REQUIRE_FALSE(result.runs[0].ok);
  CHECK_THAT(result.runs[0].reason, Catch::Contains("does not cover"));
  const auto left = std::find_if(
      result.warnings.begin(), result.warnings.end(),
      [](const std::string& w) { return w.find("calibration \"L\"") != std::string::npos; });
  REQUIRE(left != result.warnings.end());
  CHECK_THAT(*left, Catch::Contains("not monotone"));
  CHECK_THAT(*left, Catch::Contains("L.csv"));
}

TEST_CASE("trace_session: fit_rebounds beyond the measured rebounds fail the run, kept measured") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  Session session = ReadManifest(dir.path()).session;
  session.runs[0].fit_rebounds = {0, 40};
  const SessionResult result = ReduceSession(session, {});
  const RunResult& run = result.runs[0];
  CHECK_FALSE(run.ok);
  CHECK(
      run.reason ==
      fmt::format("{}: run \"run\": fit_rebounds = [0, 40] but only rebounds 0 .. {} were measured",
                  session.manifest.string(), run.measured.xmax.size() - 1));
  // The rebounds were measured before the fit was refused: they stay.
  CHECK(run.measured.xmax.size() >= 2);
  CHECK_FALSE(run.fits.kelvin_voigt.has_value());
}

// Two runs sharing nothing: the trace session's run and a second, typed-in one.
Session TwoRunSession(const std::filesystem::path& dir) {
  WriteSession(dir, 0.6, 0.001);
  std::ofstream(dir / "session.toml", std::ios::app) << R"(
[[run]]
id = "typed"
initial_displacement = 0.405
rebounds = [0.293, 0.195, 0.129]
contact_time = 353e-6
)";
  return ReadManifest(dir).session;
}

TEST_CASE("incremental: unchanged runs reuse their measurement, an edited run is measured again") {
  testing::TempDir dir;
  const Session session = TwoRunSession(dir.path());
  const SessionResult first = ReduceSession(session, {});
  REQUIRE(first.FailedRuns() == 0);
  ReduceOptions again;
  again.previous = &first;
  const SessionResult second = ReduceSession(session, again);
  CHECK(second.runs[0].reused);
  CHECK_FALSE(second.runs[1].reused);  // typed-in runs read the manifest, never the file
  CHECK(second.runs[1].measured.xmax == first.runs[1].measured.xmax);
  CHECK(second.runs[0].measured.xmax == first.runs[0].measured.xmax);
  CHECK(second.runs[0].fits.kelvin_voigt->stiffness->value ==
        first.runs[0].fits.kelvin_voigt->stiffness->value);

  // Edit the typed-in run only: the trace run is still reused.
  Session edited = session;
  edited.runs[1].rebounds[2] = 0.128;
  const SessionResult third = ReduceSession(edited, again);
  CHECK(third.runs[0].reused);
  CHECK_FALSE(third.runs[1].reused);
  CHECK(third.runs[1].measured.xmax[2] == 0.128);

  // A changed input file (a calibration's bytes) invalidates the runs using it.
  WriteSession(dir.path() / "other", 0.6, 0.002);
  std::filesystem::copy_file(dir.path() / "other" / "traces" / "R.csv",
                             dir.path() / "traces" / "R.csv",
                             std::filesystem::copy_options::overwrite_existing);
  const SessionResult fourth = ReduceSession(session, again);
  CHECK_FALSE(fourth.runs[0].reused);
  CHECK_FALSE(fourth.runs[1].reused);
}

TEST_CASE("incremental: the results file says which runs' measurements were reused") {
  testing::TempDir dir;
  const Session session = TwoRunSession(dir.path());
  const SessionResult first = ReduceSession(session, {});
  ReduceOptions again;
  again.previous = &first;
  WriteResults(ReduceSession(session, again), dir.path() / "again.h5");
  const SessionResult read = ReadResults(dir.path() / "again.h5");
  CHECK(read.runs.at(0).reused);
  CHECK_FALSE(read.runs.at(1).reused);
}

// Issue 14, item 4: reuse never serves stale or corrupt results.

// The trace session with a second trace run ("again", the same traces) and
// the typed-in run.
Session ThreeRunSession(const std::filesystem::path& dir) {
  TwoRunSession(dir);
  std::ofstream(dir / "session.toml", std::ios::app) << R"(
[[run]]
id = "again"
initial_displacement = 0.6
calibration = { right = "R", left = "L" }
fit_rebounds = [0, 2]
[run.traces.right]
csv = "traces/run-right.csv"
[run.traces.left]
csv = "traces/run-left.csv"
)";
  return ReadManifest(dir).session;
}

// Which runs of `result` were measured again rather than reused.
std::vector<std::string> Remeasured(const SessionResult& result) {
  std::vector<std::string> ids;
  for (const RunResult& run : result.runs) {
    if (!run.reused) ids.push_back(run.id);
  }
  return ids;
}

TEST_CASE("reuse: a changed setting re-measures exactly the runs it touches") {
  testing::TempDir dir;
  const Session session = ThreeRunSession(dir.path());
  const SessionResult first = ReduceSession(session, {});
  REQUIRE(first.FailedRuns() == 0);
  ReduceOptions again;
  again.previous = &first;
  using Ids = std::vector<std::string>;
  // Typed-in runs are always read afresh from the manifest.
  CHECK(Remeasured(ReduceSession(session, again)) == Ids{"typed"});

  // A run's own setting: that run alone.
  Session edited = session;
  edited.runs[2].settings["rebound_extraction.peak_window_fraction"] = {
      0.4, {session.manifest, "run \"again\".rebound_extraction.peak_window_fraction", 30}};
  const SessionResult own = ReduceSession(edited, again);
  CHECK(Remeasured(own) == Ids{"typed", "again"});
  CHECK(own.runs[2].measured.xmax !=
        first.runs[2].measured.xmax);  // measured with a narrower peak window
  CHECK(own.runs[0].measured.xmax == first.runs[0].measured.xmax);

  // The photocell's: every run whose traces are converted with a calibration.
  ReduceOptions photocell = again;
  photocell.overrides = CommandLineSettings({{"photocell.max_order", "7"}});
  CHECK(Remeasured(ReduceSession(session, photocell)) == Ids{"run", "typed", "again"});

  // The digitizer's: no run of CSV traces.
  ReduceOptions digitize = again;
  digitize.overrides = CommandLineSettings({{"digitize.traces.method", "gaussian"}});
  CHECK(Remeasured(ReduceSession(session, digitize)) == Ids{"typed"});

  // A fit's: nothing is measured again, the fits are redone with it.
  ReduceOptions fit = again;
  fit.overrides = CommandLineSettings({{"fit.kelvin_voigt.solver.max_iterations", "1"}});
  const SessionResult refit = ReduceSession(session, fit);
  CHECK(Remeasured(refit) == Ids{"typed"});
  REQUIRE(first.runs[0].fits.kelvin_voigt_least_squares);
  REQUIRE(refit.runs[0].fits.kelvin_voigt_least_squares);
  CHECK(first.runs[0].fits.kelvin_voigt_least_squares->status.converged);
  // One iteration is not enough.
  CHECK_FALSE(refit.runs[0].fits.kelvin_voigt_least_squares->status.converged);
}

TEST_CASE("settings: manifest -> options -> results file -> options, for every result") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.001);
  std::ofstream(dir.path() / "session.toml", std::ios::app) << R"(
[run.rebound_extraction]
peak_window_fraction = 0.4
[photocell]
max_order = 7
[digitize.traces]
method = "gaussian"
)";
  const Session session = ReadManifest(dir.path()).session;
  ReduceOptions options;
  options.overrides = CommandLineSettings({{"fit.kelvin_voigt.loss.kind", "huber"}});
  const SessionResult written = ReduceSession(session, options);
  REQUIRE(written.FailedRuns() == 0);
  WriteResults(written, dir.path() / "r.h5");
  const SessionResult read = ReadResults(dir.path() / "r.h5");

  // What each result was reduced with, as the options resolve it.
  const StageOptions session_options = SessionStageOptions({}, session, options.overrides);
  const StageOptions run_options =
      EntryStageOptions(session_options, session.runs[0].settings, options.overrides);
  CHECK(run_options.rebound_extraction.peak_window_fraction == 0.4);
  CHECK(run_options.photocell.max_order == 7);
  CHECK(run_options.fit.kelvin_voigt.loss.kind == RobustLoss::kHuber);
  CHECK(read.settings == SettingsOf(session_options));
  // A run of CSV traces: no digitizer's settings, the rest as it resolved them.
  const RunResult& run = read.runs[0];
  CHECK(run.settings == SettingsOfStages(run_options, {"rebound_extraction", "fit"}));
  REQUIRE(run.measured.calibrations.size() == 2);
  CHECK(run.measured.calibrations[0].settings == SettingsOfStages(session_options, {"photocell"}));

  // And back into options: the file's settings give the same options.
  StageOptions from_file;
  for (const auto& [key, value] : run.settings) {
    INFO(key);
    CHECK_FALSE(ApplySetting(from_file, key, value).has_value());
  }
  CHECK(SettingsOfStages(from_file, {"rebound_extraction", "fit"}) == run.settings);
}

TEST_CASE("reuse: a changed convention measures again and matches a fresh run") {
  testing::TempDir dir;
  const Session session = TwoRunSession(dir.path());
  const SessionResult exact = ReduceSession(session, {});
  REQUIRE(exact.FailedRuns() == 0);
  ReduceOptions thesis;
  thesis.convention = PendulumConvention::kThesis;
  const SessionResult fresh = ReduceSession(session, thesis);
  thesis.previous = &exact;
  const SessionResult again = ReduceSession(session, thesis);
  REQUIRE(again.FailedRuns() == 0);
  CHECK(again.convention == PendulumConvention::kThesis);
  for (std::size_t i = 0; i < again.runs.size(); ++i) {
    INFO("run " << again.runs[i].id);
    CHECK_FALSE(again.runs[i].reused);
    CHECK(again.runs[i].fingerprint != exact.runs[i].fingerprint);
    CHECK(again.runs[i].measured.xmax == fresh.runs[i].measured.xmax);
  }
  // The calibration depends on the pendulum: the trace run's maxima differ.
  CHECK(again.runs[0].measured.xmax != exact.runs[0].measured.xmax);
}

TEST_CASE("reuse: the fingerprint covers the convention, separation and producer, not products") {
  testing::TempDir dir;
  const Session session = TwoRunSession(dir.path());
  const Run& run = session.runs[0];
  const std::string base = RunFingerprint(run, session, {});
  CHECK(RunFingerprint(run, session, {}) == base);
  ReduceOptions o;
  o.convention = PendulumConvention::kThesis;
  CHECK(RunFingerprint(run, session, o) != base);
  o = {};
  o.convention = PendulumConvention::kExact;  // the manifest's own: the same
  CHECK(RunFingerprint(run, session, o) == base);
  o = {};
  o.separation = Separation::kForce;
  CHECK(RunFingerprint(run, session, o) != base);
  // What is made of a measurement is no part of it.
  o = {};
  o.products = Products::kRebounds;
  CHECK(RunFingerprint(run, session, o) == base);
  o = {};
  o.overrides = CommandLineSettings(
      {{"products.model_comparison", "false"}, {"products.contact_laws.hertz", "false"}});
  CHECK(RunFingerprint(run, session, o) == base);
  o = {};
  o.producer = "impactlab 0.1.0+gdeadbee";
  CHECK(RunFingerprint(run, session, o) != base);
  Session thesis = session;
  thesis.reduction.convention = "thesis";
  CHECK(RunFingerprint(run, thesis, {}) != base);
}

TEST_CASE("reuse: a product asked for later is added without measuring any run again") {
  testing::TempDir dir;
  const Session session = ThreeRunSession(dir.path());
  ReduceOptions fewer;
  fewer.overrides = CommandLineSettings(
      {{"products.contact_laws.hunt_crossley", "false"}, {"products.joint_fits", "false"}});
  const SessionResult first = ReduceSession(session, fewer);
  REQUIRE(first.FailedRuns() == 0);
  REQUIRE(first.FindProduct("contact_laws.hunt_crossley") != nullptr);
  CHECK(first.FindProduct("contact_laws.hunt_crossley")->Status() == "skipped: not asked");
  CHECK(first.joint_fits.empty());
  const auto file = dir.path() / "out.h5";
  WriteResults(first, file);

  // The same session with the defaults, the earlier file as reduce reads it.
  const SessionResult previous = ReadResults(file);
  ReduceOptions more;
  more.previous = &previous;
  const SessionResult second = ReduceSession(session, more);
  CHECK(Remeasured(second) == std::vector<std::string>{"typed"});  // typed-in: always read afresh
  for (std::size_t i = 0; i < second.runs.size(); ++i) {
    CHECK(second.runs[i].fingerprint == first.runs[i].fingerprint);
    CHECK(second.runs[i].measured.xmax == first.runs[i].measured.xmax);
  }
  CHECK(second.FindProduct("contact_laws.hunt_crossley")->Status() == "made");
  CHECK(std::any_of(second.contact_laws.begin(), second.contact_laws.end(),
                    [](const ContactLawFit& f) { return f.law == "hunt-crossley"; }));
  CHECK_FALSE(second.joint_fits.empty());
  // And the other way: --only rebounds, then everything, re-measures nothing.
  ReduceOptions rebounds;
  rebounds.products = Products::kRebounds;
  const SessionResult measured_only = ReduceSession(session, rebounds);
  CHECK(measured_only.contact_laws.empty());
  CHECK_THAT(measured_only.FindProduct("model_comparison")->Status(),
             Catch::StartsWith("skipped: not asked"));
  ReduceOptions fit;
  fit.previous = &measured_only;
  CHECK(Remeasured(ReduceSession(session, fit)) == std::vector<std::string>{"typed"});
}

TEST_CASE("reuse: a NaN written into one run's xmax measures that run again, others reused") {
  testing::TempDir dir;
  const Session session = ThreeRunSession(dir.path());
  const SessionResult first = ReduceSession(session, {});
  REQUIRE(first.FailedRuns() == 0);
  REQUIRE(first.runs.size() == 3);
  REQUIRE(first.runs[2].id == "again");
  const auto file = dir.path() / "out.h5";
  WriteResults(first, file);
  // A copy with a NaN in run "run"'s xmax[1] and in the typed run's xmax[0].
  SessionResult edited = ReadResults(file);
  const auto run_of = [](SessionResult& r, const std::string& id) -> RunResult& {
    return *std::find_if(r.runs.begin(), r.runs.end(),
                         [&](const RunResult& run) { return run.id == id; });
  };
  run_of(edited, "run").measured.xmax[1] = std::nan("");
  run_of(edited, "typed").measured.xmax[0] = std::nan("");
  const auto copy = dir.path() / "edited.h5";
  WriteResults(edited, copy);
  const SessionResult previous = ReadResults(copy);
  REQUIRE(std::isnan(previous.FindRun("run")->measured.xmax[1]));
  CHECK_THAT(ReuseProblem(previous.FindRun("run")->measured), Catch::Equals("xmax[1] is nan"));
  CHECK(ReuseProblem(previous.FindRun("again")->measured).empty());

  ReduceOptions options;
  options.previous = &previous;
  const SessionResult second = ReduceSession(session, options);
  REQUIRE(second.FailedRuns() == 0);
  CHECK_FALSE(second.runs[0].reused);
  CHECK(second.runs[0].measured.xmax == first.runs[0].measured.xmax);
  CHECK_FALSE(second.runs[1].reused);  // typed-in: the manifest's values, not the file's
  CHECK(second.runs[1].measured.xmax == session.runs[1].rebounds);
  CHECK(second.runs[2].reused);
  CHECK(second.runs[2].measured.xmax == first.runs[2].measured.xmax);
}

TEST_CASE("reuse: values that are not finite or disagree in size are named") {
  RunMeasurement r;
  r.xmax = {0.3, 0.2};
  r.xmax_sigma = {1e-3, 1e-3};
  CHECK(ReuseProblem(r).empty());
  RunMeasurement bad = r;
  bad.xmax_sigma.pop_back();
  CHECK_THAT(ReuseProblem(bad), Catch::Contains("xmax has 2 values but xmax_std_error has 1"));
  bad = r;
  bad.contact_time = std::numeric_limits<double>::infinity();
  CHECK_THAT(ReuseProblem(bad), Catch::Equals("contact_time is inf"));
  bad = r;
  bad.t_peak = {0.1, std::nan("")};
  CHECK_THAT(ReuseProblem(bad), Catch::Equals("t_peak[1] is nan"));
  bad = r;
  bad.calibrations.push_back({});
  bad.calibrations[0].cell = "right";
  bad.calibrations[0].points_x = {0.0, std::nan("")};
  bad.calibrations[0].points_volts = {1.0, 2.0};
  CHECK_THAT(ReuseProblem(bad), Catch::Equals("calibration/right/points_x[1] is nan"));
  bad = r;
  bad.measured_displacement.time_s = {0.0, 1.0};
  bad.measured_displacement.value = {0.0};
  CHECK_THAT(ReuseProblem(bad), Catch::Contains("displacement/time has 2 values"));
  bad = r;
  bad.right = BarRebounds{{0}, {0.3}, {std::nan("")}, {0.1}, {0.0}, {0.5}, {0.0}, {}, {}, {}};
  CHECK_THAT(ReuseProblem(bad), Catch::Equals("rebounds/right/xmax_std_error[0] is nan"));
}

TEST_CASE("reuse: a truncated or garbage previous file is refused with its name") {
  testing::TempDir dir;
  const Session session = TwoRunSession(dir.path());
  const SessionResult first = ReduceSession(session, {});
  const auto file = dir.path() / "out.h5";
  WriteResults(first, file);
  const auto size = std::filesystem::file_size(file);
  const auto truncated = dir.path() / "truncated.h5";
  std::filesystem::copy_file(file, truncated);
  std::filesystem::resize_file(truncated, size / 2);
  CHECK_THROWS_WITH(ReadResults(truncated), Catch::Contains("truncated.h5"));
  const auto garbage = dir.path() / "garbage.h5";
  std::ofstream(garbage) << "not an HDF5 file at all\n";
  CHECK_THROWS_WITH(ReadResults(garbage), Catch::Contains("garbage.h5"));
}

TEST_CASE("calibration cache: a calibration's cost is charged once, to the first run that asks") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  const Session session = ReadManifest(dir.path()).session;
  const Pendulum pendulum{session.apparatus->pendulum_length, session.apparatus->gravity,
                          PendulumConvention::kExact};
  CalibrationCache cache(session, pendulum, [](const Calibration&) { return StageOptions{}; });
  // Computed ahead of the runs, as reduce does: nobody charged yet.
  const CalibratedCell& ahead = cache.Get("R");
  CHECK(ahead.cost.calibrate > 0.0);
  StageSeconds first, second;
  const CalibratedCell& asked = cache.Get("R", &first);
  cache.Get("R", &second);
  CHECK(&asked == &ahead);  // computed once
  CHECK(first.calibrate == ahead.cost.calibrate);
  CHECK(first.load == ahead.cost.load);
  CHECK(second.calibrate == 0.0);
  CHECK(second.load == 0.0);
  CHECK(ahead.ok);
  CHECK(ahead.Failure().empty());
  // A calibration the manifest does not have is a cell that is not ok, said
  // with the manifest and the key, not an exception.
  const CalibratedCell& missing = cache.Get("no such", &second);
  CHECK_FALSE(missing.ok);
  CHECK(missing.failed_at.file == session.manifest);
  CHECK(missing.failed_at.key == "calibration \"no such\"");
  CHECK(missing.reason == "no such calibration");
  CHECK(missing.Failure() ==
        session.manifest.string() + ": calibration \"no such\": no such calibration");
}

// The session's pendulum, as reduce makes it.
Pendulum PendulumOf(const Session& session) {
  return {session.apparatus->pendulum_length, session.apparatus->gravity,
          PendulumConvention::kExact};
}

TEST_CASE("calibration cache: a trace that does not calibrate is a cell with its file and reason") {
  // The left cell folds over (not monotone) within the swing.
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  WriteLeftCellFoldingOver(dir.path());
  const Session session = ReadManifest(dir.path()).session;
  const Pendulum pendulum = PendulumOf(session);  // the cache holds it by reference
  CalibrationCache cache(session, pendulum, [](const Calibration&) { return StageOptions{}; });
  const CalibratedCell* left = nullptr;
  CHECK_NOTHROW(left = &cache.Get("L"));
  REQUIRE(left != nullptr);
  CHECK_FALSE(left->ok);
  CHECK(left->failed_at.file.filename() == "L.csv");
  CHECK(left->failed_at.key == "calibration \"L\"");
  CHECK_THAT(left->reason, Catch::Contains("not monotone"));
  CHECK(cache.Get("R").ok);
}

// The session's first run measured alone, with stage defaults.
MeasuredTraceRun MeasureFirstRun(const Session& session) {
  const Pendulum pendulum = PendulumOf(session);  // the cache holds it by reference
  CalibrationCache cache(session, pendulum, [](const Calibration&) { return StageOptions{}; });
  return MeasureTraceRun(session.runs[0], session, pendulum, StageOptions{}, cache);
}

TEST_CASE(
    "measure: a run that cannot be measured is a result naming the trace, with what was "
    "measured before") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  // Recalibrated from a smaller swing: the right trace's larger displacements fall outside.
  const Session session = WithCellCalibratedAt(dir.path(), "R", 0.2, 0.0);
  MeasuredTraceRun measured;
  CHECK_NOTHROW(measured = MeasureFirstRun(session));
  CHECK_FALSE(measured.ok);
  CHECK(measured.failed_at.file.filename() == "run-right.csv");
  CHECK(measured.failed_at.key == "run \"run\".traces.right");
  CHECK_THAT(measured.reason, Catch::Contains("does not cover"));
  CHECK(measured.Failure() == FormatLocation(measured.failed_at) + ": " + measured.reason);
  // The right cell's calibration was made before the conversion stopped the run.
  REQUIRE(measured.measured.calibrations.size() == 1);
  CHECK(measured.measured.calibrations[0].calibration_id == "R");
  CHECK_FALSE(measured.measured.right.has_value());
}

TEST_CASE("measure: a trace file that cannot be read when measured fails the run, naming it") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  const Session session = ReadManifest(dir.path()).session;
  // Gone between the manifest's reading and the measurement.
  std::filesystem::remove(dir.path() / "traces" / "run-left.csv");
  MeasuredTraceRun measured;
  CHECK_NOTHROW(measured = MeasureFirstRun(session));
  CHECK_FALSE(measured.ok);
  CHECK(measured.failed_at.file.filename() == "run-left.csv");
  // Both calibrations were made, and the right bar converted, before the left trace was read.
  CHECK(measured.measured.calibrations.size() == 2);
}

TEST_CASE("parallel: two jobs give exactly the results of one") {
  testing::TempDir dir;
  const Session session = TwoRunSession(dir.path());
  ReduceOptions two;
  two.jobs = 2;
  std::vector<ReduceProgress> reports;
  two.on_progress = [&](const ReduceProgress& p) { reports.push_back(p); };
  const SessionResult serial = ReduceSession(session, {});
  const SessionResult parallel = ReduceSession(session, two);
  // Each calibration and each run once, counted up to the total.
  REQUIRE(reports.size() == session.calibrations.size() + 2);
  for (std::size_t k = 0; k < reports.size(); ++k) {
    CHECK(reports[k].done == k + 1);
    CHECK(reports[k].total == reports.size());
  }
  CHECK(std::count_if(reports.begin(), reports.end(),
                      [](const ReduceProgress& p) { return p.item.rfind("run ", 0) == 0; }) == 2);
  for (std::size_t i = 0; i < serial.runs.size(); ++i) {
    CHECK(parallel.runs[i].id == serial.runs[i].id);
    CHECK(parallel.runs[i].measured.xmax == serial.runs[i].measured.xmax);
  }
}

TEST_CASE("products: --only calibration and --only rebounds stop where asked") {
  testing::TempDir dir;
  const Session session = TwoRunSession(dir.path());
  ReduceOptions calibration_only;
  calibration_only.products = Products::kCalibration;
  const SessionResult c = ReduceSession(session, calibration_only);
  CHECK(c.runs.empty());
  REQUIRE(c.calibrations.size() == 2);
  CHECK(c.calibrations[0].residual_rms_volts < 0.01);
  ReduceOptions rebounds_only;
  rebounds_only.products = Products::kRebounds;
  const SessionResult r = ReduceSession(session, rebounds_only);
  REQUIRE(r.runs.size() == 2);
  CHECK(r.runs[0].ok);
  CHECK_FALSE(r.runs[0].fits.kelvin_voigt.has_value());
  CHECK_FALSE(r.kelvin_voigt.has_value());
}

}  // namespace
}  // namespace impactlab

namespace impactlab {

TEST_CASE("trace_session: each peak time carries its standard error, into the file and back") {
  testing::TempDir dir;
  const Written w = WriteSession(dir.path(), 0.6, 0.002);
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE(result.runs.size() == 1);
  const RunResult& run = result.runs[0];
  REQUIRE(run.ok);
  REQUIRE(run.measured.t_peak_sigma.size() == run.measured.t_peak.size());
  for (std::size_t n = 0; n < run.measured.t_peak.size(); ++n) {
    INFO("rebound " << n);
    CHECK(run.measured.t_peak_sigma[n] > 0.0);
    CHECK(std::abs(run.measured.t_peak[n] - w.truth.peak_time[n + 1]) <
          5.0 * run.measured.t_peak_sigma[n]);
  }
  WriteResults(result, dir.path() / "r.h5");
  const SessionResult back = ReadResults(dir.path() / "r.h5");
  REQUIRE(back.runs.size() == 1);
  CHECK(back.runs[0].measured.t_peak_sigma == run.measured.t_peak_sigma);
}

TEST_CASE("trace runs: bars drawn in alternate slots too long to bridge give the bars' mean") {
  // A chopper whose slots are 0.2 s long (0.4 division at 0.5 s/div): each
  // bar is drawn in its half, so each has 0.1 s gaps, more than the 0.075 s
  // (a tenth of a half swing) the average bridges. No time is readable on
  // both bars, and the maxima come from each bar's own peak fits.
  testing::TempDir dir;
  const Written w = WriteSession(dir.path(), 0.6, 0.0);
  for (const auto& [name, phase] :
       {std::pair{"run-right.csv", 0.0}, std::pair{"run-left.csv", 0.1}}) {
    const Trace full = ReadTraceCsv(dir.path() / "traces" / name);
    Trace chopped;
    for (std::size_t i = 0; i < full.time_s.size(); ++i) {
      if (std::fmod(full.time_s[i] + phase, 0.2) >= 0.1) continue;
      chopped.time_s.push_back(full.time_s[i]);
      chopped.volts.push_back(full.volts[i]);
    }
    WriteTraceCsv(dir.path() / "traces" / name, chopped);
  }
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  REQUIRE(result.runs.size() == 1);
  const RunResult& run = result.runs[0];
  INFO(run.Status());
  REQUIRE(run.ok);
  REQUIRE(run.measured.xmax.size() >= 2);
  for (std::size_t n = 0; n < run.measured.xmax.size(); ++n) {
    INFO("rebound " << n);
    CHECK(run.measured.xmax[n] == Approx(w.truth.xmax[n + 1]).epsilon(1e-5));
  }
}

}  // namespace impactlab
