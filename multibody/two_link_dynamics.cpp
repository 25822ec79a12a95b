#include "multibody/two_link_dynamics.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace impactlab {
namespace {

using Solver = Eigen::LLT<TwoLinkMatrix>;

// M, the right-hand side Q - h, and the factorised M.
struct Balance {
  TwoLinkMatrix mass;
  TwoLinkVector rhs;
  Solver solver;
};

Balance Assemble(const TwoLinkModel& model, const TwoLinkVector& q, const TwoLinkVector& v,
                 const DriveVoltages& voltages) {
  Balance b;
  TwoLinkVector velocity_forces;
  model.Inertia(q, v, &b.mass, &velocity_forces);
  b.rhs = model.AppliedForces(q, v, voltages) - velocity_forces;
  b.solver.compute(b.mass);
  if (b.solver.info() != Eigen::Success) {
    throw std::domain_error(fmt::format(
        "the mass matrix is not positive definite at beam deflections {:.3g}, {:.3g} m (a state "
        "far outside the arm's range: a diverging or too-stiff motion)",
        q(kBeam1Deflection), q(kBeam2Deflection)));
  }
  return b;
}

double RegularisedSign(double velocity, double scale) {
  return velocity / std::sqrt(velocity * velocity + scale * scale);
}

}  // namespace

TwoLinkVector FreeAcceleration(const TwoLinkModel& model, const TwoLinkVector& q,
                               const TwoLinkVector& v, const DriveVoltages& voltages) {
  const Balance b = Assemble(model, q, v, voltages);
  return b.solver.solve(b.rhs);
}

ConstrainedAcceleration ConstrainedMotion(const TwoLinkModel& model, const TwoLinkVector& q,
                                          const TwoLinkVector& v, const DriveVoltages& voltages) {
  const Balance b = Assemble(model, q, v, voltages);
  const PointMotion tip = model.Tip(q, v);
  const TwoLinkRow normal = tip.jacobian.row(0);
  const TwoLinkRow tangent = tip.jacobian.row(1);
  const TwoLinkSurface& surface = model.parameters().surface;
  const double slip = tangent.dot(v);
  const double friction_per_normal =
      -surface.friction_coefficient * RegularisedSign(slip, surface.slip_velocity_m_s);
  const TwoLinkRow loaded = normal + friction_per_normal * tangent;  // W
  const TwoLinkVector free = b.solver.solve(b.rhs);
  const TwoLinkVector response = b.solver.solve(loaded.transpose());  // M^-1 W^T
  ConstrainedAcceleration out;
  out.normal_force_n = (-tip.velocity_product.x() - normal.dot(free)) / normal.dot(response);
  out.friction_force_n = friction_per_normal * out.normal_force_n;
  out.acceleration = free + out.normal_force_n * response;
  return out;
}

ContactImpulseLaw ImpactLawOf(const TwoLinkSurface& surface) {
  ContactImpulseLaw law;
  law.friction_coefficient = surface.friction_coefficient;
  law.friction =
      surface.impact_friction == "paper" ? ImpactFriction::kPaper : ImpactFriction::kIncremental;
  law.restitution = surface.restitution_law == "newton"    ? RestitutionLaw::kNewton
                    : surface.restitution_law == "poisson" ? RestitutionLaw::kPoisson
                                                           : RestitutionLaw::kEnergetic;
  law.restitution_coefficient = surface.restitution_coefficient;
  return law;
}

ImpactOutcome Impact(const TwoLinkModel& model, const TwoLinkVector& q,
                     const TwoLinkVector& velocity_before, double plastic_below_m_s) {
  TwoLinkMatrix mass;
  TwoLinkVector unused;
  model.Inertia(q, velocity_before, &mass, &unused);
  const Solver solver(mass);
  const PointMotion tip = model.Tip(q, velocity_before);
  const Eigen::Matrix<double, 2, kTwoLinkCoordinates>& rows = tip.jacobian;  // G_n, G_t
  const Eigen::Matrix<double, kTwoLinkCoordinates, 2> response = solver.solve(rows.transpose());
  const Eigen::Matrix2d delassus = rows * response;
  const Eigen::Vector2d before = rows * velocity_before;
  ContactImpulseLaw law = ImpactLawOf(model.parameters().surface);
  if (std::abs(before(0)) < plastic_below_m_s) law.restitution_coefficient = 0.0;
  const ContactImpulse contact = ResolveContactImpulse(delassus, before, law);

  ImpactOutcome out;
  out.normal_velocity_before_m_s = before(0);
  out.tangential_velocity_before_m_s = before(1);
  out.normal_impulse_n_s = contact.impulse(0);
  out.tangential_impulse_n_s = contact.impulse(1);
  out.sticks = contact.sticks;
  out.slip_reversed = contact.slip_reversed;
  out.normal_work_j = contact.normal_work_j;
  out.friction_work_j = contact.friction_work_j;
  const TwoLinkVector generalized_impulse = rows.transpose() * contact.impulse;
  out.velocity = velocity_before + response * contact.impulse;
  out.normal_velocity_after_m_s = rows.row(0).dot(out.velocity);
  out.tangential_velocity_after_m_s = rows.row(1).dot(out.velocity);
  const double scale = (mass * velocity_before).norm();
  out.momentum_residual =
      (mass * (out.velocity - velocity_before) - generalized_impulse).norm() / scale;
  return out;
}

int DependentCoordinate(const TwoLinkModel& model, const TwoLinkVector& q) {
  const TwoLinkRow normal = model.Tip(q, TwoLinkVector::Zero()).jacobian.row(0);
  return std::abs(normal(kLink2Angle)) >= 0.2 * std::abs(normal(kLink1Angle)) ? kLink2Angle
                                                                              : kLink1Angle;
}

double CloseLoop(const TwoLinkModel& model, int dependent, TwoLinkVector* q, TwoLinkVector* v) {
  double gap = model.Gap(*q);
  for (int iteration = 0; iteration < 30 && gap != 0.0; ++iteration) {
    const double slope = model.Tip(*q, TwoLinkVector::Zero()).jacobian(0, dependent);
    const double step = gap / slope;
    (*q)(dependent) -= step;
    gap = model.Gap(*q);
    if (std::abs(step) <= 1e-15 * (1.0 + std::abs((*q)(dependent)))) break;
  }
  if (!(std::abs(gap) < 1e-12)) {
    throw std::domain_error(fmt::format(
        "two-link: the loop closure did not converge (gap {:.3g} m after Newton)", gap));
  }
  const TwoLinkRow normal = model.Tip(*q, TwoLinkVector::Zero()).jacobian.row(0);
  (*v)(dependent) -= normal.dot(*v) / normal(dependent);
  return gap;
}

}  // namespace impactlab
