// The planar two-link flexible manipulator of the second source document
// (docs/two-link.md): what it is made of, how it is driven, the surface its
// tool strikes and the sensors that watch it. All SI.
//
//   joint A (fixed) - hub RB1 - beam 1 - RB2 (carries motor B) = joint B
//   joint B - hub RB3 - beam 2 - RB4 (the tool)
//
// The surface is the line x = -surface.distance_m of the base frame (the
// document's "25 mm in the negative n1 direction"); the tool's tip touches it
// from x > -distance.
#pragma once

#include <string>

namespace impactlab {

struct TwoLinkBeam {
  double length_m = 0.0;                  // L, flexible length
  double hub_radius_m = 0.0;              // the beam's root is this far out from its joint
  double mass_per_length_kg_per_m = 0.0;  // rho A
  double flexural_rigidity_n_m2 = 0.0;    // E I
  double damping_n_s_per_m2 = 0.0;        // force per unit length per transverse velocity
};

struct TwoLinkBody {
  double mass_kg = 0.0;
  double inertia_kg_m2 = 0.0;  // about its centre of mass
};

// A DC motor and planetary gearbox, reduced to the gearbox output (eq. 27):
//   T = -J_eq s' - C_eq s + n K_t e_a / R - n^2 K_t K_b s / R,
// s the output speed. The output drives its link through a dead band of
// `backlash_rad` (total play) and a gear mesh of stiffness k_g and damping
// c_g while engaged. The encoder sits on the motor: it reads the output angle.
struct TwoLinkDrive {
  double gear_ratio = 1.0;                    // n
  double torque_constant_n_m_per_a = 0.0;     // K_t
  double back_emf_v_s_per_rad = 0.0;          // K_b
  double armature_resistance_ohm = 1.0;       // R
  double equivalent_inertia_kg_m2 = 0.0;      // J_eq, at the output
  double equivalent_damping_n_m_s = 0.0;      // C_eq, at the output
  double backlash_rad = 0.0;                  // total play at the output
  double mesh_stiffness_n_m_per_rad = 2.0e4;  // k_g
  double mesh_damping_n_m_s = 0.5;            // c_g

  // Stall torque per volt, n K_t / R, and the speed damping n^2 K_t K_b / R.
  double TorquePerVolt() const {
    return gear_ratio * torque_constant_n_m_per_a / armature_resistance_ohm;
  }
  double BackEmfDamping() const {
    return gear_ratio * gear_ratio * torque_constant_n_m_per_a * back_emf_v_s_per_rad /
           armature_resistance_ohm;
  }
};

struct TwoLinkTool {
  TwoLinkBody body;       // RB4
  double centre_m = 0.0;  // its centre of mass this far beyond beam 2's tip, along the beam
  double tip_x_m = 0.0;   // the contact tip from the centre of mass, along the beam ...
  double tip_y_m = 0.0;   // ... and across it
};

struct TwoLinkSurface {
  double distance_m = 0.025;          // the line x = -distance
  double friction_coefficient = 0.2;  // kinetic Coulomb mu
  double slip_velocity_m_s = 1e-3;  // friction is mu N v / sqrt(v^2 + v_s^2) (eq. 21, regularised)
  // The impact law (multibody/contact_impulse.h): e in [0, 1] (0: plastic,
  // the paper's), how it ends the impulse, and how friction acts during it.
  double restitution_coefficient = 0.0;
  std::string restitution_law = "energetic";    // "newton", "poisson" or "energetic"
  std::string impact_friction = "incremental";  // "incremental" or "paper"
};

// Where the sensors sit and what the experiment's logger adds.
struct TwoLinkSensors {
  double counts_per_rev = 1024.0;           // encoder counts per motor turn
  double beam_sensitivity_v_per_g = 0.100;  // mid-beam accelerometers (the document)
  double body_sensitivity_v_per_g = 0.005;  // on RB2 and RB4 (the document)
  double beam_noise_v = 2e-3;               // one-sigma, experiment only
  double body_noise_v = 0.5e-3;
  double adc_lsb_v = 20.0 / 65536.0;  // 16 bits over +-10 V, experiment only
  double sample_rate_hz = 1000.0;
};

// The proportional tip-position law of the sanding demonstration (case 3):
// the tip is commanded to x = -distance - press_depth_m, y = centre_y_m +
// amplitude_m sin(2 pi t / period_s); each joint's voltage is gain times its
// angle error (the encoder's angle against the inverse kinematics of the
// rigid arm), clipped to +-max_voltage_v.
struct TwoLinkSanding {
  double centre_y_m = 0.55;
  double amplitude_m = 0.15;
  double period_s = 2.0;
  double press_depth_m = 0.01;
  double gain_v_per_rad = 20.0;
  double max_voltage_v = 3.0;
};

// One experiment: the start configuration and what drives the joints.
struct TwoLinkCase {
  double q1_rad = 0.0;  // link 1's angle from the x axis
  double q4_rad = 0.0;  // link 2's angle from link 1 (the joint B angle)
  double voltage_a_v = 0.0;
  double voltage_b_v = 0.0;
  double start_delay_s = 0.0;  // the motors start this long after the log
  double duration_s = 5.0;
  bool sanding = false;  // drive by TwoLinkSanding instead of constant voltages
};

// The most samples a case may log (sample rate x duration): beyond it a
// record's memory, not the physics, is what limits.
inline constexpr double kTwoLinkMaxSamples = 2e6;

struct TwoLinkParameters {
  TwoLinkBeam beam1, beam2;
  TwoLinkBody hub1;   // RB1: turns about joint A (only its inertia matters)
  TwoLinkBody body2;  // RB2: at beam 1's tip, carrying motor B's stator
  TwoLinkBody hub3;   // RB3: turns about joint B
  TwoLinkTool tool;   // RB4
  TwoLinkDrive drive_a, drive_b;
  TwoLinkSurface surface;
  TwoLinkSensors sensors;
  TwoLinkSanding sanding;
  TwoLinkCase cases[3];  // the document's cases 1, 2 and 3

  // The document's three cases on a documented, plausible set of parts
  // (docs/two-link.md says which numbers are assumptions).
  static TwoLinkParameters Nominal();

  // False with a message naming the key when a value is out of range.
  bool Check(std::string* error) const;
};

}  // namespace impactlab
