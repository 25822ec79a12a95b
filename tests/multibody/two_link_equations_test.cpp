// The two-link arm's equations of motion against an independent Lagrangian
// (two_link_reference.h): mass matrix, velocity-product forces, stiffness,
// damping, energies, the contact tip, the accelerometers and the drive law.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include "multibody/two_link_model.h"
#include "multibody/two_link_modes.h"
#include "tests/multibody/two_link_reference.h"

namespace impactlab {
namespace {

using testing::Vec8;

// Random states: angles anywhere, deflections of a few cm and rotations of a
// few hundredths of a radian, rates of a few rad/s.
struct RandomState {
  Vec8 q, v;
};
std::vector<RandomState> RandomStates(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Vec8 q_scale = (Vec8() << 3.0, 0.05, 0.05, 3.0, 0.05, 0.05, 3.0, 3.0).finished();
  const Vec8 v_scale = (Vec8() << 4.0, 0.5, 1.0, 6.0, 0.5, 1.0, 5.0, 5.0).finished();
  std::vector<RandomState> out;
  for (int n = 0; n < count; ++n) {
    RandomState s;
    for (int i = 0; i < 8; ++i) {
      s.q(i) = q_scale(i) * unit(rng);
      s.v(i) = v_scale(i) * unit(rng);
    }
    out.push_back(s);
  }
  return out;
}

// Nominal parameters, and a variant with every geometric offset non-zero
// (the tip off the beam's axis) and unequal beams.
std::vector<TwoLinkParameters> ParameterSets() {
  TwoLinkParameters a = TwoLinkParameters::Nominal();
  TwoLinkParameters b = a;
  b.beam1 = {0.62, 0.07, 0.41, 5.5, 0.03};
  b.beam2 = {0.44, 0.03, 0.27, 2.1, 0.08};
  b.body2 = {1.7, 4.0e-3};
  b.hub3 = {0.3, 5.0e-4};
  b.hub1 = {0.4, 3.0e-3};
  b.tool = {{0.6, 1.1e-3}, 0.035, 0.025, -0.015};
  b.drive_a.equivalent_inertia_kg_m2 = 0.021;
  b.drive_b.equivalent_inertia_kg_m2 = 0.013;
  return {a, b};
}

double MaxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

TEST_CASE("two-link: Kane's mass matrix and velocity forces equal Lagrange's from the geometry") {
  int set_index = 0;
  double worst_mass = 0.0, worst_forces = 0.0;
  for (const TwoLinkParameters& p : ParameterSets()) {
    const TwoLinkModel model(p);
    for (const RandomState& s : RandomStates(6, 11 + set_index)) {
      INFO("parameter set " << set_index << ", q = " << s.q.transpose()
                            << ", v = " << s.v.transpose());
      TwoLinkMatrix mass;
      TwoLinkVector forces;
      model.Inertia(s.q, s.v, &mass, &forces);
      const testing::LagrangeReference ref = testing::Lagrange(p, s.q, s.v);
      const double mass_error = MaxAbs(mass - ref.mass) / MaxAbs(ref.mass);
      const double force_error = (forces - ref.velocity_forces).norm() / ref.velocity_forces.norm();
      INFO("mass matrix rel err " << mass_error << ", h rel err " << force_error);
      CHECK(mass_error <= 1e-10);
      CHECK(force_error <= 1e-10);
      worst_mass = std::max(worst_mass, mass_error);
      worst_forces = std::max(worst_forces, force_error);
      // Element by element, relative to each row's scale (the small entries too).
      for (int i = 0; i < 8; ++i) {
        const double row_scale = ref.mass.row(i).cwiseAbs().maxCoeff();
        CHECK(MaxAbs(mass.row(i) - ref.mass.row(i)) <= 1e-12 * row_scale);
      }
      CHECK(mass.isApprox(mass.transpose(), 0.0));
      // Kinetic energy 1/2 v^T M v.
      CHECK(model.KineticEnergy(s.q, s.v) == Approx(0.5 * s.v.dot(ref.mass * s.v)).epsilon(1e-12));
    }
    ++set_index;
  }
  WARN("Lagrange check: worst relative error of M " << worst_mass << ", of h " << worst_forces
                                                    << " (12 random states, 2 parameter sets)");
}

TEST_CASE("two-link: at rest the velocity forces vanish and they are quadratic in the rates") {
  const TwoLinkParameters p = TwoLinkParameters::Nominal();
  const TwoLinkModel model(p);
  for (const RandomState& s : RandomStates(3, 5)) {
    TwoLinkMatrix mass;
    TwoLinkVector h0, h1, h3;
    model.Inertia(s.q, TwoLinkVector::Zero(), &mass, &h0);
    CHECK(h0.norm() == 0.0);
    model.Inertia(s.q, s.v, &mass, &h1);
    model.Inertia(s.q, 3.0 * s.v, &mass, &h3);
    CHECK((h3 - 9.0 * h1).norm() <= 1e-13 * h3.norm());
    // Power balance: v . h = 1/2 v^T (dM/dt) v, dM/dt from the reference by
    // central differences along v.
    const double dt = 1e-6;
    const Vec8 qp = s.q + dt * s.v, qm = s.q - dt * s.v;
    const Eigen::Matrix<double, 8, 8> mdot =
        (testing::Lagrange(p, qp, s.v).mass - testing::Lagrange(p, qm, s.v).mass) / (2.0 * dt);
    CHECK(s.v.dot(h1) == Approx(0.5 * s.v.dot(mdot * s.v)).epsilon(1e-7));
  }
}

TEST_CASE("two-link: beam stiffness and damping are the cantilever's closed forms") {
  for (const TwoLinkParameters& p : ParameterSets()) {
    const TwoLinkModel model(p);
    TwoLinkMatrix expected = TwoLinkMatrix::Zero();
    expected.block<2, 2>(kBeam1Deflection, kBeam1Deflection) =
        testing::CantileverStiffness(p.beam1);
    expected.block<2, 2>(kBeam2Deflection, kBeam2Deflection) =
        testing::CantileverStiffness(p.beam2);
    CHECK(MaxAbs(model.stiffness() - expected) <= 1e-13 * MaxAbs(expected));
    // Damping c int phi_i phi_j: c [[13 L/35, -11 L^2/210], [-11 L^2/210, L^3/105]].
    TwoLinkMatrix damping = TwoLinkMatrix::Zero();
    for (const auto& [beam, first] : {std::pair{p.beam1, 1}, std::pair{p.beam2, 4}}) {
      const double l = beam.length_m, c = beam.damping_n_s_per_m2;
      damping.block<2, 2>(first, first) << 13.0 * l / 35.0, -11.0 * l * l / 210.0,
          -11.0 * l * l / 210.0, l * l * l / 105.0;
      damping.block<2, 2>(first, first) *= c;
    }
    CHECK(MaxAbs(model.beam_damping() - damping) <= 1e-13 * MaxAbs(damping));
  }
}

TEST_CASE("two-link: potential energy is the beams' strain and the meshes' twist beyond the play") {
  TwoLinkParameters p = TwoLinkParameters::Nominal();
  p.drive_a.backlash_rad = 0.004;
  p.drive_b.backlash_rad = 0.01;
  const TwoLinkModel model(p);
  for (const RandomState& s : RandomStates(4, 17)) {
    Vec8 q = s.q;
    for (double twist_a : {-0.01, -0.001, 0.0015, 0.02}) {
      for (double twist_b : {-0.02, 0.004, 0.0051}) {
        q(kGearboxAAngle) = q(kLink1Angle) + twist_a;
        q(kGearboxBAngle) = q(kLink2Angle) + twist_b;
        CHECK(model.PotentialEnergy(q) == Approx(testing::PotentialReference(p, q)).epsilon(1e-13));
      }
    }
  }
}

TEST_CASE("two-link: contact tip, gap and accelerometers follow the arm's geometry") {
  int set_index = 0;
  for (const TwoLinkParameters& p : ParameterSets()) {
    const TwoLinkModel model(p);
    for (const RandomState& s : RandomStates(4, 23 + set_index)) {
      INFO("parameter set " << set_index << ", q = " << s.q.transpose());
      const std::array<testing::Jet2, 8> q = testing::Seed(s.q);
      const testing::Arm<testing::Jet2> arm{p, q};
      auto compare = [&](const PointMotion& got, const testing::P2<testing::Jet2>& point) {
        const testing::PointReference ref = testing::PointOf(point, s.v);
        CHECK((got.position - ref.position).norm() <= 1e-14 * (1.0 + ref.position.norm()));
        CHECK(MaxAbs(got.jacobian - ref.jacobian) <= 1e-14 * (1.0 + MaxAbs(ref.jacobian)));
        CHECK((got.velocity_product - ref.velocity_product).norm() <=
              1e-12 * (1.0 + ref.velocity_product.norm()));
      };
      compare(model.Tip(s.q, s.v), arm.Tip());
      CHECK(model.Gap(s.q) == Approx(arm.Tip().x.a.a + p.surface.distance_m).margin(1e-14));
      compare(model.Sensor(TwoLinkSensor::kBeam1Middle, s.q, s.v),
              arm.Beam1(0.5 * p.beam1.length_m));
      compare(model.Sensor(TwoLinkSensor::kBody2, s.q, s.v), arm.JointB());
      compare(model.Sensor(TwoLinkSensor::kBeam2Middle, s.q, s.v),
              arm.Beam2(0.5 * p.beam2.length_m));
      compare(model.Sensor(TwoLinkSensor::kTool, s.q, s.v), arm.ToolCentre());
      // The sensing axes: each body's transverse axis.
      const double quarter = 0.5 * std::numbers::pi;
      CHECK(model.SensorAxisAngle(TwoLinkSensor::kBeam1Middle, s.q) ==
            Approx(s.q(0) + quarter).margin(1e-14));
      CHECK(model.SensorAxisAngle(TwoLinkSensor::kBody2, s.q) ==
            Approx(s.q(0) + s.q(2) + quarter).margin(1e-14));
      CHECK(model.SensorAxisAngle(TwoLinkSensor::kBeam2Middle, s.q) ==
            Approx(s.q(0) + s.q(2) + s.q(3) + quarter).margin(1e-14));
      CHECK(model.SensorAxisAngle(TwoLinkSensor::kTool, s.q) ==
            Approx(s.q(0) + s.q(2) + s.q(3) + s.q(5) + quarter).margin(1e-14));
    }
    ++set_index;
  }
}

TEST_CASE("two-link: applied forces are minus the potential's gradient plus the drives' eq. 27") {
  TwoLinkParameters p = TwoLinkParameters::Nominal();
  p.drive_a.backlash_rad = 0.004;
  p.drive_b.backlash_rad = 0.006;
  const TwoLinkModel model(p);
  const DriveVoltages volts{1.3, -2.1};
  for (const RandomState& s : RandomStates(3, 29)) {
    Vec8 q = s.q;
    // Both meshes engaged well past the damping's build-up (1e-4 rad).
    q(kGearboxAAngle) = q(kLink1Angle) + 0.0035;
    q(kGearboxBAngle) = q(kLink2Angle) - 0.0072;
    // The conservative part: -dV/dq by central differences of the reference.
    Vec8 gradient;
    for (int i = 0; i < 8; ++i) {
      const double h = 1e-7;
      Vec8 up = q, down = q;
      up(i) += h;
      down(i) -= h;
      gradient(i) =
          (testing::PotentialReference(p, up) - testing::PotentialReference(p, down)) / (2.0 * h);
    }
    Vec8 expected = -gradient;
    // Beam damping c int phi phi (checked above) on the rates.
    expected -= model.beam_damping() * s.v;
    auto drive = [&](const TwoLinkDrive& d, int gearbox, int joint, double voltage) {
      const double n = d.gear_ratio, kt = d.torque_constant_n_m_per_a;
      const double kb = d.back_emf_v_s_per_rad, r = d.armature_resistance_ohm;
      const double relative = s.v(gearbox) - s.v(joint);
      expected(gearbox) += n * kt * voltage / r - n * n * kt * kb * s.v(gearbox) / r -
                           d.equivalent_damping_n_m_s * s.v(gearbox) -
                           d.mesh_damping_n_m_s * relative;
      expected(joint) += d.mesh_damping_n_m_s * relative;
    };
    drive(p.drive_a, kGearboxAAngle, kLink1Angle, volts.a_v);
    drive(p.drive_b, kGearboxBAngle, kLink2Angle, volts.b_v);
    const Vec8 got = model.AppliedForces(q, s.v, volts);
    CHECK((got - expected).norm() <= 1e-6 * expected.norm());
    // Inside the dead band the meshes transmit nothing.
    q(kGearboxAAngle) = q(kLink1Angle) + 0.001;
    q(kGearboxBAngle) = q(kLink2Angle) - 0.002;
    const Vec8 free = model.AppliedForces(q, s.v, volts);
    CHECK(free(kLink1Angle) == Approx(0.0).margin(1e-12));
    CHECK(free(kLink2Angle) == Approx(0.0).margin(1e-12));
  }
}

// det(A) by Gaussian elimination with partial pivoting.
double Determinant(Eigen::Matrix<double, 8, 8> a) {
  double det = 1.0;
  for (int col = 0; col < 8; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 8; ++r) {
      if (std::abs(a(r, col)) > std::abs(a(pivot, col))) pivot = r;
    }
    if (pivot != col) {
      a.row(col).swap(a.row(pivot));
      det = -det;
    }
    det *= a(col, col);
    for (int r = col + 1; r < 8; ++r) {
      const double f = a(r, col) / a(col, col);
      for (int c = col; c < 8; ++c) a(r, c) -= f * a(col, c);
    }
  }
  return det;
}

TEST_CASE("two-link: free vibration frequencies at rest solve det(K - w^2 M) = 0") {
  // Undamped, motors off: the linearised modes at rest are the generalized
  // eigenvalues of the stiffness (beams' closed form, meshes' k_g) and the
  // reference mass matrix.
  const TwoLinkParameters p = testing::ConservativeParameters();
  const TwoLinkModel model(p);
  Vec8 q;
  q << 0.9, 0.0, 0.0, 0.5, 0.0, 0.0, 0.9, 0.5;
  const Eigen::Matrix<double, 8, 8> mass = testing::Lagrange(p, q, Vec8::Zero()).mass;
  Eigen::Matrix<double, 8, 8> stiffness = Eigen::Matrix<double, 8, 8>::Zero();
  stiffness.block<2, 2>(1, 1) = testing::CantileverStiffness(p.beam1);
  stiffness.block<2, 2>(4, 4) = testing::CantileverStiffness(p.beam2);
  for (const auto& [k, joint, gearbox] : {std::tuple{p.drive_a.mesh_stiffness_n_m_per_rad, 0, 6},
                                          std::tuple{p.drive_b.mesh_stiffness_n_m_per_rad, 3, 7}}) {
    stiffness(joint, joint) += k;
    stiffness(gearbox, gearbox) += k;
    stiffness(joint, gearbox) -= k;
    stiffness(gearbox, joint) -= k;
  }
  const std::vector<VibrationMode> modes =
      LinearisedModes(model, q, Vec8::Zero(), DriveVoltages{}, false);
  // 8 coordinates, two rigid-body motions (the arm turning as a whole with
  // its gearboxes): six oscillatory modes, the rigid-body zero eigenvalues
  // left out (the differences would split them into spurious ~1e-5 Hz pairs).
  std::vector<VibrationMode> flexible;
  std::ostringstream list;
  int near_zero = 0;
  for (const VibrationMode& m : modes) {
    list << m.frequency_hz << " ";
    if (m.frequency_hz > 1e-3) {
      flexible.push_back(m);
    } else {
      ++near_zero;
    }
  }
  WARN("free modes at rest (Hz): " << list.str());
  CHECK(near_zero == 0);
  REQUIRE(flexible.size() == 6);
  for (const VibrationMode& m : flexible) {
    const double f = m.frequency_hz;
    INFO("mode at " << f << " Hz");
    auto det = [&](double hz) {
      const double w = 2.0 * std::numbers::pi * hz;
      return Determinant(stiffness - w * w * mass);
    };
    // A simple root of the characteristic polynomial within 1e-6 of f.
    CHECK(det(f * (1.0 - 1e-6)) * det(f * (1.0 + 1e-6)) < 0.0);
    // ... and not merely a sign change somewhere: 1 % away there is none.
    CHECK(det(f * 0.99) * det(f * (1.0 - 1e-6)) > 0.0);
    CHECK(det(f * 1.01) * det(f * (1.0 + 1e-6)) > 0.0);
    CHECK(m.damping_ratio == Approx(0.0).margin(1e-6));
  }
}

}  // namespace
}  // namespace impactlab
