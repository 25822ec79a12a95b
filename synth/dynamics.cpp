#include "synth/dynamics.h"

#include <cmath>
#include <numbers>

namespace impactlab::synth_detail {

using std::numbers::pi;

double Sawtooth::NextJumpTime() const {
  return start_s + 2.0 * pi * static_cast<double>(cycle + 1) / omega;
}

double Sawtooth::Force(double t) const {
  const double since_contact = t - start_s;
  if (since_contact < 0.0) return 0.0;
  const double phase = omega * since_contact - 2.0 * pi * static_cast<double>(cycle);
  const double decay = decay_rate > 0.0 ? std::exp(-decay_rate * since_contact) : 1.0;
  return -amplitude * 0.5 * (pi - phase) * decay;
}

double Dynamics::Displacement(const State& y, int bar) const {
  if (!bars[bar].present) return 0.0;
  return bars[bar].length * std::sin(y[2 * bar]);
}

double Dynamics::Velocity(const State& y, int bar) const {
  if (!bars[bar].present) return 0.0;
  return bars[bar].length * std::cos(y[2 * bar]) * y[2 * bar + 1];
}

double Dynamics::Overlap(const State& y) const {
  return -(Displacement(y, kRight) + Displacement(y, kLeft));
}

double Dynamics::OverlapRate(const State& y) const {
  return -(Velocity(y, kRight) + Velocity(y, kLeft));
}

double Dynamics::ContactForce(const State& y) const {
  // Identical faces in series carry the same force from the same (zero)
  // initial state, so each compresses by delta / elements.
  const double x = Overlap(y) / elements;
  if (element.poynting_thomson) return element.k1 * x + element.k2 * (x - y[4]);
  const double x_rate = OverlapRate(y) / elements;
  return element.k1 * x + element.c * x_rate;
}

double Dynamics::MechanicalEnergy(const State& y) const {
  double energy = 0.0;
  for (int bar : {kRight, kLeft}) {
    if (!bars[bar].present) continue;
    const double m = bars[bar].mass;
    const double l = bars[bar].length;
    const double speed = l * y[2 * bar + 1];  // tangential
    const double half_sin = std::sin(0.5 * y[2 * bar]);
    energy += 0.5 * m * speed * speed + 2.0 * m * gravity * l * half_sin * half_sin;
  }
  return energy;
}

double Dynamics::ElasticEnergy(const State& y) const {
  const double x = Overlap(y) / elements;
  double per_face = 0.5 * element.k1 * x * x;
  if (element.poynting_thomson) per_face += 0.5 * element.k2 * (x - y[4]) * (x - y[4]);
  return elements * per_face;
}

double Dynamics::DissipationRate(const State& y) const {
  if (element.poynting_thomson) {
    // Dashpot force K2 (x1 - x2) = C x2': power C x2'^2 = K2^2 (x1 - x2)^2 / C.
    const double stretch = Overlap(y) / elements - y[4];
    return elements * element.k2 * element.k2 * stretch * stretch / element.c;
  }
  const double x_rate = OverlapRate(y) / elements;
  return elements * element.c * x_rate * x_rate;
}

void Dynamics::operator()(const State& y, State& dydt, double t) const {
  std::array<double, 2> horizontal_force{0.0, 0.0};
  if (in_contact) {
    const double f = ContactForce(y);
    horizontal_force = {f, f};
  }
  for (const Sawtooth& s : sawtooths) horizontal_force[s.bar] += s.Force(t);

  for (int bar : {kRight, kLeft}) {
    const int i = 2 * bar;
    if (held[bar] || !bars[bar].present) {
      dydt[i] = 0.0;
      dydt[i + 1] = 0.0;
      continue;
    }
    const double l = bars[bar].length;
    dydt[i] = y[i + 1];
    dydt[i + 1] = -(gravity / l) * std::sin(y[i]) +
                  horizontal_force[bar] * std::cos(y[i]) / (bars[bar].mass * l);
  }
  if (in_contact && element.poynting_thomson) {
    // C x2' = K2 (x1 - x2) (thesis eq. 45).
    dydt[4] = element.k2 * (Overlap(y) / elements - y[4]) / element.c;
  } else {
    dydt[4] = 0.0;
  }
  dydt[5] = in_contact ? DissipationRate(y) : 0.0;
}

}  // namespace impactlab::synth_detail
