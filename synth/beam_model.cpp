#include <array>

#include "synth/beam_model_internal.h"

namespace impactlab {

bool BeamArm::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (!(length_m > 0.0 && mass_per_length_kg_per_m > 0.0 && flexural_rigidity_n_m2 > 0.0)) {
    return fail("the beam needs a positive length, mass per length and EI");
  }
  if (!(hub_inertia_kg_m2 > 0.0 && tip_mass_kg >= 0.0 && tip_inertia_kg_m2 >= 0.0)) {
    return fail("inertias must be positive (hub) or >= 0 (tip)");
  }
  if (!(beam_damping_n_s_per_m2 >= 0.0 && hub_damping_n_m_s > 0.0)) {
    return fail("damping must be >= 0 (beam) and > 0 (hub)");
  }
  if (!(motor_torque_n_m > 0.0)) return fail("the motor torque must be positive");
  if (!(wall_angle_rad > start_angle_rad)) return fail("the wall must lie ahead of the start");
  if (!(start_delay_s >= 0.0)) return fail("start_delay_s must be >= 0");
  return true;
}

namespace beam_internal {
namespace {

// Gauss-Legendre, 5 points on [0, 1]: exact to degree 9 (the integrands are <= 6).
constexpr std::array<double, 5> kGaussX = {0.04691007703066800, 0.2307653449471585, 0.5,
                                           0.7692346550528415, 0.9530899229693320};
constexpr std::array<double, 5> kGaussW = {0.1184634425280945, 0.2393143352496832,
                                           0.2844444444444444, 0.2393143352496832,
                                           0.1184634425280945};

// Second derivatives of the shape functions in x: the beam's curvature per
// unit q2 and q3.
double TipDeflectionCurvature(double xi, double l) { return (6.0 - 12.0 * xi) / (l * l); }
double TipSlopeCurvature(double xi, double l) { return (6.0 * xi - 2.0) / l; }

}  // namespace

double TipDeflectionShape(double xi) { return 3.0 * xi * xi - 2.0 * xi * xi * xi; }
double TipSlopeShape(double xi, double length_m) { return length_m * (xi * xi * xi - xi * xi); }

Eigen::RowVector3d TipTravelRow(double length_m) { return {length_m, 1.0, 0.0}; }

LinearEquations<3> FreeFlightEquations(const BeamArm& arm) {
  const double l = arm.length_m;
  // Per unit length of beam: the transverse velocity x theta' + w' = u(x) p',
  // the deflection velocity w' = d(x) p' (where the beam's damping acts) and
  // the curvature w'' = k(x) p (where its stiffness acts).
  Eigen::Matrix3d beam_mass = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d beam_damping = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d beam_stiffness = Eigen::Matrix3d::Zero();
  for (std::size_t g = 0; g < kGaussX.size(); ++g) {
    const double xi = kGaussX[g], weight = kGaussW[g] * l;
    const double phi2 = TipDeflectionShape(xi), phi3 = TipSlopeShape(xi, l);
    const Eigen::Vector3d velocity(xi * l, phi2, phi3);
    const Eigen::Vector3d deflection(0.0, phi2, phi3);
    const Eigen::Vector3d curvature(0.0, TipDeflectionCurvature(xi, l), TipSlopeCurvature(xi, l));
    beam_mass += weight * velocity * velocity.transpose();
    beam_damping += weight * deflection * deflection.transpose();
    beam_stiffness += weight * curvature * curvature.transpose();
  }
  // The tip mass moves at L theta' + q2' (the tip's travel); the tip body
  // turns at theta' + q3', since phi2'(L) = 0 and phi3'(L) = 1.
  const Eigen::RowVector3d tip_velocity = TipTravelRow(l);
  const Eigen::RowVector3d tip_rotation(1.0, 0.0, 1.0);

  LinearEquations<3> equations;
  equations.mass = arm.mass_per_length_kg_per_m * beam_mass +
                   arm.tip_mass_kg * tip_velocity.transpose() * tip_velocity +
                   arm.tip_inertia_kg_m2 * tip_rotation.transpose() * tip_rotation;
  equations.mass(0, 0) += arm.hub_inertia_kg_m2;
  equations.damping = arm.beam_damping_n_s_per_m2 * beam_damping;
  equations.damping(0, 0) += arm.hub_damping_n_m_s;
  equations.stiffness = arm.flexural_rigidity_n_m2 * beam_stiffness;
  equations.force = {arm.motor_torque_n_m, 0.0, 0.0};
  return equations;
}

Eigen::Matrix<double, 3, 2> OnTheWallBasis(double length_m) {
  Eigen::Matrix<double, 3, 2> basis;
  basis << -1.0 / length_m, 0.0,  //
      1.0, 0.0,                   //
      0.0, 1.0;
  return basis;
}

LinearEquations<2> OnTheWallEquations(const LinearEquations<3>& free, double length_m) {
  const Eigen::Matrix<double, 3, 2> basis = OnTheWallBasis(length_m);
  return {basis.transpose() * free.mass * basis, basis.transpose() * free.damping * basis,
          basis.transpose() * free.stiffness * basis, basis.transpose() * free.force};
}

}  // namespace beam_internal
}  // namespace impactlab
