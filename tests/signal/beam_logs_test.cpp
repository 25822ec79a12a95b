// Tests of the flexible-arm log generator (synth/beam_logs.h): its modes against
// the closed form of the one-term Ritz beam, its kinematics, determinism and the
// session it writes.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "io/errors.h"
#include "io/manifest.h"
#include "synth/beam_logs.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST_CASE("With the hub locked, the pinned beam's mode is the one-term Ritz value", "[beam_logs]") {
  // A huge hub holds theta, so the wall holds q2 = 0 and only phi3 moves:
  // K33 = 4 EI / L, M33 = rho L^3 / 105 (tip inertia 0), omega^2 = 420 EI / (rho L^4).
  BeamArm arm;
  arm.hub_inertia_kg_m2 = 1e9;
  arm.tip_inertia_kg_m2 = 0.0;
  arm.beam_damping_n_s_per_m2 = 0.0;
  arm.motor_torque_n_m = 2e9;  // the huge hub still has to reach the wall
  arm.hub_damping_n_m_s = 1e9;
  const BeamRecord record = SimulateBeam(arm, {}, 1000.0, 3.0);
  const double omega = std::sqrt(420.0 * arm.flexural_rigidity_n_m2 /
                                 (arm.mass_per_length_kg_per_m * std::pow(arm.length_m, 4)));
  bool found = false;
  for (const BeamPole& mode : record.post_modes) {
    if (std::abs(mode.natural_frequency_hz * 2.0 * std::numbers::pi / omega - 1.0) < 1e-6) {
      found = true;
      CHECK(std::abs(mode.damping_ratio) < 1e-6);
    }
  }
  CHECK(found);
}

TEST_CASE("The tip meets the wall at the motor's steady speed", "[beam_logs]") {
  BeamArm arm;
  arm.wall_angle_rad = arm.start_angle_rad + 1.5;  // long enough to settle
  const BeamRecord record = SimulateBeam(arm, {}, 1000.0, 5.0);
  const double steady_tip_speed = arm.length_m * arm.motor_torque_n_m / arm.hub_damping_n_m_s;
  CHECK(record.impact_speed_m_s == Approx(steady_tip_speed).epsilon(0.03));
  // The encoder angle reaches the wall angle at the impact.
  const auto at = static_cast<std::size_t>(std::ceil(record.impact_time_s * 1000.0));
  CHECK(record.angle_rad[at] == Approx(arm.wall_angle_rad).margin(2e-3));
  CHECK(record.min_contact_force_n > 0.0);  // the motor keeps the tip on the wall
  CHECK_THROWS_AS(SimulateBeam(arm, {}, 1000.0, 0.5), std::invalid_argument);
}

TEST_CASE("The session follows session-format.md and the same seed writes the same bytes",
          "[beam_logs]") {
  TempDir dir;
  BeamLogOptions options;
  options.seed = 7;
  options.duration_s = 3.0;
  const BeamLogSummary a = GenerateBeamLogs(dir.path() / "a", options);
  GenerateBeamLogs(dir.path() / "b", options);
  BeamLogOptions other = options;
  other.seed = 8;
  GenerateBeamLogs(dir.path() / "c", other);
  const fs::path file = "logs/case1-experiment.csv";
  CHECK(Slurp(dir.path() / "a" / file) == Slurp(dir.path() / "b" / file));
  CHECK(Slurp(dir.path() / "a" / file) != Slurp(dir.path() / "c" / file));
  CHECK(a.rows == 3000);

  const ManifestReadResult manifest = ReadManifest(dir.path() / "a");
  CHECK(manifest.warnings.empty());
  REQUIRE(manifest.session.logs.size() == 1);
  const Log& log = manifest.session.logs[0];
  CHECK(log.id == "case1");
  REQUIRE(log.simulation);
  REQUIRE(log.channels.size() == 3);
  CHECK(log.channels[0].name == "q1");
  CHECK(log.channels[0].counts_per_rev == 4096.0);
  CHECK(log.channels[0].gear_ratio == 50.0);
  CHECK(log.channels[1].sensitivity == 0.1);
  CHECK(a.truth["schema"] == "impactlab-logs-truth");
  CHECK(a.truth["impact_offset_s"].get<double>() ==
        Approx(a.simulation_impact_s - a.experiment_impact_s));

  CHECK_THROWS_AS(GenerateBeamLogs(dir.path() / "a", options), InputError);
  other.sample_rate_hz = 1.0;
  CHECK_THROWS_AS(GenerateBeamLogs(dir.path() / "d", other), std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
