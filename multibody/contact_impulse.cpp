#include "multibody/contact_impulse.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/LU>

namespace impactlab {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double Sign(double x) { return x > 0.0 ? 1.0 : -1.0; }

// The work of each component over an impulse taken along a straight line
// from 0 to P, during which u goes linearly from u- to u+: P_i (u-_i + u+_i)/2.
void StraightPathWork(ContactImpulse* out, const Eigen::Vector2d& before) {
  out->normal_work_j = out->impulse(0) * 0.5 * (before(0) + out->velocity_after(0));
  out->friction_work_j = out->impulse(1) * 0.5 * (before(1) + out->velocity_after(1));
}

// The paper's law (eqs. 22-26): stick if the cone allows it, else slide
// against the slip before the impact, plastic.
ContactImpulse PaperImpulse(const Eigen::Matrix2d& w, const Eigen::Vector2d& before, double mu) {
  ContactImpulse out;
  const Eigen::Vector2d stick = w.lu().solve(-before);
  if (stick(0) > 0.0 && std::abs(stick(1)) <= mu * stick(0)) {
    out.impulse = stick;
    out.sticks = true;
  } else {
    const double s = before(1) != 0.0 ? Sign(before(1)) : -Sign(stick(1));
    const Eigen::Vector2d direction(1.0, -mu * s);
    out.impulse = direction * (-before(0) / w.row(0).dot(direction));
  }
  out.velocity_after = before + w * out.impulse;
  out.compression_impulse_n_s = out.impulse(0);
  StraightPathWork(&out, before);
  return out;
}

// How the tip moves tangentially while the normal impulse grows.
struct Mode {
  bool sticking = false;
  double slip_sign = 0.0;
};

// The mode a tip at rest tangentially takes: stick inside the cone, else
// slip the one way the impulse drives it.
Mode ModeFromRest(const Eigen::Matrix2d& w, double mu) {
  if (std::abs(w(1, 0)) <= mu * w(1, 1)) return {true, 0.0};
  return {false, Sign(w(1, 0))};
}

}  // namespace

ContactImpulse ResolveContactImpulse(const Eigen::Matrix2d& w, const Eigen::Vector2d& before,
                                     const ContactImpulseLaw& law) {
  const double mu = law.friction_coefficient, e = law.restitution_coefficient;
  if (!(mu >= 0.0) || !(e >= 0.0 && e <= 1.0) || !std::isfinite(mu)) {
    throw std::invalid_argument(
        fmt::format("impact law: friction {} must be >= 0 and restitution {} in [0, 1]", mu, e));
  }
  if (!(w(0, 0) > 0.0 && w(1, 1) > 0.0)) {
    throw std::domain_error("impact: the contact's Delassus matrix is not positive definite");
  }
  ContactImpulse out;
  out.velocity_after = before;
  if (!(before(0) < 0.0)) return out;  // not approaching: no impulse
  if (law.friction == ImpactFriction::kPaper) {
    if (e != 0.0) throw std::invalid_argument("impact law: the paper's law is plastic (e = 0)");
    return PaperImpulse(w, before, mu);
  }

  Mode mode = before(1) != 0.0 ? Mode{false, Sign(before(1))} : ModeFromRest(w, mu);
  Eigen::Vector2d u = before;
  double p = 0.0;                       // the normal impulse so far
  double compression_work = kInfinity;  // -(normal work to p_c), once compression ended
  bool compressing = true, ended = false;
  // At most: slip to rest, a reversal or stick, compression's end, the end.
  for (int segment = 0; segment < 8; ++segment) {
    const double tangential_rate = mode.sticking ? -w(1, 0) / w(1, 1) : -mu * mode.slip_sign;
    const Eigen::Vector2d rate = w * Eigen::Vector2d(1.0, tangential_rate);  // du/dp
    if (!(rate(0) > 0.0)) {
      throw std::domain_error(fmt::format(
          "impact: friction mu = {} jams the contact (the normal velocity {:.4g} m/s cannot be "
          "stopped: Painlevé's paradox at impact)",
          mu, u(0)));
    }
    // The next event, as a normal-impulse increment.
    double to_rest = kInfinity;
    if (!mode.sticking && u(1) * rate(1) < 0.0) to_rest = -u(1) / rate(1);
    double to_phase_end = kInfinity;
    if (compressing) {
      to_phase_end = -u(0) / rate(0);
    } else if (law.restitution == RestitutionLaw::kNewton) {
      to_phase_end = std::max(0.0, (-e * before(0) - u(0)) / rate(0));
    } else if (law.restitution == RestitutionLaw::kPoisson) {
      to_phase_end = std::max(0.0, (1.0 + e) * out.compression_impulse_n_s - p);
    } else {
      // The work u_n dp still to do, e^2 W_c less what restitution did, with
      // u_n(p') = u_n + rate_n p' >= 0: the positive root, stably.
      const double remaining =
          std::max(0.0, e * e * compression_work - out.normal_work_j - compression_work);
      const double root = std::sqrt(u(0) * u(0) + 2.0 * rate(0) * remaining);
      to_phase_end = remaining > 0.0 ? 2.0 * remaining / (u(0) + root) : 0.0;
    }
    const double step = std::min(to_rest, to_phase_end);
    out.normal_work_j += step * (u(0) + 0.5 * rate(0) * step);
    out.friction_work_j += tangential_rate * step * (u(1) + 0.5 * rate(1) * step);
    out.impulse += step * Eigen::Vector2d(1.0, tangential_rate);
    u += step * rate;
    p += step;
    if (to_rest <= to_phase_end) {
      u(1) = 0.0;
      out.slip_stopped = true;
      const Mode next = ModeFromRest(w, mu);
      out.slip_reversed = !next.sticking;
      mode = next;
      if (to_rest < to_phase_end) continue;
    }
    if (compressing) {
      u(0) = 0.0;
      compressing = false;
      out.compression_impulse_n_s = p;
      compression_work = -out.normal_work_j;
      ended = e == 0.0;
      if (ended) break;
      continue;
    }
    ended = true;
    break;
  }
  if (!ended) throw std::logic_error("impact: the impulse did not end in eight segments");
  out.velocity_after = before + w * out.impulse;
  out.sticks = mode.sticking || out.velocity_after(1) == 0.0;
  return out;
}

}  // namespace impactlab
