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
  long max_steps = 0;           // integration steps; more is reported as too stiff (0: no limit)
  bool keep_state = true;       // the full state history per sample
};

struct TwoLinkEvent {
  double time_s = 0.0;
  std::string kind;      // "impact" or "separation"
  ImpactOutcome impact;  // for impacts
};

struct TwoLinkRecord {
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

  double FirstImpact() const;  // s; NaN-free: -1 when there was none
};

// Throws std::invalid_argument for bad options; std::domain_error for a tip
// that starts inside the surface or a motion the model cannot integrate (step
// collapse, chatter, loop closure), with the time.
TwoLinkRecord SimulateTwoLink(const TwoLinkModel& model, const TwoLinkCase& experiment,
                              const TwoLinkSimulationOptions& options = {});

// The joint voltages the case's drive law gives at time t for encoder angles
// (the motors are off before the start delay).
DriveVoltages CaseVoltages(const TwoLinkModel& model, const TwoLinkCase& experiment, double t_s,
                           double gearbox_a_rad, double gearbox_b_rad);

}  // namespace impactlab
