// `impactlab synth-logs`: encoder and accelerometer logs of a flexible arm whose
// tip strikes a wall, as an experiment/simulation pair with exact truth
// (docs/logs.md, "Sample data"; the second source document, section 3).
//
// The arm: a hub (angle theta, encoder q1) driven by a DC motor at constant
// voltage (torque tau0 - c_h theta'), a uniform flexible beam of length L
// clamped to it, and a rigid tip body (mass m_t, rotary inertia J_t). The beam's
// deflection in the rotating frame uses the paper's assumed modes (eq. 8):
//   w(x, t) = phi2(x) q2(t) + phi3(x) q3(t),
//   phi2 = 3 (x/L)^2 - 2 (x/L)^3   (q2: tip deflection),
//   phi3 = x^3 / L^2 - x^2 / L     (q3: tip slope),
// linearised (small deflection, no centrifugal stiffening), with viscous damping
// c_w per unit length on the deflection velocity (the paper's beam damping).
// Lagrange's equations give M p'' + C p' + K p = Q for p = (theta, q2, q3), the
// integrals over the shape functions by Gauss-Legendre quadrature (exact here).
//
// Free flight until the tip reaches the wall, s = L (theta - theta_w) + q2 = 0.
// The impact is perfectly plastic and the tip then stays on the wall, the
// paper's non-holonomic constraint: the post-impact velocity is the projection
// p'+ = p'- - M^-1 G^T (G M^-1 G^T)^-1 G p'-, G = (L, 1, 0), and the motion
// continues in (q2, q3) with theta = theta_w - q2 / L. Each phase is linear with
// constant coefficients, so its modes (frequencies, damping ratios) are the
// roots of det(M s^2 + C s + K) - the truth. The response is integrated by RK4
// with 20 steps per sample (relative error ~1e-8), the impact instant bracketed
// and bisected to 1e-13 s.
//
// Sensors: q1 = theta (incremental encoder on the motor, counts_per_rev x
// gear_ratio counts per joint turn); a1, the transverse acceleration at the
// beam's mid-point (100 mV/g); a2, on the tip body `a2_inboard_m` inboard of the
// contact point (5 mV/g). An accelerometer sample is the mean acceleration over
// the sample interval before it (an integrating anti-alias filter: the change
// of the sensor's velocity over the interval), so the impact's impulse shows as
// one sample's spike of (velocity jump) / dt, as a real accelerometer sees the
// short contact. Sample k is at t = k / rate. The experiment has Gaussian
// voltage noise, a 16-bit ADC, integer counts and its own parameters (a
// heavier tip body, more motor friction, a later start); the simulation is the
// nominal model in SI, clean.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

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
// overdamped decay (a real pole).
struct BeamMode {
  double frequency_hz = 0.0;          // damped; 0 for a real pole
  double natural_frequency_hz = 0.0;  // |s| / 2 pi
  double damping_ratio = 0.0;         // -Re s / |s|; 1 for a real pole
  double decay_rate_per_s = 0.0;      // -Re s
};

// A clean record of one arm, in SI.
struct BeamRecord {
  std::vector<double> time_s, angle_rad, a1_m_s2, a2_m_s2;
  double impact_time_s = 0.0;
  double impact_speed_m_s = 0.0;     // tip speed into the wall
  double min_contact_force_n = 0.0;  // after the impact; < 0 would mean the tip pulls
  std::vector<BeamMode> free_modes;  // free flight: real poles, then modes by frequency
  std::vector<BeamMode> post_modes;  // tip on the wall, the same
  // Per channel (angle, a1, a2) and post-impact pole: amplitude at the first
  // sample whose interval lies after the impact, SI.
  std::vector<std::vector<double>> post_mode_amplitudes;
};

BeamRecord SimulateBeam(const BeamArm& arm, const BeamSensors& sensors, double sample_rate_hz,
                        double duration_s);

struct BeamLogOptions {
  std::uint64_t seed = 1;  // noise; the same seed writes the same bytes
  double sample_rate_hz = 1000.0;
  double duration_s = 5.0;
  BeamArm simulation;  // the nominal model
  // The experiment: the nominal arm with these differences.
  double experiment_tip_inertia_factor = 1.26;  // heavier tip body: 10.9 Hz
  double experiment_hub_damping_factor = 1.02;  // more friction: slower, later impact
  double experiment_start_delay_s = 0.042;      // the logger started before the motor
  BeamSensors sensors;
  double noise_factor = 1.0;    // scales both accelerometer noises
  bool inject_defects = false;  // a NaN, a duplicated and a missing row in the experiment
  std::string log_id = "case1";

  bool Check(std::string* error) const;
};

struct BeamLogSummary {
  int rows = 0;  // per file
  double experiment_impact_s = 0.0;
  double simulation_impact_s = 0.0;
  nlohmann::json truth;  // schema "impactlab-logs-truth" 1 (docs/logs.md)
};

// Writes `folder`/session.toml and `folder`/logs/<id>-{experiment,simulation}.csv.
// The folder must not exist or be empty. Throws std::invalid_argument for bad
// options, InputError for a folder that cannot be written.
BeamLogSummary GenerateBeamLogs(const std::filesystem::path& folder, const BeamLogOptions& options);

// The experiment's arm for the options.
BeamArm ExperimentArm(const BeamLogOptions& options);

}  // namespace impactlab
