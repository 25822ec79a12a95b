// An independent statement of the two-link arm's kinematics and Lagrangian,
// written from the geometry (multibody/two_link_model.h, two_link_parameters.h,
// docs/two-link.md eq. 8) without any of multibody/'s code: every material
// point's position in closed trigonometric form, differentiated twice by
// nested forward-mode dual numbers (ceres::Jet<ceres::Jet<double, 8>, 8>).
// From these the mass matrix M = sum m J^T J + sum I g g^T and the
// velocity-product forces of Lagrange's equations in Christoffel form,
//   h_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) v_j v_k,
// which the model's Kane assembly must reproduce.
#pragma once

#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include <ceres/jet.h>
#include <Eigen/Core>

#include "multibody/two_link_parameters.h"

namespace impactlab::testing {

inline constexpr int kQ = 8;  // q1..q6, theta_A, theta_B
using Vec8 = Eigen::Matrix<double, kQ, 1>;
using Mat8 = Eigen::Matrix<double, kQ, kQ>;
using Jet1 = ceres::Jet<double, kQ>;
using Jet2 = ceres::Jet<Jet1, kQ>;

// Gauss-Legendre with 4 nodes on [-1, 1], from the closed form
// +-sqrt(3/7 -+ 2/7 sqrt(6/5)), weights (18 +- sqrt(30))/36.
struct Gauss4 {
  std::array<double, 4> node, weight;
  Gauss4() {
    const double inner = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(6.0 / 5.0));
    const double outer = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(6.0 / 5.0));
    const double w_inner = (18.0 + std::sqrt(30.0)) / 36.0;
    const double w_outer = (18.0 - std::sqrt(30.0)) / 36.0;
    node = {-outer, -inner, inner, outer};
    weight = {w_outer, w_inner, w_inner, w_outer};
  }
};

// A constant as T (nested duals take no mixed arithmetic with double).
template <typename T>
struct ConstantOf {
  static T Make(double x) { return T(x); }
};
template <typename T, int N>
struct ConstantOf<ceres::Jet<T, N>> {
  static ceres::Jet<T, N> Make(double x) { return ceres::Jet<T, N>(ConstantOf<T>::Make(x)); }
};
template <typename T>
T K(double x) {
  return ConstantOf<T>::Make(x);
}

template <typename T>
struct P2 {
  T x, y;
};

// R(angle) (a, b).
template <typename T>
P2<T> Turned(const T& angle, const T& a, const T& b) {
  using std::cos;
  using std::sin;
  const T c = cos(angle), s = sin(angle);
  return {c * a - s * b, s * a + c * b};
}

template <typename T>
P2<T> operator+(const P2<T>& l, const P2<T>& r) {
  return {l.x + r.x, l.y + r.y};
}

// Hermite shapes of a cantilever in tip deflection and tip rotation.
inline double Phi2(double x, double length) {
  const double r = x / length;
  return 3.0 * r * r - 2.0 * r * r * r;
}
inline double Phi3(double x, double length) {
  return x * x * x / (length * length) - x * x / length;
}

// The arm's geometry as functions of q.
template <typename T>
struct Arm {
  const TwoLinkParameters& p;
  const std::array<T, kQ>& q;

  T Link1() const { return q[0]; }
  T Body2() const { return q[0] + q[2]; }
  T Link2() const { return q[0] + q[2] + q[3]; }
  T Tool() const { return q[0] + q[2] + q[3] + q[5]; }

  P2<T> Beam1(double x) const {
    return Turned<T>(
        Link1(), K<T>(p.beam1.hub_radius_m + x),
        K<T>(Phi2(x, p.beam1.length_m)) * q[1] + K<T>(Phi3(x, p.beam1.length_m)) * q[2]);
  }
  P2<T> JointB() const {
    return Turned<T>(Link1(), K<T>(p.beam1.hub_radius_m + p.beam1.length_m), q[1]);
  }
  P2<T> Beam2(double x) const {
    return JointB() + Turned<T>(Link2(), K<T>(p.beam2.hub_radius_m + x),
                                K<T>(Phi2(x, p.beam2.length_m)) * q[4] +
                                    K<T>(Phi3(x, p.beam2.length_m)) * q[5]);
  }
  // A point fixed in the tool's body, at (along, across) from beam 2's tip.
  P2<T> OnTool(double along, double across) const {
    return Beam2(p.beam2.length_m) + Turned<T>(Tool(), K<T>(along), K<T>(across));
  }
  P2<T> ToolCentre() const { return OnTool(p.tool.centre_m, 0.0); }
  P2<T> Tip() const { return OnTool(p.tool.centre_m + p.tool.tip_x_m, p.tool.tip_y_m); }
};

// Every scalar coordinate of the kinetic energy with its weight: each point
// mass's x and y (weight m), each rotor's angle (weight I).
template <typename T>
std::vector<std::pair<double, T>> WeightedCoordinates(const TwoLinkParameters& p,
                                                      const std::array<T, kQ>& q) {
  const Arm<T> arm{p, q};
  static const Gauss4 gauss;
  std::vector<std::pair<double, T>> out;
  auto point = [&](double mass, const P2<T>& r) {
    out.emplace_back(mass, r.x);
    out.emplace_back(mass, r.y);
  };
  for (int g = 0; g < 4; ++g) {
    const double x1 = 0.5 * p.beam1.length_m * (1.0 + gauss.node[g]);
    point(0.5 * p.beam1.length_m * gauss.weight[g] * p.beam1.mass_per_length_kg_per_m,
          arm.Beam1(x1));
    const double x2 = 0.5 * p.beam2.length_m * (1.0 + gauss.node[g]);
    point(0.5 * p.beam2.length_m * gauss.weight[g] * p.beam2.mass_per_length_kg_per_m,
          arm.Beam2(x2));
  }
  point(p.body2.mass_kg + p.hub3.mass_kg, arm.JointB());
  point(p.tool.body.mass_kg, arm.ToolCentre());
  out.emplace_back(p.hub1.inertia_kg_m2, arm.Link1());
  out.emplace_back(p.body2.inertia_kg_m2, arm.Body2());
  out.emplace_back(p.hub3.inertia_kg_m2, arm.Link2());
  out.emplace_back(p.tool.body.inertia_kg_m2, arm.Tool());
  out.emplace_back(p.drive_a.equivalent_inertia_kg_m2, q[6]);
  out.emplace_back(p.drive_b.equivalent_inertia_kg_m2, q[7]);
  return out;
}

// q as second-order dual numbers: value, first and second derivatives.
inline std::array<Jet2, kQ> Seed(const Vec8& q) {
  std::array<Jet2, kQ> out;
  for (int i = 0; i < kQ; ++i) {
    Jet1 value(q(i), i);  // q_i with d/dq = e_i
    out[i] = Jet2(value, i);
    // the outer derivative of q_i is the constant 1 (no second derivative)
    out[i].v[i] = Jet1(1.0);
  }
  return out;
}

// A scalar's value, gradient and Hessian from its second-order dual.
struct Derivatives {
  double value = 0.0;
  Vec8 gradient = Vec8::Zero();
  Mat8 hessian = Mat8::Zero();
};
inline Derivatives Unpack(const Jet2& f) {
  Derivatives d;
  d.value = f.a.a;
  for (int j = 0; j < kQ; ++j) {
    d.gradient(j) = f.a.v(j);
    for (int k = 0; k < kQ; ++k) d.hessian(j, k) = f.v(j).v(k);
  }
  return d;
}

// A point's position, Jacobian rows and the velocity-product part of its
// acceleration, sum_jk d2p/dq_j dq_k v_j v_k.
struct PointReference {
  Eigen::Vector2d position;
  Eigen::Matrix<double, 2, kQ> jacobian;
  Eigen::Vector2d velocity_product;
};
inline PointReference PointOf(const P2<Jet2>& r, const Vec8& v) {
  PointReference out;
  const Derivatives x = Unpack(r.x), y = Unpack(r.y);
  out.position = {x.value, y.value};
  out.jacobian.row(0) = x.gradient.transpose();
  out.jacobian.row(1) = y.gradient.transpose();
  out.velocity_product = {v.dot(x.hessian * v), v.dot(y.hessian * v)};
  return out;
}

// M(q) and h(q, v) from Lagrange's equations.
struct LagrangeReference {
  Mat8 mass = Mat8::Zero();
  Vec8 velocity_forces = Vec8::Zero();
};
inline LagrangeReference Lagrange(const TwoLinkParameters& p, const Vec8& q, const Vec8& v) {
  const std::array<Jet2, kQ> seeded = Seed(q);
  LagrangeReference out;
  // dM_ij/dq_k
  std::array<Mat8, kQ> dmass;
  for (Mat8& m : dmass) m.setZero();
  for (const auto& [weight, f] : WeightedCoordinates(p, seeded)) {
    const Derivatives d = Unpack(f);
    out.mass += weight * d.gradient * d.gradient.transpose();
    for (int k = 0; k < kQ; ++k) {
      const Vec8 column = d.hessian.col(k);
      dmass[k] += weight * (column * d.gradient.transpose() + d.gradient * column.transpose());
    }
  }
  for (int i = 0; i < kQ; ++i) {
    double h = 0.0;
    for (int j = 0; j < kQ; ++j) {
      for (int k = 0; k < kQ; ++k) {
        h += (dmass[k](i, j) - 0.5 * dmass[i](j, k)) * v(j) * v(k);
      }
    }
    out.velocity_forces(i) = h;
  }
  return out;
}

// The beams' strain energy with the closed-form cantilever stiffness
// E I [[12/L^3, -6/L^2], [-6/L^2, 4/L]] and the meshes' twist beyond the dead band.
inline Eigen::Matrix2d CantileverStiffness(const TwoLinkBeam& b) {
  const double l = b.length_m, ei = b.flexural_rigidity_n_m2;
  Eigen::Matrix2d k;
  k << 12.0 / (l * l * l), -6.0 / (l * l), -6.0 / (l * l), 4.0 / l;
  return ei * k;
}
inline double MeshTwist(double twist, double backlash) {
  if (twist > 0.5 * backlash) return twist - 0.5 * backlash;
  if (twist < -0.5 * backlash) return twist + 0.5 * backlash;
  return 0.0;
}
inline double PotentialReference(const TwoLinkParameters& p, const Vec8& q) {
  const Eigen::Vector2d b1(q(1), q(2)), b2(q(4), q(5));
  const double ta = MeshTwist(q(6) - q(0), p.drive_a.backlash_rad);
  const double tb = MeshTwist(q(7) - q(3), p.drive_b.backlash_rad);
  return 0.5 * b1.dot(CantileverStiffness(p.beam1) * b1) +
         0.5 * b2.dot(CantileverStiffness(p.beam2) * b2) +
         0.5 * p.drive_a.mesh_stiffness_n_m_per_rad * ta * ta +
         0.5 * p.drive_b.mesh_stiffness_n_m_per_rad * tb * tb;
}

// Motors, damping and backlash off: a conservative arm.
inline TwoLinkParameters ConservativeParameters() {
  TwoLinkParameters p = TwoLinkParameters::Nominal();
  for (TwoLinkDrive* d : {&p.drive_a, &p.drive_b}) {
    d->torque_constant_n_m_per_a = 0.0;
    d->back_emf_v_s_per_rad = 0.0;
    d->equivalent_damping_n_m_s = 0.0;
    d->mesh_damping_n_m_s = 0.0;
    d->backlash_rad = 0.0;
  }
  p.beam1.damping_n_s_per_m2 = 0.0;
  p.beam2.damping_n_s_per_m2 = 0.0;
  return p;
}

}  // namespace impactlab::testing
