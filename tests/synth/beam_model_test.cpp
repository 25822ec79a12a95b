// The flexible arm's equations (synth/beam_model_internal.h): the structure
// Lagrange's equations must have, whatever the quadrature's rounding.
#include <cmath>
#include <complex>
#include <numbers>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include "synth/beam_model_internal.h"

namespace impactlab {
namespace {

using namespace beam_internal;

TEST_CASE(
    "synth: the arm's mass matrix is symmetric positive definite, its stiffness spares the hub") {
  const BeamArm arm;
  const LinearEquations<3> free = FreeFlightEquations(arm);
  CHECK((free.mass - free.mass.transpose()).norm() <= 1e-15 * free.mass.norm());
  CHECK(free.mass.llt().info() == Eigen::Success);
  // The rigid rotation stores no strain energy and meets only the hub's damping.
  CHECK(free.stiffness.row(0).isZero(0.0));
  CHECK(free.stiffness.col(0).isZero(0.0));
  CHECK(free.damping(0, 0) == arm.hub_damping_n_m_s);
  CHECK(free.damping.row(0).tail<2>().isZero(0.0));
  // The beam alone about the hub: rho L^3 / 3, plus the tip's m_t L^2 + J_t.
  const double l = arm.length_m;
  CHECK(free.mass(0, 0) ==
        Approx(arm.hub_inertia_kg_m2 + arm.mass_per_length_kg_per_m * l * l * l / 3.0 +
               arm.tip_mass_kg * l * l + arm.tip_inertia_kg_m2)
            .epsilon(1e-14));
  // One-term Ritz stiffness of a clamped beam's tip slope: K33 = 4 EI / L.
  CHECK(free.stiffness(2, 2) == Approx(4.0 * arm.flexural_rigidity_n_m2 / l).epsilon(1e-14));
}

TEST_CASE("synth: on the wall the tip does not move, and the motor still pushes") {
  const BeamArm arm;
  const Eigen::Matrix<double, 3, 2> basis = OnTheWallBasis(arm.length_m);
  // Every motion the basis allows keeps the tip where it is: G T = 0.
  CHECK((TipTravelRow(arm.length_m) * basis).isZero(1e-15));
  const LinearEquations<2> pinned = OnTheWallEquations(FreeFlightEquations(arm), arm.length_m);
  CHECK(pinned.mass.llt().info() == Eigen::Success);
  CHECK(pinned.force[0] == Approx(-arm.motor_torque_n_m / arm.length_m));
  CHECK(pinned.force[1] == 0.0);
}

TEST_CASE("synth: the free flight's poles: the rigid rotation's decay and two damped modes") {
  const BeamArm arm;
  const LinearEquations<3> free = FreeFlightEquations(arm);
  const std::vector<BeamPole> poles = Poles(free.mass, free.damping, free.stiffness);
  // Six roots: 0 (the rotation's position, no mode), a real decay and two pairs.
  REQUIRE(poles.size() == 3);
  CHECK(poles[0].frequency_hz == 0.0);
  CHECK(poles[0].damping_ratio == 1.0);
  CHECK(poles[1].frequency_hz > 0.0);
  CHECK(poles[2].frequency_hz > poles[1].frequency_hz);
  for (const BeamPole& pole : poles) {
    // Each pole is a root: det(M s^2 + C s + K) vanishes there, relative to its size.
    const std::complex<double> s(-pole.decay_rate_per_s,
                                 2.0 * std::numbers::pi * pole.frequency_hz);
    const Eigen::Matrix3cd at_s = free.mass.cast<std::complex<double>>() * s * s +
                                  free.damping.cast<std::complex<double>>() * s +
                                  free.stiffness.cast<std::complex<double>>();
    const double size = (free.mass.norm() * std::norm(s) + free.damping.norm() * std::abs(s) +
                         free.stiffness.norm());
    CHECK(std::abs(at_s.determinant()) <= 1e-9 * size * size * size);
  }
}

}  // namespace
}  // namespace impactlab
