// The manipulator in motion through its regimes (docs/two-link.md,
// "Simulation"): free flight until the tool's tip reaches the surface
// (located as a root of the gap), the impact (multibody/two_link_dynamics.h),
// constrained motion with q4 (or q1) from the loop closure after every step,
// separation where the normal force would turn tensile, re-impact.
//
// One Dormand-Prince 5(4) integrator (model/ode_integrator.h) carries the
// state (q, q'); the motors' start is a known discontinuity the steps land
// on; events are refined on fresh single steps to a few ulps. Samples come
// from the dense output at k / sample_rate; an accelerometer sample is the
// mean acceleration along its axis over the interval before it (the velocity
// change over the interval, as an integrating anti-alias filter sees it), so
// an impact shows as one sample's spike.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "multibody/two_link_dynamics.h"
#include "multibody/two_link_model.h"

namespace impactlab {

struct TwoLinkSimulationOptions {
  double relative_tolerance = 1e-8;  // bench_two_link: angles to ~2e-9 rad, a1 to ~2e-3 m/s^2
  double absolute_tolerance = 1e-11;
  double max_step_s = 2e-3;
  double sample_rate_hz = 0.0;  // 0: the parameters' sensors.sample_rate_hz
  double duration_s = 0.0;      // 0: the case's
  int max_events = 10000;       // impacts and separations; more is reported as chatter
  // Impacts approaching slower than this are plastic whatever the surface's
  // restitution, so that rebounds that accumulate (a Zeno sequence) end in
  // persistent contact rather than at the event cap.
  double plastic_below_m_s = 1e-4;
  // Integration steps, and seconds of computing, after which the motion is
  // refused as too stiff for this explicit integrator, with the model's
  // fastest rate named. 0: 50 000 steps + 40 000 per simulated second (the
  // nominal cases take 3 500-7 000 per second), and 2 s + 0.5 s per
  // simulated second (they take under 0.1 s per second).
  long max_steps = 0;
  double max_wall_seconds = 0.0;
  // A beam tip deflected beyond this share of its length is refused, and
  // beyond the second warned: the model's deflections are linear. (The
  // nominal cases peak at 0.10, when the motors start.)
  double max_deflection_ratio = 0.3;
  double warn_deflection_ratio = 0.2;
  bool keep_state = true;  // the full state history per sample
};

struct TwoLinkEvent {
  double time_s = 0.0;
  std::string kind;      // "impact" or "separation"
  ImpactOutcome impact;  // for impacts
};

// The energy's ledger over a simulation: the kinetic energy plus what the
// beams and gear meshes store elastically, at the start and at the end, and
// every work that changed it. Its imbalance is the integration's error
// (docs/two-link.md, "Energy").
struct TwoLinkEnergy {
  double initial_j = 0.0, final_j = 0.0;
  // The integral of q'^T Q over the motion, Q the forces that are not a
  // potential's: the motors' torques, back-EMF braking and the beams', gears'
  // and drives' damping.
  double drives_and_damping_j = 0.0;
  // The surface's force in constrained motion: sliding friction (never
  // positive) and the normal force's work on the tip's residual normal speed.
  double surface_j = 0.0;
  double impacts_j = 0.0;       // the impulses' work, normal and friction
  double projections_j = 0.0;   // the loop closure's projections onto the surface (numerical)
  double peak_kinetic_j = 0.0;  // the largest kinetic energy at a sample

  double Imbalance() const {
    return final_j - initial_j - drives_and_damping_j - surface_j - impacts_j - projections_j;
  }
};

struct TwoLinkRecord {
  // false: the motion was refused part way (or before it started); `reason`
  // says why, with the time and the cause; the samples and events are what
  // was simulated up to there (the energy's ledger is whole only when ok).
  bool ok = true;
  std::string reason;
  std::vector<double> time_s;
  std::vector<double> gearbox_a_rad, gearbox_b_rad;  // what the encoders read (output side)
  std::array<std::vector<double>, kTwoLinkAccelerometers> acceleration_m_s2;
  // The full state per sample (keep_state), the regime and the surface's force.
  std::vector<TwoLinkVector> position, velocity;
  std::vector<int> in_contact;
  std::vector<double> normal_force_n, friction_force_n, tip_x_m, tip_y_m, voltage_a_v, voltage_b_v;
  std::vector<TwoLinkEvent> events;
  double max_loop_closure_m = 0.0;  // largest |gap| at constrained samples
  long steps = 0;
  long rhs_evaluations = 0;
  double max_deflection_ratio = 0.0;  // the largest |beam tip deflection| / length
  std::vector<std::string> warnings;  // where the model's assumptions were stretched
  TwoLinkEnergy energy;

  double FirstImpact() const;  // s; NaN-free: -1 when there was none
};

// Throws std::invalid_argument for bad options. A tip that starts inside the
// surface, or a motion the model cannot integrate (step collapse, a state
// that leaves the finite numbers, a step or time budget spent, a beam
// deflected beyond the small-deflection model, chatter, loop closure, a
// frictional jam), is a record with !ok, the reason naming the time and the
// cause, and what was simulated before it.
TwoLinkRecord SimulateTwoLink(const TwoLinkModel& model, const TwoLinkCase& experiment,
                              const TwoLinkSimulationOptions& options = {});

// The joint voltages the case's drive law gives at time t for encoder angles
// (the motors are off before the start delay).
DriveVoltages CaseVoltages(const TwoLinkModel& model, const TwoLinkCase& experiment, double t_s,
                           double gearbox_a_rad, double gearbox_b_rad);

}  // namespace impactlab
