#include "fit/kelvin_voigt_two_point.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "fit/uncertainty.h"
#include "model/kelvin_voigt.h"

namespace impactlab {
namespace {

// The estimates as one vector, so that their uncertainties come from one
// propagation: [ln e, e, zeta, K, C, X_0, X_1, ...] (K, C only with tau_c).
std::vector<double> Estimates(const Pendulum& pendulum, double mass, double xa, double xb,
                              std::optional<double> contact_time, int a, int b,
                              std::size_t rebound_count, Separation separation) {
  // Eq. 34/35: the speed ratio over N impacts; PENDUL's thesis convention
  // takes X_a through X sqrt(g/L) and X_b through its potential energy.
  // The log of the ratio, not a difference of logs: at X/L = 1e-9 each ln v is
  // about -16 and the difference would lose a digit.
  const double log_e =
      std::log(SpeedFromPeakEnergy(pendulum, xb) / SpeedFromAmplitude(pendulum, xa)) / (b - a);
  // ln e = 0 is the elastic limit; DampingRatioFromLogRestitution wants ln e < 0.
  const double zeta = log_e < 0.0 ? DampingRatioFromLogRestitution(log_e, separation) : 0.0;
  std::vector<double> out = {log_e, std::exp(log_e), zeta};
  if (contact_time) {
    const double k = StiffnessFromContactTime(mass, *contact_time, zeta, separation);
    out.push_back(k);
    out.push_back(2.0 * zeta * std::sqrt(k * mass));  // eq. 38
  }
  for (std::size_t n = 0; n < rebound_count; ++n) {
    out.push_back(PredictMaximum(pendulum, xa, a, static_cast<int>(n), log_e));
  }
  return out;
}

// What a caller must get right: a pair among the rebounds measured, one
// uncertainty per maximum or none.
void CheckPreconditions(const ReboundMeasurements& m, const TwoPointOptions& options) {
  const auto [a, b] = options.rebounds;
  const int count = static_cast<int>(m.xmax.size());
  if (!(0 <= a && a < b && b < count)) {
    throw std::invalid_argument(
        fmt::format("the fit pair must satisfy 0 <= a < b < {} (rebounds measured), got [{}, {}]",
                    count, a, b));
  }
  if (!m.xmax_sigma.empty() && m.xmax_sigma.size() != m.xmax.size()) {
    throw std::invalid_argument("give one uncertainty per rebound maximum, or none");
  }
}

}  // namespace

std::string TwoPointRefusal(const Pendulum& pendulum, const ReboundMeasurements& m,
                            const TwoPointOptions& options) {
  CheckPreconditions(m, options);
  for (std::size_t n = 0; n < m.xmax.size(); ++n) {
    if (!(m.xmax[n] > 0.0) || !std::isfinite(m.xmax[n])) {
      return fmt::format("rebound {} maximum must be a positive number, got {}", n, m.xmax[n]);
    }
  }
  if (m.contact_time && !(*m.contact_time > 0.0)) {
    return fmt::format("contact time must be positive, got {}", *m.contact_time);
  }
  const auto [a, b] = options.rebounds;
  const double xa = m.xmax[a], xb = m.xmax[b];
  if (xb > xa) return {};  // no dissipation: the fit's own reason says so
  for (const double x : {xa, xb}) {
    if (std::string beyond = SwingAmplitudeProblem(pendulum, x); !beyond.empty()) return beyond;
  }
  // The model's maxima before the pair's first swing faster than it: rebound
  // 0's is the fastest.
  if (a > 0) {
    const double log_e =
        std::log(SpeedFromPeakEnergy(pendulum, xb) / SpeedFromAmplitude(pendulum, xa)) / (b - a);
    return PredictMaximumProblem(pendulum, xa, a, 0, log_e);
  }
  return {};
}

std::string PredictMaximumProblem(const Pendulum& pendulum, double from_x, int from, int to,
                                  double log_restitution) {
  if (std::string beyond = SwingAmplitudeProblem(pendulum, from_x); !beyond.empty()) {
    return beyond;
  }
  return SwingSpeedProblem(
      pendulum, SpeedFromAmplitude(pendulum, from_x) * std::exp(log_restitution * (to - from)));
}

double PredictMaximum(const Pendulum& pendulum, double from_x, int from, int to,
                      double log_restitution) {
  const double speed =
      SpeedFromAmplitude(pendulum, from_x) * std::exp(log_restitution * (to - from));
  return AmplitudeFromSpeed(pendulum, speed);
}

KelvinVoigtTwoPointFit FitKelvinVoigtTwoPoint(const Pendulum& pendulum, double mass,
                                              const ReboundMeasurements& measured,
                                              const TwoPointOptions& options) {
  KelvinVoigtTwoPointFit fit;
  fit.rebounds_used = options.rebounds;
  fit.separation = options.separation;
  fit.contact_time = measured.contact_time;
  if (std::string refusal = TwoPointRefusal(pendulum, measured, options); !refusal.empty()) {
    fit.reason = std::move(refusal);
    return fit;
  }
  const auto [a, b] = options.rebounds;
  const double xa = measured.xmax[a], xb = measured.xmax[b];
  if (xb > xa) {
    fit.reason = fmt::format(
        "rebound {} ({}) exceeds rebound {} ({}): the pair shows no dissipation, so no "
        "Kelvin-Voigt parameters follow from it; choose another pair (fit_rebounds)",
        b, xb, a, xa);
    return fit;
  }

  const std::size_t count = measured.xmax.size();
  const auto estimates = [&](const std::vector<double>& in) {
    const std::optional<double> tau =
        measured.contact_time ? std::optional<double>(in[2]) : std::nullopt;
    return Estimates(pendulum, mass, in[0], in[1], tau, a, b, count, options.separation);
  };
  const std::vector<double> inputs = {xa, xb, measured.contact_time.value_or(0.0)};
  const auto sigma_of = [&](int n) {
    return measured.xmax_sigma.empty() ? 0.0 : measured.xmax_sigma[n];
  };
  std::vector<double> input_sigmas = {sigma_of(a), sigma_of(b),
                                      measured.contact_time ? measured.contact_time_sigma : 0.0};
  const std::vector<double> values = estimates(inputs);
  const std::vector<double> sigmas = PropagateUncertainty(estimates, inputs, input_sigmas);

  fit.ok = true;
  std::size_t i = 0;
  fit.log_restitution = {values[i], sigmas[i]};
  ++i;
  fit.restitution = {values[i], sigmas[i]};
  ++i;
  fit.damping_ratio = {values[i], sigmas[i]};
  ++i;
  if (measured.contact_time) {
    fit.stiffness = Estimate{values[i], sigmas[i]};
    ++i;
    fit.damping = Estimate{values[i], sigmas[i]};
    ++i;
  }
  for (; i < values.size(); ++i) fit.predicted_xmax.push_back({values[i], sigmas[i]});
  if (fit.log_restitution.value == 0.0) {
    fit.note = fmt::format("rebounds {} and {} are equal: no measurable dissipation", a, b);
  }
  return fit;
}

}  // namespace impactlab
