#include "multibody/two_link_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impactlab {
namespace {

// Gauss-Legendre, 4 points on [-1, 1]: exact for the degree-6 integrands of
// the cubic shapes' kinetic energy.
constexpr std::array<double, 4> kGaussNodes = {-0.8611363115940526, -0.3399810435848563,
                                               0.3399810435848563, 0.8611363115940526};
constexpr std::array<double, 4> kGaussWeights = {0.3478548451374538, 0.6521451548625461,
                                                 0.6521451548625461, 0.3478548451374538};

// The document's assumed modes (eq. 8): tip deflection and tip rotation.
double TipDeflectionShape(double x, double length) {
  const double r = x / length;
  return r * r * (3.0 - 2.0 * r);
}
double TipRotationShape(double x, double length) { return x * x * (x / length - 1.0) / length; }
double TipDeflectionCurvature(double x, double length) {
  return 6.0 / (length * length) - 12.0 * x / (length * length * length);
}
double TipRotationCurvature(double x, double length) {
  return 6.0 * x / (length * length) - 2.0 / length;
}

TwoLinkRow Unit(int coordinate) {
  TwoLinkRow row = TwoLinkRow::Zero();
  row(coordinate) = 1.0;
  return row;
}

// The bodies' orientations, linear in q.
TwoLinkRow Link1Frame() { return Unit(kLink1Angle); }
TwoLinkRow Body2Frame() { return Unit(kLink1Angle) + Unit(kBeam1Rotation); }
TwoLinkRow Link2Frame() { return Body2Frame() + Unit(kLink2Angle); }
TwoLinkRow ToolFrame() { return Link2Frame() + Unit(kBeam2Rotation); }

// The beams' stiffness E I int phi_i'' phi_j'' and damping c int phi_i phi_j
// in their two coordinates, by the same Gauss rule (exact here).
void AddBeamMatrices(const TwoLinkBeam& beam, int first, TwoLinkMatrix* stiffness,
                     TwoLinkMatrix* damping) {
  for (int g = 0; g < 4; ++g) {
    const double x = 0.5 * beam.length_m * (1.0 + kGaussNodes[g]);
    const double w = 0.5 * beam.length_m * kGaussWeights[g];
    const Eigen::Vector2d curvature(TipDeflectionCurvature(x, beam.length_m),
                                    TipRotationCurvature(x, beam.length_m));
    const Eigen::Vector2d shape(TipDeflectionShape(x, beam.length_m),
                                TipRotationShape(x, beam.length_m));
    stiffness->block<2, 2>(first, first) +=
        w * beam.flexural_rigidity_n_m2 * curvature * curvature.transpose();
    damping->block<2, 2>(first, first) += w * beam.damping_n_s_per_m2 * shape * shape.transpose();
  }
}

}  // namespace

double DeadBandTwist(double twist_rad, double backlash_rad) {
  const double half = 0.5 * backlash_rad;
  if (twist_rad > half) return twist_rad - half;
  if (twist_rad < -half) return twist_rad + half;
  return 0.0;
}

TwoLinkModel::Point TwoLinkModel::BeamPoint(int beam, double x, double mass) const {
  const TwoLinkBeam& b1 = parameters_.beam1;
  const TwoLinkBeam& b2 = parameters_.beam2;
  Point point;
  point.mass = mass;
  Term& link1 = point.terms[0];
  link1.angle = Link1Frame();
  if (beam == 1) {
    link1.offset = {b1.hub_radius_m + x, 0.0};
    link1.shape(1, kBeam1Deflection) = TipDeflectionShape(x, b1.length_m);
    link1.shape(1, kBeam1Rotation) = TipRotationShape(x, b1.length_m);
    point.term_count = 1;
    return point;
  }
  link1.offset = {b1.hub_radius_m + b1.length_m, 0.0};
  link1.shape(1, kBeam1Deflection) = 1.0;
  Term& link2 = point.terms[1];
  link2.angle = Link2Frame();
  link2.offset = {b2.hub_radius_m + x, 0.0};
  link2.shape(1, kBeam2Deflection) = TipDeflectionShape(x, b2.length_m);
  link2.shape(1, kBeam2Rotation) = TipRotationShape(x, b2.length_m);
  point.term_count = 2;
  return point;
}

TwoLinkModel::TwoLinkModel(const TwoLinkParameters& parameters) : parameters_(parameters) {
  std::string error;
  if (!parameters_.Check(&error)) throw std::invalid_argument(error);
  const TwoLinkParameters& p = parameters_;

  int next = 0;
  for (int beam = 1; beam <= 2; ++beam) {
    const TwoLinkBeam& b = beam == 1 ? p.beam1 : p.beam2;
    for (int g = 0; g < 4; ++g) {
      const double x = 0.5 * b.length_m * (1.0 + kGaussNodes[g]);
      masses_[next++] =
          BeamPoint(beam, x, 0.5 * b.length_m * kGaussWeights[g] * b.mass_per_length_kg_per_m);
    }
  }
  // Joint B carries RB2 and RB3, both centred on it.
  Point joint_b = BeamPoint(2, 0.0, p.body2.mass_kg + p.hub3.mass_kg);
  joint_b.term_count = 1;
  masses_[next++] = joint_b;
  // The tool: beam 2's tip, then along RB4's own frame.
  Point tool = BeamPoint(2, p.beam2.length_m, p.tool.body.mass_kg);
  // (beam 2's shapes at its tip are 1 and 0: the tip deflection q5)
  tool.terms[2].angle = ToolFrame();
  tool.terms[2].offset = {p.tool.centre_m, 0.0};
  tool.term_count = 3;
  masses_[next++] = tool;

  tip_ = tool;
  tip_.mass = 0.0;
  tip_.terms[2].offset = {p.tool.centre_m + p.tool.tip_x_m, p.tool.tip_y_m};

  rotors_ = {Rotor{Link1Frame(), p.hub1.inertia_kg_m2},
             Rotor{Body2Frame(), p.body2.inertia_kg_m2},
             Rotor{Link2Frame(), p.hub3.inertia_kg_m2},
             Rotor{ToolFrame(), p.tool.body.inertia_kg_m2},
             Rotor{Unit(kGearboxAAngle), p.drive_a.equivalent_inertia_kg_m2},
             Rotor{Unit(kGearboxBAngle), p.drive_b.equivalent_inertia_kg_m2}};

  sensors_ = {BeamPoint(1, 0.5 * p.beam1.length_m, 0.0), joint_b,
              BeamPoint(2, 0.5 * p.beam2.length_m, 0.0), tool};
  sensor_axes_ = {Link1Frame(), Body2Frame(), Link2Frame(), ToolFrame()};

  AddBeamMatrices(p.beam1, kBeam1Deflection, &stiffness_, &damping_);
  AddBeamMatrices(p.beam2, kBeam2Deflection, &stiffness_, &damping_);
}

PointMotion TwoLinkModel::Motion(const Point& point, const TwoLinkVector& q,
                                 const TwoLinkVector& v) const {
  PointMotion motion;
  for (int k = 0; k < point.term_count; ++k) {
    const Term& term = point.terms[k];
    const double angle = term.angle.dot(q);
    const double rate = term.angle.dot(v);
    const double c = std::cos(angle), s = std::sin(angle);
    Eigen::Matrix2d rotation;
    rotation << c, -s, s, c;
    const Eigen::Vector2d local = term.offset + term.shape * q;
    const Eigen::Vector2d local_rate = term.shape * v;
    const Eigen::Vector2d turned(-local.y(), local.x());                 // S s
    const Eigen::Vector2d turned_rate(-local_rate.y(), local_rate.x());  // S s'
    motion.position += rotation * local;
    motion.jacobian += rotation * (turned * term.angle + term.shape);
    motion.velocity_product += rotation * (-rate * rate * local + 2.0 * rate * turned_rate);
  }
  return motion;
}

void TwoLinkModel::Inertia(const TwoLinkVector& q, const TwoLinkVector& v, TwoLinkMatrix* mass,
                           TwoLinkVector* velocity_forces) const {
  mass->setZero();
  velocity_forces->setZero();
  for (const Point& point : masses_) {
    const PointMotion m = Motion(point, q, v);
    mass->noalias() += point.mass * m.jacobian.transpose() * m.jacobian;
    velocity_forces->noalias() += point.mass * m.jacobian.transpose() * m.velocity_product;
  }
  for (const Rotor& rotor : rotors_) {
    mass->noalias() += rotor.inertia * rotor.angle.transpose() * rotor.angle;
  }
}

TwoLinkVector TwoLinkModel::AppliedForces(const TwoLinkVector& q, const TwoLinkVector& v,
                                          const DriveVoltages& voltages) const {
  TwoLinkVector forces = -stiffness_ * q - damping_ * v;
  auto drive = [&](const TwoLinkDrive& d, int gearbox, int joint, double voltage) {
    const double twist = DeadBandTwist(q(gearbox) - q(joint), d.backlash_rad);
    // The mesh's damping builds up over the first kMeshEngagementRad of
    // engagement, so that the force stays continuous where the teeth meet.
    const double engagement =
        d.backlash_rad == 0.0 ? 1.0 : std::min(1.0, std::abs(twist) / kMeshEngagementRad);
    const double mesh = d.mesh_stiffness_n_m_per_rad * twist +
                        engagement * d.mesh_damping_n_m_s * (v(gearbox) - v(joint));
    forces(gearbox) += d.TorquePerVolt() * voltage -
                       (d.BackEmfDamping() + d.equivalent_damping_n_m_s) * v(gearbox) - mesh;
    forces(joint) += mesh;
  };
  drive(parameters_.drive_a, kGearboxAAngle, kLink1Angle, voltages.a_v);
  drive(parameters_.drive_b, kGearboxBAngle, kLink2Angle, voltages.b_v);
  return forces;
}

PointMotion TwoLinkModel::Tip(const TwoLinkVector& q, const TwoLinkVector& v) const {
  return Motion(tip_, q, v);
}

double TwoLinkModel::Gap(const TwoLinkVector& q) const {
  return Motion(tip_, q, TwoLinkVector::Zero()).position.x() + parameters_.surface.distance_m;
}

PointMotion TwoLinkModel::Sensor(TwoLinkSensor sensor, const TwoLinkVector& q,
                                 const TwoLinkVector& v) const {
  return Motion(sensors_[static_cast<int>(sensor)], q, v);
}

double TwoLinkModel::SensorAxisAngle(TwoLinkSensor sensor, const TwoLinkVector& q) const {
  return sensor_axes_[static_cast<int>(sensor)].dot(q) + 0.5 * M_PI;
}

double TwoLinkModel::KineticEnergy(const TwoLinkVector& q, const TwoLinkVector& v) const {
  TwoLinkMatrix mass;
  TwoLinkVector unused;
  Inertia(q, v, &mass, &unused);
  return 0.5 * v.dot(mass * v);
}

double TwoLinkModel::PotentialEnergy(const TwoLinkVector& q) const {
  auto mesh = [&](const TwoLinkDrive& d, int gearbox, int joint) {
    const double twist = DeadBandTwist(q(gearbox) - q(joint), d.backlash_rad);
    return 0.5 * d.mesh_stiffness_n_m_per_rad * twist * twist;
  };
  return 0.5 * q.dot(stiffness_ * q) + mesh(parameters_.drive_a, kGearboxAAngle, kLink1Angle) +
         mesh(parameters_.drive_b, kGearboxBAngle, kLink2Angle);
}

}  // namespace impactlab
