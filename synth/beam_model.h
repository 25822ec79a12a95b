// The flexible arm of `impactlab synth-logs` (docs/logs.md, "The model"; the
// second source document, section 3): what it is made of, where its sensors
// sit, and the poles its motion has.
//
// A hub (angle theta, encoder q1) driven by a DC motor at constant voltage
// (torque tau0 - c_h theta'), a uniform flexible beam of length L clamped to
// it, and a rigid tip body (mass m_t, rotary inertia J_t). The beam's
// deflection in the rotating frame uses the paper's assumed modes (eq. 8):
//   w(x, t) = phi2(x) q2(t) + phi3(x) q3(t),
//   phi2 = 3 (x/L)^2 - 2 (x/L)^3   (q2: tip deflection),
//   phi3 = x^3 / L^2 - x^2 / L     (q3: tip slope),
// linearised (small deflection, no centrifugal stiffening), with viscous damping
// c_w per unit length on the deflection velocity (the paper's beam damping).
// Lagrange's equations give M p'' + C p' + K p = Q for p = (theta, q2, q3)
// (synth/beam_model_internal.h); synth/beam_simulation.h integrates them.
#pragma once

#include <string>

namespace impactlab {

struct BeamArm {
  double length_m = 0.9;                    // L
  double mass_per_length_kg_per_m = 0.405;  // aluminium 50 x 3 mm
  double flexural_rigidity_n_m2 = 5.32;     // EI: post-impact mode at 11.5 Hz
  double hub_inertia_kg_m2 = 0.05;          // hub, motor and gearbox, at the joint
  double tip_mass_kg = 0.5;                 // m_t
  double tip_inertia_kg_m2 = 2e-3;          // J_t about the tip
  double beam_damping_n_s_per_m2 = 0.1;     // c_w, per unit length
  double hub_damping_n_m_s = 2.0;           // c_h: back-EMF and gearbox, N m s/rad
  double motor_torque_n_m = 1.0;            // tau0, from the motor's start on
  double start_angle_rad = 0.9599;          // theta at rest (55 deg, the paper's Case 1)
  double wall_angle_rad = 1.8;              // theta_w: the tip touches the wall here
  double start_delay_s = 0.0;               // the motor starts this long after the log

  bool Check(std::string* error) const;
};

// Sensors: q1 = theta (incremental encoder on the motor, counts_per_rev x
// gear_ratio counts per joint turn); a1, the transverse acceleration at the
// beam's `a1_position`; a2, on the tip body `a2_inboard_m` inboard of the
// contact point. The noise and the ADC apply to the experiment only.
struct BeamSensors {
  double counts_per_rev = 4096.0;  // encoder, per motor turn
  double gear_ratio = 50.0;        // motor turns per joint turn
  double a1_sensitivity_v_per_g = 0.100;
  double a2_sensitivity_v_per_g = 0.005;
  double a1_noise_v = 2e-3;  // one-sigma, experiment only
  double a2_noise_v = 0.5e-3;
  double adc_lsb_v = 20.0 / 65536.0;  // 16 bits over +-10 V, experiment only
  double a1_position = 0.5;           // a1 at this fraction of L
  double a2_inboard_m = 0.04;         // a2 this far inboard of the contact point
};

// One pole of a phase: a damped mode (a complex pair) or, with frequency 0, an
// overdamped decay (a real pole). Each phase is linear with constant
// coefficients, so its poles, the roots of det(M s^2 + C s + K), are the truth.
struct BeamPole {
  double frequency_hz = 0.0;          // damped; 0 for a real pole
  double natural_frequency_hz = 0.0;  // |s| / 2 pi
  double damping_ratio = 0.0;         // -Re s / |s|; 1 for a real pole
  double decay_rate_per_s = 0.0;      // -Re s
};

}  // namespace impactlab
