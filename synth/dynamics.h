// Internal to synth/: the equations of motion of the two pendula, their contact
// element and the support-wire forcing, as one right-hand side for the ODE
// integrator. The phase logic (which bars are held, whether they touch, which
// wire sawtooth is in which cycle) lives in experiment.cpp; this class only
// evaluates the equations of the current phase, so that each phase is smooth.
//
// State y (6 doubles):
//   y[0] theta_R  (rad)    y[1] theta_R' (rad/s)
//   y[2] theta_L  (rad)    y[3] theta_L' (rad/s)
//   y[4] x2, the Poynting-Thomson internal node of one contact element (length)
//   y[5] energy dissipated in the dashpots since contact began (force*length)
//
// Each pendulum: theta'' = -(g/L) sin(theta) + F_h cos(theta) / (M L), with
// F_h the horizontal force on the bar (positive away from the other bar) and
// X = L sin(theta) positive away from equilibrium.
#pragma once

#include <array>
#include <vector>

namespace impactlab::synth_detail {

using State = std::array<double, 6>;

enum Bar : int { kRight = 0, kLeft = 1 };

struct BarModel {
  double length = 0.0;  // L, length units
  double mass = 0.0;    // M, mass units
  bool present = true;  // false for the left bar of the wall arrangement
};

// The contact element of ONE bar face (thesis: mass M against a fixed plane).
// Kelvin-Voigt is the Poynting-Thomson element with k2 = 0 read as
// F = k1 x + c x' (flag below).
struct ContactElement {
  bool poynting_thomson = false;
  double k1 = 0.0;  // K (Kelvin-Voigt) or K1 (Poynting-Thomson), force/length
  double k2 = 0.0;  // K2 (Poynting-Thomson only), force/length
  double c = 0.0;   // C, force*time/length
};

// One impact's support-wire forcing on one bar (thesis eq. 104, summed over
// the bar's wires): F_h(t) = -amplitude * S(omega (t - start)) * exp(-(t - start) decay_rate)
// with S the sawtooth sum_n sin(n phi)/n = (pi - phi)/2 on 0 < phi < 2 pi.
// S jumps by pi at each phi = 2 pi k; `cycle` is the k of the current smooth
// segment, so that S stays a smooth function of t inside a segment.
struct Sawtooth {
  int bar = kRight;
  double start_s = 0.0;     // moment of contact, s
  double amplitude = 0.0;   // wires * (2 v / pi) sqrt(rho V), force units
  double omega = 0.0;       // pi a / l, rad/s
  double decay_rate = 0.0;  // 1 / decay time, 1/s (0: undamped, as the thesis)
  long cycle = 0;           // k: S = (pi - (phi - 2 pi k)) / 2 in this segment

  double NextJumpTime() const;  // start of cycle k + 1, s
  double Force(double t) const;
};

class Dynamics {
 public:
  double gravity = 0.0;             // g, length/s^2
  std::array<BarModel, 2> bars;     // right, left
  std::array<bool, 2> held{};       // held by its magnet: does not move
  bool in_contact = false;          // the contact element acts
  int elements = 2;                 // faces in series: 2 (pair), 1 (wall)
  ContactElement element;           //
  std::vector<Sawtooth> sawtooths;  // active wire forcing

  void operator()(const State& y, State& dydt, double t) const;

  // Horizontal displacement X = L sin(theta) and its rate of one bar.
  double Displacement(const State& y, int bar) const;
  double Velocity(const State& y, int bar) const;
  // Overlap delta of the faces (> 0 when they interpenetrate) and its rate:
  // -(X_R + X_L) for the pair, -X_R against the wall.
  double Overlap(const State& y) const;
  double OverlapRate(const State& y) const;
  // Force of the contact element (positive pushes the bars apart), whether or
  // not the contact phase is on: F = element law at x = delta / elements.
  double ContactForce(const State& y) const;
  // Kinetic plus gravitational energy of the pendula (force*length); 1 - cos
  // written as 2 sin^2(theta/2).
  double MechanicalEnergy(const State& y) const;
  // Energy stored in the contact elements (all faces), force*length.
  double ElasticEnergy(const State& y) const;
  // Rate at which the dashpots dissipate energy (all faces), force*length/s.
  double DissipationRate(const State& y) const;
};

}  // namespace impactlab::synth_detail
