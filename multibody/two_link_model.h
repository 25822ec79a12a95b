// The two-link manipulator's equations of motion (docs/two-link.md, "The
// equations"), by Kane's method on a set of material points.
//
// Generalized coordinates q (TwoLinkCoordinate): the document's q1 (link 1's
// angle), q2, q3 (beam 1's tip deflection and tip rotation), q4 (link 2's
// angle from RB2), q5, q6 (beam 2's), and the two gearbox output angles
// theta_A (absolute) and theta_B (from RB2), which differ from q1 and q4 by
// the backlash and the mesh's twist.
//
// Every body's orientation is linear in q (link 1: q1; RB2: q1 + q3; RB3 and
// beam 2's frame: q1 + q3 + q4; RB4: that + q6), and every point is a chain of
// terms R(alpha) s with s linear in q: a beam point at x is R(q1) (r1 + x,
// phi2(x) q2 + phi3(x) q3) (eq. 8). The rotations are kept exact; the beams'
// deflections are linear in their frames (no axial shortening, no rotary
// inertia of the slices). For such a chain the velocity is J(q) q' and the
// acceleration J q'' + a0(q, q') with, per term,
//   J  += R (S s grad(alpha)^T + ds/dq),  a0 += R (-alpha'^2 s + 2 alpha' S s'),
// S the quarter turn. Kane's equations are then
//   M(q) q'' = Q(q, q', t) - h(q, q'),   M = sum m J^T J + sum I g g^T,
//   h = sum m J^T a0,
// over the beams' Gauss points (exact for the cubic shapes) and the rigid
// bodies. tests/multibody checks M and h against Lagrange's equations from
// automatically differentiated energies.
#pragma once

#include <array>

#include <Eigen/Core>

#include "multibody/two_link_parameters.h"

namespace impactlab {

enum TwoLinkCoordinate : int {
  kLink1Angle = 0,   // q1
  kBeam1Deflection,  // q2
  kBeam1Rotation,    // q3
  kLink2Angle,       // q4
  kBeam2Deflection,  // q5
  kBeam2Rotation,    // q6
  kGearboxAAngle,    // theta_A
  kGearboxBAngle,    // theta_B
  kTwoLinkCoordinates
};

using TwoLinkVector = Eigen::Matrix<double, kTwoLinkCoordinates, 1>;
using TwoLinkMatrix = Eigen::Matrix<double, kTwoLinkCoordinates, kTwoLinkCoordinates>;
using TwoLinkRow = Eigen::Matrix<double, 1, kTwoLinkCoordinates>;

// A point's motion: position, velocity Jacobian and the velocity-product part
// of its acceleration (a = J q'' + a0).
struct PointMotion {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, kTwoLinkCoordinates> jacobian =
      Eigen::Matrix<double, 2, kTwoLinkCoordinates>::Zero();
  Eigen::Vector2d velocity_product = Eigen::Vector2d::Zero();
};

// The accelerometers, in the document's order (Figures 7-10).
enum class TwoLinkSensor : int { kBeam1Middle = 0, kBody2, kBeam2Middle, kTool };
inline constexpr int kTwoLinkAccelerometers = 4;

// The joint torques a drive law asks for, as armature voltages.
struct DriveVoltages {
  double a_v = 0.0;
  double b_v = 0.0;
};

class TwoLinkModel {
 public:
  // Throws std::invalid_argument when the parameters fail their Check().
  explicit TwoLinkModel(const TwoLinkParameters& parameters);

  const TwoLinkParameters& parameters() const { return parameters_; }

  // M(q) and h(q, q').
  void Inertia(const TwoLinkVector& q, const TwoLinkVector& v, TwoLinkMatrix* mass,
               TwoLinkVector* velocity_forces) const;

  // Everything but inertia and contact: the beams' stiffness and damping, the
  // gear meshes (dead band, stiffness, damping) and the motors at the given
  // voltages (eq. 27).
  TwoLinkVector AppliedForces(const TwoLinkVector& q, const TwoLinkVector& v,
                              const DriveVoltages& voltages) const;

  // The tool's contact tip; the surface gap n . (tip - surface) and its
  // normal (x) and tangential (y) rows of the Jacobian.
  PointMotion Tip(const TwoLinkVector& q, const TwoLinkVector& v) const;
  double Gap(const TwoLinkVector& q) const;

  // An accelerometer's point and its sensing direction (its body's transverse
  // axis, the document's b_i2).
  PointMotion Sensor(TwoLinkSensor sensor, const TwoLinkVector& q, const TwoLinkVector& v) const;
  double SensorAxisAngle(TwoLinkSensor sensor, const TwoLinkVector& q) const;

  // Energies: kinetic 1/2 q'^T M q', and potential (beams' strain and the
  // gear meshes' twist beyond the dead band).
  double KineticEnergy(const TwoLinkVector& q, const TwoLinkVector& v) const;
  double PotentialEnergy(const TwoLinkVector& q) const;

  // The beams' stiffness and damping matrices (constant).
  const TwoLinkMatrix& stiffness() const { return stiffness_; }
  const TwoLinkMatrix& beam_damping() const { return damping_; }

 private:
  struct Term {
    TwoLinkRow angle = TwoLinkRow::Zero();  // alpha = angle . q
    Eigen::Vector2d offset = Eigen::Vector2d::Zero();
    Eigen::Matrix<double, 2, kTwoLinkCoordinates> shape =
        Eigen::Matrix<double, 2, kTwoLinkCoordinates>::Zero();  // s = offset + shape q
  };
  struct Point {
    std::array<Term, 3> terms;
    int term_count = 0;
    double mass = 0.0;
  };
  struct Rotor {
    TwoLinkRow angle = TwoLinkRow::Zero();
    double inertia = 0.0;
  };

  PointMotion Motion(const Point& point, const TwoLinkVector& q, const TwoLinkVector& v) const;
  Point BeamPoint(int beam, double x, double mass) const;

  TwoLinkParameters parameters_;
  std::array<Point, 10> masses_;  // 4 Gauss points per beam, joint B (RB2 + RB3), the tool
  Point tip_;                     // the tool's contact tip
  std::array<Rotor, 6> rotors_;   // RB1..RB4 and the two gearboxes' equivalent inertia
  std::array<Point, kTwoLinkAccelerometers> sensors_;
  std::array<TwoLinkRow, kTwoLinkAccelerometers> sensor_axes_;
  TwoLinkMatrix stiffness_ = TwoLinkMatrix::Zero();
  TwoLinkMatrix damping_ = TwoLinkMatrix::Zero();
};

// The twist over which a gear mesh's damping builds up after the teeth meet.
inline constexpr double kMeshEngagementRad = 1e-4;

// The dead band's transmitted twist: 0 inside +-backlash/2, else the twist
// beyond it.
double DeadBandTwist(double twist_rad, double backlash_rad);

}  // namespace impactlab
