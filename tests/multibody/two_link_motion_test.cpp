// The two-link arm in motion: energy conservation in free flight, the rigid
// limit against a classical rigid two-link, the integrator's order, the
// impact law and the loop closure.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include "model/ode_integrator.h"
#include "multibody/two_link_dynamics.h"
#include "multibody/two_link_model.h"
#include "multibody/two_link_state.h"
#include "tests/multibody/two_link_reference.h"

namespace impactlab {
namespace {

using Integrator = OdeIntegrator<2 * kTwoLinkCoordinates>;
using State = Integrator::State;

Integrator::System FreeFlight(const TwoLinkModel& model) {
  return [&model](const State& y, State& dydt, double) {
    TwoLinkVector q, v;
    SplitState(y, &q, &v);
    dydt = JoinState(v, FreeAcceleration(model, q, v, DriveVoltages{}));
  };
}

// testing::ConservativeParameters(): motors off and every dissipation
// removed; the meshes stay (no play). Its mesh modes ring at ~370 and ~610 Hz,
// the arm's own at 3-27 Hz. ConservativeArm(): the same with the meshes disengaged (stiffness 0):
// the gearboxes coast and the arm's own modes (5-43 Hz) are the fastest, so that long runs stay
// cheap.
TwoLinkParameters ConservativeArm() {
  TwoLinkParameters p = testing::ConservativeParameters();
  p.drive_a.mesh_stiffness_n_m_per_rad = 0.0;
  p.drive_b.mesh_stiffness_n_m_per_rad = 0.0;
  return p;
}

// A swinging, vibrating start: both links turning, every beam coordinate and
// both meshes deflected.
void SwingingStart(TwoLinkVector* q, TwoLinkVector* v) {
  *q << 0.9, 0.01, -0.02, 0.5, -0.005, 0.01, 0.902, 0.499;
  *v << 2.0, 0.3, -0.5, -3.0, 0.2, 0.4, 2.1, -2.9;
}

double Energy(const TwoLinkModel& model, const State& y) {
  TwoLinkVector q, v;
  SplitState(y, &q, &v);
  return model.KineticEnergy(q, v) + model.PotentialEnergy(q);
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

TEST_CASE("two-link: free flight without motors or damping conserves T + V") {
  const TwoLinkModel model(ConservativeArm());
  TwoLinkVector q, v;
  SwingingStart(&q, &v);
  Integrator integrator({1e-12, 1e-15, 0.01});
  integrator.Reset(FreeFlight(model), JoinState(q, v), 0.0, 1e-5);
  const double e0 = Energy(model, integrator.state());
  double worst = 0.0;
  const auto start = std::chrono::steady_clock::now();
  while (integrator.time() < 5.0) {
    REQUIRE(integrator.Step(5.0).ok);
    worst = std::max(worst, std::abs(Energy(model, integrator.state()) - e0) / e0);
  }
  const double end_drift = std::abs(Energy(model, integrator.state()) - e0) / e0;
  WARN("energy: E0 = " << e0 << " J, worst relative drift over 5 s " << worst << ", at the end "
                       << end_drift << ", " << integrator.accepted_steps() << " steps, "
                       << Seconds(start) << " s");
  CHECK(worst <= 1e-9);
  // The motion did exercise every coordinate (it is not a trivial rest).
  TwoLinkVector q_end, v_end;
  SplitState(integrator.state(), &q_end, &v_end);
  CHECK(std::abs(q_end(kLink1Angle) - q(kLink1Angle)) > 1.0);
}

TEST_CASE("two-link: mesh twist and beam deflection trade energy but the sum is conserved") {
  // The same system started from rest with only the meshes wound up: energy
  // flows out of the meshes into motion and the beams, and T + V holds.
  // (The tolerance is relative to the gearbox angles, ~1 rad, while the
  // energy sits in twists of a few mrad: 1e-12 keeps the drift below 1e-9.)
  const TwoLinkModel model(testing::ConservativeParameters());
  TwoLinkVector q = TwoLinkVector::Zero(), v = TwoLinkVector::Zero();
  q(kLink1Angle) = 1.2;
  q(kGearboxAAngle) = 1.2 + 0.003;
  q(kLink2Angle) = -0.4;
  q(kGearboxBAngle) = -0.4 - 0.004;
  // (0.1 s: some 40 periods of the mesh modes)
  Integrator integrator({1e-12, 1e-15, 0.01});
  integrator.Reset(FreeFlight(model), JoinState(q, v), 0.0, 1e-5);
  const double e0 = Energy(model, integrator.state());
  double worst = 0.0, max_kinetic = 0.0;
  const auto start = std::chrono::steady_clock::now();
  while (integrator.time() < 0.1) {
    REQUIRE(integrator.Step(0.1).ok);
    worst = std::max(worst, std::abs(Energy(model, integrator.state()) - e0) / e0);
    TwoLinkVector qs, vs;
    SplitState(integrator.state(), &qs, &vs);
    max_kinetic = std::max(max_kinetic, model.KineticEnergy(qs, vs));
  }
  WARN("energy with the meshes wound up: E0 = " << e0 << " J, worst relative drift over 0.1 s "
                                                << worst << ", largest T / E0 " << max_kinetic / e0
                                                << ", " << integrator.accepted_steps() << " steps, "
                                                << Seconds(start) << " s");
  CHECK(worst <= 1e-9);
  CHECK(max_kinetic > 0.5 * e0);
}

// ---------------------------------------------------------------------------
// The rigid limit.

// The classical rigid two-link: link 1 (hub RB1, beam 1 as a uniform rod from
// r1 to r1 + L1, RB2 and RB3's masses at joint B, RB2's inertia) about A;
// link 2 (RB3, beam 2 as a rod from r3 to r3 + L2, the tool at
// r3 + L2 + centre with its inertia) about B at angle q4 from link 1.
//   M(q4) = [[a + 2 b cos q4, c + b cos q4], [c + b cos q4, c]],
//   h = b sin q4 [-(2 q1' q4' + q4'^2), q1'^2].
struct RigidArm {
  double a, b, c;
  explicit RigidArm(const TwoLinkParameters& p) {
    const double r1 = p.beam1.hub_radius_m, l1 = p.beam1.length_m,
                 rho1 = p.beam1.mass_per_length_kg_per_m;
    const double r3 = p.beam2.hub_radius_m, l2 = p.beam2.length_m,
                 rho2 = p.beam2.mass_per_length_kg_per_m;
    const double a1 = r1 + l1;
    const double d_tool = r3 + l2 + p.tool.centre_m;
    const double link1_inertia = p.hub1.inertia_kg_m2 + p.body2.inertia_kg_m2 +
                                 rho1 * (a1 * a1 * a1 - r1 * r1 * r1) / 3.0 +
                                 (p.body2.mass_kg + p.hub3.mass_kg) * a1 * a1;
    const double link2_mass = rho2 * l2 + p.tool.body.mass_kg;
    const double link2_moment =
        rho2 * ((r3 + l2) * (r3 + l2) - r3 * r3) / 2.0 + p.tool.body.mass_kg * d_tool;
    const double link2_inertia = p.hub3.inertia_kg_m2 + p.tool.body.inertia_kg_m2 +
                                 rho2 * ((r3 + l2) * (r3 + l2) * (r3 + l2) - r3 * r3 * r3) / 3.0 +
                                 p.tool.body.mass_kg * d_tool * d_tool;
    a = link1_inertia + link2_mass * a1 * a1 + link2_inertia;
    b = a1 * link2_moment;
    c = link2_inertia;
  }
  // y = (q1, q4, q1', q4', -, -)
  void operator()(const OdeIntegrator<6>::State& y, OdeIntegrator<6>::State& dydt, double) const {
    const double cq = std::cos(y[1]), sq = std::sin(y[1]);
    const double w1 = y[2], w4 = y[3];
    const double m11 = a + 2.0 * b * cq, m12 = c + b * cq, m22 = c;
    const double h1 = -b * sq * (2.0 * w1 * w4 + w4 * w4), h2 = b * sq * w1 * w1;
    const double det = m11 * m22 - m12 * m12;
    dydt = {w1, w4, (-m22 * h1 + m12 * h2) / det, (m12 * h1 - m11 * h2) / det, 0.0, 0.0};
  }
};

struct Trajectory {
  std::vector<double> q1, q4;
};

constexpr double kRigidSpan = 1.0;
constexpr int kRigidSamples = 50;

Trajectory RigidTrajectory(const TwoLinkParameters& p, double q1, double q4, double w1, double w4) {
  OdeIntegrator<6> integrator({1e-12, 1e-15, 0.01});
  integrator.Reset(RigidArm(p), {q1, q4, w1, w4, 0.0, 0.0}, 0.0, 1e-4);
  Trajectory out;
  for (int k = 1; k <= kRigidSamples; ++k) {
    const double t = kRigidSpan * k / kRigidSamples;
    while (integrator.time() < t) REQUIRE(integrator.Step(t).ok);
    out.q1.push_back(integrator.state()[0]);
    out.q4.push_back(integrator.state()[1]);
  }
  return out;
}

// The flexible arm with its beams `factor` times stiffer, the drives decoupled.
Trajectory StiffenedTrajectory(double factor, double q1, double q4, double w1, double w4,
                               long* steps) {
  TwoLinkParameters p = testing::ConservativeParameters();
  p.beam1.flexural_rigidity_n_m2 *= factor;
  p.beam2.flexural_rigidity_n_m2 *= factor;
  for (TwoLinkDrive* d : {&p.drive_a, &p.drive_b}) {
    d->mesh_stiffness_n_m_per_rad = 0.0;
    d->equivalent_inertia_kg_m2 = 1e-6;
  }
  const TwoLinkModel model(p);
  TwoLinkVector q = TwoLinkVector::Zero(), v = TwoLinkVector::Zero();
  q(kLink1Angle) = q(kGearboxAAngle) = q1;
  q(kLink2Angle) = q(kGearboxBAngle) = q4;
  v(kLink1Angle) = w1;
  v(kLink2Angle) = w4;
  Integrator integrator({1e-9, 1e-12, 0.01});
  integrator.Reset(FreeFlight(model), JoinState(q, v), 0.0, 1e-6);
  Trajectory out;
  for (int k = 1; k <= kRigidSamples; ++k) {
    const double t = kRigidSpan * k / kRigidSamples;
    while (integrator.time() < t) REQUIRE(integrator.Step(t).ok);
    out.q1.push_back(integrator.state()[kLink1Angle]);
    // (link 2 is at q1 + q3 + q4; with stiff beams the tip rotation q3 -> 0)
    out.q4.push_back(integrator.state()[kLink2Angle]);
  }
  *steps = integrator.accepted_steps();
  return out;
}

double WorstDifference(const Trajectory& a, const Trajectory& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.q1.size(); ++k) {
    worst = std::max({worst, std::abs(a.q1[k] - b.q1[k]), std::abs(a.q4[k] - b.q4[k])});
  }
  return worst;
}

TEST_CASE(
    "two-link: with stiff beams the arm moves as the classical rigid two-link, error ~ 1/EI") {
  const double q1 = 0.3, q4 = 0.8, w1 = 2.0, w4 = -3.0;
  const Trajectory rigid = RigidTrajectory(testing::ConservativeParameters(), q1, q4, w1, w4);
  // The rigid arm itself moves well away from a uniform rotation.
  CHECK(std::abs(rigid.q4.back() - (q4 + w4 * kRigidSpan)) > 0.1);
  const double factors[2] = {1e2, 1e3};
  double errors[2];
  for (int i = 0; i < 2; ++i) {
    long steps = 0;
    const auto start = std::chrono::steady_clock::now();
    errors[i] = WorstDifference(StiffenedTrajectory(factors[i], q1, q4, w1, w4, &steps), rigid);
    WARN("rigid limit: EI x " << factors[i] << ": largest |q1 - q1_rigid|, |q4 - q4_rigid| over "
                              << kRigidSpan << " s = " << errors[i] << " rad (" << steps
                              << " steps, " << Seconds(start) << " s)");
  }
  CHECK(errors[0] <= 1e-4);
  CHECK(errors[1] <= 1e-5);
  // Ten times stiffer, ten times closer (first order in the compliance).
  const double ratio = errors[0] / errors[1];
  WARN("rigid limit: error ratio for a 10x stiffer beam " << ratio);
  CHECK(ratio > 6.0);
  CHECK(ratio < 15.0);
}

// ---------------------------------------------------------------------------
// The integrator's order.

TEST_CASE("two-link: the Dormand-Prince integration converges at fifth order") {
  const TwoLinkModel model(ConservativeArm());
  TwoLinkVector q, v;
  SwingingStart(&q, &v);
  const double span = 0.5;
  auto run = [&](double rtol, long* steps) {
    Integrator integrator({rtol, 1e-3 * rtol, 1.0});
    integrator.Reset(FreeFlight(model), JoinState(q, v), 0.0, 1e-4);
    while (integrator.time() < span) REQUIRE(integrator.Step(span).ok);
    *steps = integrator.accepted_steps();
    return integrator.state();
  };
  long reference_steps = 0;
  const State reference = run(1e-13, &reference_steps);
  std::vector<double> log_steps, log_error;
  std::ostringstream table;
  for (double rtol : {1e-5, 1e-6, 1e-7, 1e-8}) {
    long steps = 0;
    const State y = run(rtol, &steps);
    double error = 0.0;
    for (int i = 0; i < 2 * kTwoLinkCoordinates; ++i) {
      error = std::max(error, std::abs(y[i] - reference[i]) / (1.0 + std::abs(reference[i])));
    }
    table << "  rtol " << rtol << ": " << steps << " steps, error " << error << "\n";
    log_steps.push_back(std::log(static_cast<double>(steps)));
    log_error.push_back(std::log(error));
  }
  // Least-squares slope of log(error) against log(steps).
  const int n = static_cast<int>(log_steps.size());
  double mx = 0.0, my = 0.0;
  for (int i = 0; i < n; ++i) {
    mx += log_steps[i] / n;
    my += log_error[i] / n;
  }
  double sxy = 0.0, sxx = 0.0;
  for (int i = 0; i < n; ++i) {
    sxy += (log_steps[i] - mx) * (log_error[i] - my);
    sxx += (log_steps[i] - mx) * (log_steps[i] - mx);
  }
  const double slope = sxy / sxx;
  WARN("integrator order: slope of log(error) vs log(steps) = " << slope << " (reference "
                                                                << reference_steps << " steps)\n"
                                                                << table.str());
  CHECK(slope < -4.0);
  CHECK(slope > -6.0);
}

// ---------------------------------------------------------------------------
// The impact and the loop closure.

// A state with the tip on the surface: beams and meshes deflected, q4 closed
// by CloseLoop, and an incoming velocity (tip moving into the surface, and
// along it).
struct Contact {
  TwoLinkVector q, v;
};
Contact ContactState(const TwoLinkModel& model) {
  Contact c;
  // Link 1 at 57 deg, link 2 bent back to the surface at ~141 deg: turning
  // link 2 moves the tip both into the surface and along it.
  c.q << 1.0, 0.004, -0.006, 1.4, 0.002, 0.003, 1.001, 1.399;
  c.v.setZero();
  REQUIRE(DependentCoordinate(model, c.q) == kLink2Angle);
  const double gap = CloseLoop(model, kLink2Angle, &c.q, &c.v);
  CHECK(std::abs(gap) <= 1e-12);
  CHECK(std::abs(model.Gap(c.q)) <= 1e-12);
  c.v << 0.5, 0.2, -0.3, 2.0, 0.1, -0.2, 0.5, 2.0;
  const TwoLinkRow normal = model.Tip(c.q, c.v).jacobian.row(0);
  if (normal.dot(c.v) > 0.0) c.v = -c.v;
  return c;
}

// x = A^-1 b by Gaussian elimination with partial pivoting (a few lines
// instead of Eigen's decompositions, which cost seconds of compile time).
TwoLinkVector Solve(TwoLinkMatrix a, TwoLinkVector b) {
  const int n = kTwoLinkCoordinates;
  for (int col = 0; col < n; ++col) {
    int pivot = col;
    for (int r = col + 1; r < n; ++r) {
      if (std::abs(a(r, col)) > std::abs(a(pivot, col))) pivot = r;
    }
    a.row(col).swap(a.row(pivot));
    std::swap(b(col), b(pivot));
    for (int r = col + 1; r < n; ++r) {
      const double f = a(r, col) / a(col, col);
      for (int c = col; c < n; ++c) a(r, c) -= f * a(col, c);
      b(r) -= f * b(col);
    }
  }
  TwoLinkVector x;
  for (int r = n - 1; r >= 0; --r) {
    double sum = b(r);
    for (int c = r + 1; c < n; ++c) sum -= a(r, c) * x(c);
    x(r) = sum / a(r, r);
  }
  return x;
}

TwoLinkMatrix MassOf(const TwoLinkModel& model, const TwoLinkVector& q) {
  TwoLinkMatrix m;
  TwoLinkVector h;
  model.Inertia(q, TwoLinkVector::Zero(), &m, &h);
  return m;
}

TEST_CASE("two-link: the loop closure puts the tip on the surface with zero normal speed") {
  const TwoLinkModel model(TwoLinkParameters::Nominal());
  TwoLinkVector q, v;
  q << 1.52, 0.003, -0.004, 0.2, 0.001, 0.002, 1.52, 0.2;
  v << 1.0, 0.1, 0.2, -0.5, 0.05, 0.1, 1.0, -0.5;
  const TwoLinkVector q0 = q, v0 = v;
  REQUIRE(DependentCoordinate(model, q) == kLink2Angle);
  CloseLoop(model, kLink2Angle, &q, &v);
  CHECK(std::abs(model.Gap(q)) <= 1e-14);
  const TwoLinkRow normal = model.Tip(q, v).jacobian.row(0);
  CHECK(std::abs(normal.dot(v)) <= 1e-13 * v.norm());
  // Only the dependent coordinate and its rate moved.
  for (int i = 0; i < kTwoLinkCoordinates; ++i) {
    if (i == kLink2Angle) continue;
    CHECK(q(i) == q0(i));
    CHECK(v(i) == v0(i));
  }
  // The tip itself (the model's tip is checked against the geometry in
  // two_link_equations_test.cpp) is on x = -distance.
  CHECK(model.Tip(q, v).position.x() ==
        Approx(-model.parameters().surface.distance_m).margin(1e-14));
}

TEST_CASE("two-link: where link 2 turns the tip along the surface, q1 closes the loop") {
  const TwoLinkModel model(TwoLinkParameters::Nominal());
  // Link 2 pointing straight at the surface (alpha3 = pi): turning it moves
  // the tip along the surface, so q1 must be the dependent coordinate.
  TwoLinkVector q, v;
  q << 0.8, 0.002, -0.003, 2.35, 0.001, -0.002, 0.8, 2.35;
  v << 0.3, 0.1, -0.2, 1.0, 0.05, 0.1, 0.3, 1.0;
  REQUIRE(DependentCoordinate(model, q) == kLink1Angle);
  const TwoLinkVector q0 = q;
  CloseLoop(model, kLink1Angle, &q, &v);
  CHECK(std::abs(model.Gap(q)) <= 1e-14);
  CHECK(std::abs(model.Tip(q, v).jacobian.row(0).dot(v)) <= 1e-13 * v.norm());
  CHECK(q(kLink2Angle) == q0(kLink2Angle));
  CHECK(std::abs(q(kLink1Angle) - q0(kLink1Angle)) < 0.05);
}

TEST_CASE("two-link: a sticking impact stops the tip and balances momentum") {
  TwoLinkParameters p = TwoLinkParameters::Nominal();
  p.surface.friction_coefficient = 100.0;
  const TwoLinkModel model(p);
  const Contact c = ContactState(model);
  const ImpactOutcome out = Impact(model, c.q, c.v);
  const PointMotion tip = model.Tip(c.q, c.v);
  const Eigen::Vector2d before = tip.jacobian * c.v, after = tip.jacobian * out.velocity;
  WARN("sticking impact: tip velocity before "
       << before.transpose() << " m/s, after " << after.transpose() << ", residual "
       << out.momentum_residual << ", impulses " << out.normal_impulse_n_s << ", "
       << out.tangential_impulse_n_s << " N s");
  CHECK(before.x() < 0.0);
  CHECK(std::abs(before.y()) > 0.1 * std::abs(before.x()));
  CHECK(out.sticks);
  CHECK(out.normal_impulse_n_s > 0.0);
  CHECK(std::abs(after.x()) <= 1e-12 * std::abs(before.x()));
  CHECK(std::abs(after.y()) <= 1e-12 * before.norm());
  CHECK(out.normal_velocity_after_m_s == Approx(after.x()).margin(1e-15));
  CHECK(out.tangential_velocity_after_m_s == Approx(after.y()).margin(1e-15));
  CHECK(out.momentum_residual <= 1e-12);
  // Momentum balance recomputed here: M (v+ - v-) = G^T P.
  const TwoLinkMatrix m = MassOf(model, c.q);
  const TwoLinkVector impulse = tip.jacobian.transpose() *
                                Eigen::Vector2d(out.normal_impulse_n_s, out.tangential_impulse_n_s);
  CHECK((m * (out.velocity - c.v) - impulse).norm() <= 1e-12 * (m * c.v).norm());
  // A perfectly plastic impact loses kinetic energy.
  CHECK(model.KineticEnergy(c.q, out.velocity) < model.KineticEnergy(c.q, c.v));
}

TEST_CASE(
    "two-link: a frictionless impact has no tangential impulse and removes the normal speed") {
  TwoLinkParameters p = TwoLinkParameters::Nominal();
  p.surface.friction_coefficient = 0.0;
  const TwoLinkModel model(p);
  const Contact c = ContactState(model);
  const ImpactOutcome out = Impact(model, c.q, c.v);
  const PointMotion tip = model.Tip(c.q, c.v);
  const TwoLinkRow normal = tip.jacobian.row(0);
  WARN("frictionless impact: normal speed before " << normal.dot(c.v) << " m/s, after "
                                                   << normal.dot(out.velocity) << ", residual "
                                                   << out.momentum_residual);
  CHECK_FALSE(out.sticks);
  CHECK(out.tangential_impulse_n_s == 0.0);
  CHECK(out.normal_impulse_n_s > 0.0);
  CHECK(std::abs(normal.dot(out.velocity)) <= 1e-12 * std::abs(normal.dot(c.v)));
  CHECK(out.momentum_residual <= 1e-12);
  // The closed form: v+ = v- - M^-1 G_n^T (G_n v-) / (G_n M^-1 G_n^T), and
  // the kinetic energy lost is (G_n v-)^2 / (2 G_n M^-1 G_n^T).
  const TwoLinkMatrix m = MassOf(model, c.q);
  const TwoLinkVector response = Solve(m, normal.transpose());
  const double approach = normal.dot(c.v), delassus = normal.dot(response);
  const TwoLinkVector expected = c.v - response * approach / delassus;
  CHECK((out.velocity - expected).norm() <= 1e-12 * c.v.norm());
  CHECK(out.normal_impulse_n_s == Approx(-approach / delassus).epsilon(1e-12));
  const double lost = model.KineticEnergy(c.q, c.v) - model.KineticEnergy(c.q, out.velocity);
  CHECK(lost == Approx(0.5 * approach * approach / delassus).epsilon(1e-9));
}

TEST_CASE(
    "two-link: by the paper's law a sliding impact's friction is mu times the normal impulse, "
    "against the slip before") {
  TwoLinkParameters p = TwoLinkParameters::Nominal();
  p.surface.friction_coefficient = 0.2;
  p.surface.impact_friction = "paper";
  const TwoLinkModel model(p);
  const Contact c = ContactState(model);
  const ImpactOutcome out = Impact(model, c.q, c.v);
  const PointMotion tip = model.Tip(c.q, c.v);
  const double slip = tip.jacobian.row(1).dot(c.v);
  REQUIRE_FALSE(out.sticks);
  CHECK(out.tangential_impulse_n_s ==
        Approx(-0.2 * (slip > 0.0 ? 1.0 : -1.0) * out.normal_impulse_n_s).epsilon(1e-14));
  CHECK(std::abs(tip.jacobian.row(0).dot(out.velocity)) <=
        1e-12 * std::abs(tip.jacobian.row(0).dot(c.v)));
  CHECK(out.momentum_residual <= 1e-12);
}

TEST_CASE(
    "two-link: where the slip reverses during the impulse, the incremental law's friction does "
    "no positive work, and the paper's ends pushing the tip along its slip") {
  TwoLinkParameters p = TwoLinkParameters::Nominal();
  const TwoLinkModel incremental_model(p);
  p.surface.impact_friction = "paper";
  const TwoLinkModel paper_model(p);
  const Contact c = ContactState(incremental_model);
  const ImpactOutcome incremental = Impact(incremental_model, c.q, c.v);
  const ImpactOutcome paper = Impact(paper_model, c.q, c.v);
  WARN("slip " << incremental.tangential_velocity_before_m_s << " -> "
               << incremental.tangential_velocity_after_m_s << " (paper's "
               << paper.tangential_velocity_after_m_s << ") m/s; P_n "
               << incremental.normal_impulse_n_s << " (" << paper.normal_impulse_n_s << "), P_t "
               << incremental.tangential_impulse_n_s << " (" << paper.tangential_impulse_n_s
               << ") N s; friction work " << incremental.friction_work_j << " ("
               << paper.friction_work_j << ") J");
  REQUIRE(incremental.slip_reversed);
  CHECK(incremental.friction_work_j <= 0.0);
  // The paper's friction impulse points along the slip it leaves: Coulomb's
  // law broken over the impulse's last part.
  CHECK(paper.tangential_impulse_n_s * paper.tangential_velocity_after_m_s > 0.0);
  CHECK(std::abs(incremental.tangential_impulse_n_s) <=
        0.2 * incremental.normal_impulse_n_s * (1 + 1e-12));
  CHECK(incremental.momentum_residual <= 1e-12);
  // Both are plastic, and the energy lost is the impulses' work.
  CHECK(std::abs(incremental.normal_velocity_after_m_s) <=
        1e-12 * std::abs(incremental.normal_velocity_before_m_s));
  const double lost = incremental_model.KineticEnergy(c.q, c.v) -
                      incremental_model.KineticEnergy(c.q, incremental.velocity);
  CHECK(lost == Approx(-(incremental.normal_work_j + incremental.friction_work_j)).epsilon(1e-9));
}

TEST_CASE("two-link: constrained acceleration keeps the tip's normal acceleration zero") {
  const TwoLinkModel model(TwoLinkParameters::Nominal());
  Contact c = ContactState(model);
  // A state on the constraint: close the normal speed.
  CloseLoop(model, kLink2Angle, &c.q, &c.v);
  const DriveVoltages volts{1.5, 1.5};
  const ConstrainedAcceleration a = ConstrainedMotion(model, c.q, c.v, volts);
  const PointMotion tip = model.Tip(c.q, c.v);
  const double normal_acceleration =
      tip.jacobian.row(0).dot(a.acceleration) + tip.velocity_product.x();
  const TwoLinkVector free = FreeAcceleration(model, c.q, c.v, volts);
  CHECK(std::abs(normal_acceleration) <=
        1e-10 * std::abs(tip.jacobian.row(0).dot(free) + tip.velocity_product.x()));
  // Newton: M (a - a_free) = W^T lambda with W = G_n + friction/normal G_t.
  const TwoLinkMatrix m = MassOf(model, c.q);
  const TwoLinkVector reaction = tip.jacobian.row(0).transpose() * a.normal_force_n +
                                 tip.jacobian.row(1).transpose() * a.friction_force_n;
  CHECK((m * (a.acceleration - free) - reaction).norm() <= 1e-9 * (1.0 + reaction.norm()));
  // Coulomb: |friction| <= mu lambda, against the slip.
  const double slip = tip.jacobian.row(1).dot(c.v);
  CHECK(std::abs(a.friction_force_n) <= model.parameters().surface.friction_coefficient *
                                            std::abs(a.normal_force_n) * (1.0 + 1e-14));
  CHECK(a.friction_force_n * a.normal_force_n * slip <= 0.0);
}

}  // namespace
}  // namespace impactlab
