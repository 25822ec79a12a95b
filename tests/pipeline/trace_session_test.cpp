// A session whose runs come as CSV traces (digital scope), made from the
// model with known photocell curves: reduce recovers the maxima, the contact
// time and the Kelvin-Voigt parameters.
#include <cmath>
#include <fstream>
#include <random>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "io/manifest.h"
#include "io/trace.h"
#include "model/kelvin_voigt.h"
#include "model/rebound_history.h"
#include "pipeline/reduce.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

constexpr double kG = 385.644, kL = 22.0, kK = 462000.0, kC = 9.0;
const double kMass = 2.23 / kG;
const Pendulum kPendulum{kL, kG, PendulumConvention::kExact};

double RightCell(double x) { return 2.4 - 3.1 * x + 0.9 * x * x; }  // falls with X (x < 1.5)
double LeftCell(double x) { return 0.2 + 2.2 * x - 0.35 * x * x; }   // inverted amplifier

struct Written {
  ReboundSequence truth;
};

void WriteCsv(const std::filesystem::path& path, const std::vector<double>& t,
              const std::vector<double>& v) {
  Trace trace;
  trace.time_s = t;
  trace.volts = v;
  WriteTraceCsv(path, trace);
}

// The calibration sweep of one cell and the run's three traces.
Written WriteSession(const std::filesystem::path& dir, double x0, double noise_volts) {
  std::filesystem::create_directories(dir / "traces");
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, noise_volts);
  const double quarter = 0.5 * HalfPeriod(kPendulum, x0);
  using Cell = double (*)(double);
  for (const auto& [name, cell] : {std::pair<const char*, Cell>{"R", RightCell}, std::pair<const char*, Cell>{"L", LeftCell}}) {
    std::vector<double> t, v;
    for (double s = -0.01; s <= 1.05 * quarter; s += 2e-4) {
      const double x = s < 0 ? x0 : ReleaseSwingDisplacement(kPendulum, x0, std::min(s, quarter));
      t.push_back(s);
      v.push_back(cell(std::max(x, 0.0)) + noise(rng));
    }
    WriteCsv(dir / "traces" / (std::string(name) + ".csv"), t, v);
  }
  const KelvinVoigtContactLaw law({kMass, kK, kC}, Separation::kKinematic);
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
  std::ofstream(dir / "session.toml") << fmt::format(R"(format = 1
title = "CSV traces from the model"
[apparatus]
pendulum_length = {}
weight = 2.23
[[calibration]]
id = "R"
cell = "right"
initial_displacement = {}
[calibration.trace]
csv = "traces/R.csv"
[[calibration]]
id = "L"
cell = "left"
initial_displacement = {}
[calibration.trace]
csv = "traces/L.csv"
[[run]]
id = "run"
initial_displacement = {}
calibration = {{ right = "R", left = "L" }}
fit_rebounds = [0, 2]
[run.traces.right]
csv = "traces/run-right.csv"
[run.traces.left]
csv = "traces/run-left.csv"
[run.traces.contact]
csv = "traces/run-contact.csv"
impact = 2
)",
                                                     kL, x0, x0, x0);
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
  CHECK(run.source == "csv");
  REQUIRE(run.xmax.size() >= 4);
  for (std::size_t n = 0; n < run.xmax.size(); ++n) {
    // Session rebound n is PENDUL rebound n + 1 (first_rebound = 1).
    CHECK(run.xmax[n] == Approx(w.truth.xmax[n + 1]).epsilon(1e-6));
    CHECK(run.t_peak[n] == Approx(w.truth.peak_time[n + 1]).margin(1e-5));
  }
  CHECK(run.contact_time_source == "contact trace");
  CHECK(*run.contact_time == Approx(w.truth.contact.contact_time).margin(1e-6));
  CHECK(run.kelvin_voigt->stiffness->value == Approx(kK).epsilon(1e-2));
  CHECK(run.kelvin_voigt->damping->value == Approx(kC).epsilon(2e-2));
  REQUIRE(run.calibrations.size() == 2);
  CHECK(run.calibrations[0].residual_rms_volts < 1e-6);
}

TEST_CASE("trace_session: with noisy traces the maxima stay within their reported uncertainty") {
  testing::TempDir dir;
  const Written w = WriteSession(dir.path(), 0.405, 0.005);
  const SessionResult result = ReduceSession(ReadManifest(dir.path()).session, {});
  const RunResult& run = result.runs[0];
  INFO(run.Status());
  REQUIRE(run.ok);
  for (std::size_t n = 0; n < run.xmax.size(); ++n) {
    INFO("rebound " << n);
    CHECK(run.xmax_sigma[n] > 0.0);
    CHECK(std::abs(run.xmax[n] - w.truth.xmax[n + 1]) < 5.0 * run.xmax_sigma[n]);
    CHECK(std::abs(run.xmax[n] - w.truth.xmax[n + 1]) < 5e-4 * 0.405);  // 0.05 % of X0
  }
}

TEST_CASE("trace_session: a missing trace file fails that run with the file named") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  std::filesystem::remove(dir.path() / "traces" / "L.csv");
  CHECK_THROWS_WITH(ReadManifest(dir.path()), Catch::Contains("L.csv"));
}

TEST_CASE("trace_session: a calibration that does not cover the run is refused") {
  testing::TempDir dir;
  WriteSession(dir.path(), 0.6, 0.0);
  // Recalibrate from a smaller swing: the run's larger displacements fall outside.
  WriteSession(dir.path() / "small", 0.2, 0.0);
  std::filesystem::copy_file(dir.path() / "small" / "traces" / "R.csv",
                             dir.path() / "traces" / "R.csv",
                             std::filesystem::copy_options::overwrite_existing);
  Session session = ReadManifest(dir.path()).session;
  session.calibrations[0].initial_displacement = 0.2;
  const SessionResult result = ReduceSession(session, {});
  CHECK_FALSE(result.runs[0].ok);
  CHECK_THAT(result.runs[0].failure, Catch::Contains("does not cover"));
}

}  // namespace
}  // namespace impactlab
