// The flexible arm's equations of motion (synth/beam_model.h) as matrices.
// Private to synth/: only .cpp files include it, so Eigen stays out of the
// public headers.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "synth/beam_model.h"

namespace impactlab::beam_internal {

// M q'' + C q' + K q = Q, constant coefficients, N generalised coordinates.
template <int N>
struct LinearEquations {
  Eigen::Matrix<double, N, N> mass;
  Eigen::Matrix<double, N, N> damping;
  Eigen::Matrix<double, N, N> stiffness;
  Eigen::Matrix<double, N, 1> force;
};

// The shape functions of eq. 8 at x = xi L: phi2 (q2, the tip deflection) and
// phi3 (q3, the tip slope).
double TipDeflectionShape(double xi);
double TipSlopeShape(double xi, double length_m);

// Free flight, p = (theta, q2, q3): Lagrange's equations, the shape-function
// integrals by 5-point Gauss-Legendre quadrature (exact for these polynomials).
// The motor's torque drives theta.
LinearEquations<3> FreeFlightEquations(const BeamArm& arm);

// The tip's travel towards the wall, G p = L theta + q2, G = (L, 1, 0): the tip
// mass moves at G p', and the tip touches the wall when G p = L theta_w.
Eigen::RowVector3d TipTravelRow(double length_m);

// The tip held on the wall (the paper's non-holonomic constraint), theta =
// theta_w - q2 / L: p = T r + (theta_w, 0, 0) for r = (q2, q3), with this T.
Eigen::Matrix<double, 3, 2> OnTheWallBasis(double length_m);

// The free-flight equations restricted to the wall: T^T M T r'' + ... = T^T Q.
LinearEquations<2> OnTheWallEquations(const LinearEquations<3>& free, double length_m);

// Poles of det(M s^2 + C s + K), each complex pair once, real poles with
// frequency 0 first, then modes by frequency; the rigid rotation's root at 0
// is no mode.
std::vector<BeamPole> Poles(const Eigen::MatrixXd& mass, const Eigen::MatrixXd& damping,
                            const Eigen::MatrixXd& stiffness);

}  // namespace impactlab::beam_internal
