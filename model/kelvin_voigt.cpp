#include "model/kelvin_voigt.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <boost/math/special_functions/sinc.hpp>
#include <boost/math/tools/roots.hpp>

#include "model/impact_speed_internal.h"

namespace impactlab {
namespace {

using std::numbers::pi;

void CheckKelvinVoigtRates(const KelvinVoigtRates& r) {
  if (!(r.natural_frequency > 0.0) || !std::isfinite(r.natural_frequency) ||
      !(r.damping_ratio >= 0.0) || !std::isfinite(r.damping_ratio)) {
    throw std::invalid_argument(
        fmt::format("Kelvin-Voigt needs wn > 0 and zeta >= 0, got wn = {}, zeta = {}",
                    r.natural_frequency, r.damping_ratio));
  }
}

// sqrt(|1 - zeta^2|) without cancellation ((1 - zeta) is exact near 1) and
// without overflow for huge zeta.
double SqrtOneMinusZetaSquared(double zeta) {
  return std::sqrt(std::abs(1.0 - zeta)) * std::sqrt(1.0 + zeta);
}

// h(zeta) = acos(zeta)/sqrt(1 - zeta^2), continued analytically through zeta = 1
// (h(1) = 1) as acosh(zeta)/sqrt(zeta^2 - 1). wn * (time of peak compression).
double PeakPhaseRatio(double zeta) {
  if (zeta == 1.0) return 1.0;
  const double s = SqrtOneMinusZetaSquared(zeta);
  if (zeta < 1.0) {
    // acos(zeta) = 2 asin(sqrt((1 - zeta)/2)): accurate as zeta -> 1.
    return 2.0 * std::asin(std::sqrt(0.5 * (1.0 - zeta))) / s;
  }
  // Far above critical: acosh(zeta) = ln(2 zeta) + O(zeta^-2) and s = zeta (1 +
  // O(zeta^-2)); written without s, which overflows near the largest double.
  if (zeta > 1e8) return (std::numbers::ln2 + std::log(zeta)) / zeta;
  // acosh(zeta) = ln(zeta + s) = log1p(zeta - 1) + log1p(s / zeta): accurate near 1.
  return (std::log1p(zeta - 1.0) + std::log1p(s / zeta)) / s;
}

void ThrowKelvinVoigtNoKinematicSeparation(double zeta) {
  throw NoSeparationError(
      fmt::format("damping ratio zeta = {} >= 1: with kinematic separation the compression never "
                  "returns to 0, so contact never ends; use force separation",
                  zeta));
}

}  // namespace

KelvinVoigtRates RatesOf(const KelvinVoigt& m) {
  if (!(m.mass > 0.0) || !(m.stiffness > 0.0) || !(m.damping >= 0.0) || !std::isfinite(m.mass) ||
      !std::isfinite(m.stiffness) || !std::isfinite(m.damping)) {
    throw std::invalid_argument(
        fmt::format("Kelvin-Voigt needs M > 0, K > 0, C >= 0, got M = {}, K = {}, C = {}", m.mass,
                    m.stiffness, m.damping));
  }
  return {std::sqrt(m.stiffness / m.mass), m.damping / (2.0 * std::sqrt(m.stiffness * m.mass))};
}

KelvinVoigt KelvinVoigtFromRates(double mass, const KelvinVoigtRates& r) {
  const double wn = r.natural_frequency;
  return {mass, mass * wn * wn, 2.0 * r.damping_ratio * mass * wn};
}

double LogRestitutionFromDampingRatio(double zeta, Separation separation) {
  if (!(zeta >= 0.0) || !std::isfinite(zeta)) {
    throw std::invalid_argument(fmt::format("a damping ratio must be >= 0, got {}", zeta));
  }
  if (separation == Separation::kForce) return -2.0 * (zeta * PeakPhaseRatio(zeta));
  if (zeta >= 1.0) ThrowKelvinVoigtNoKinematicSeparation(zeta);
  return -pi * zeta / SqrtOneMinusZetaSquared(zeta);
}

ContactResponse KelvinVoigtContact(const KelvinVoigtRates& r, double v, Separation separation) {
  CheckKelvinVoigtRates(r);
  model_internal::CheckImpactSpeed(v);
  const double zeta = r.damping_ratio;
  const double wn = r.natural_frequency;
  const double h = PeakPhaseRatio(zeta);

  ContactResponse out;
  out.separation = separation;
  out.log_restitution = LogRestitutionFromDampingRatio(zeta, separation);
  out.restitution = std::exp(out.log_restitution);
  out.contact_time =
      separation == Separation::kForce ? 2.0 * h / wn : pi / (wn * SqrtOneMinusZetaSquared(zeta));
  out.peak_time = h / wn;
  out.peak_compression = v / wn * std::exp(-zeta * h);
  return out;
}

ContactResponse KelvinVoigtContact(const KelvinVoigt& model, double v, Separation separation) {
  return KelvinVoigtContact(RatesOf(model), v, separation);
}

double KelvinVoigtCompression(const KelvinVoigtRates& r, double v, double t) {
  CheckKelvinVoigtRates(r);
  const double zeta = r.damping_ratio;
  const double wn = r.natural_frequency;
  // x = v exp(-zeta wn t) S(t), S = sin(wd t)/wd, t or sinh(b t)/b: written as
  // t sinc(wd t) and t sinhc(b t) so it stays exact as wd or b -> 0.
  const double s = SqrtOneMinusZetaSquared(zeta);
  const double tau = wn * t;
  if (zeta <= 1.0) {
    const double shape = zeta < 1.0 ? boost::math::sinc_pi(s * tau) : 1.0;
    return v * t * std::exp(-zeta * tau) * shape;
  }
  // Overdamped: exp(-zeta tau) sinh(s tau) overflows times underflows for
  // large s tau. With zeta - s = 1/(zeta + s):
  // x = v t exp(-tau/(zeta + s)) (1 - exp(-2 s tau)) / (2 s tau).
  if (tau == 0.0) return 0.0;
  const double y = 2.0 * s * tau;
  return v * t * std::exp(-tau / (zeta + s)) * (-std::expm1(-y) / y);
}

double DampingRatioFromLogRestitution(double log_e, Separation separation) {
  if (!(log_e < 0.0) || !std::isfinite(log_e)) {
    throw std::domain_error(
        fmt::format("a restitution below 1 is needed to infer damping, got ln e = {} (e = {})",
                    log_e, std::exp(log_e)));
  }
  if (separation == Separation::kKinematic) {
    return -log_e / std::hypot(log_e, pi);  // eq. 36 with N = 1
  }
  // 2 zeta h(zeta) rises monotonically from 0 to infinity: bracket and solve.
  const auto residual = [log_e](double zeta) {
    return -2.0 * (zeta * PeakPhaseRatio(zeta)) - log_e;
  };
  double hi = std::max(1.0, -log_e);
  while (residual(hi) > 0.0) {
    hi *= 2.0;
    if (!std::isfinite(hi)) {
      throw std::domain_error(fmt::format(
          "ln e = {} is beyond any finite damping ratio under force separation", log_e));
    }
  }
  std::uintmax_t iterations = 200;
  const auto [lo_root, hi_root] =
      boost::math::tools::toms748_solve(residual, 0.0, hi, -log_e, residual(hi),
                                        boost::math::tools::eps_tolerance<double>(52), iterations);
  return 0.5 * (lo_root + hi_root);
}

double StiffnessFromContactTime(double mass, double contact_time, double zeta,
                                Separation separation) {
  if (!(mass > 0.0) || !(contact_time > 0.0) || !(zeta >= 0.0)) {
    throw std::invalid_argument(fmt::format(
        "stiffness needs M > 0, tau_c > 0, zeta >= 0, got M = {}, tau_c = {}, zeta = {}", mass,
        contact_time, zeta));
  }
  if (separation == Separation::kForce) {
    const double wn = 2.0 * PeakPhaseRatio(zeta) / contact_time;
    return mass * wn * wn;
  }
  if (zeta >= 1.0) ThrowKelvinVoigtNoKinematicSeparation(zeta);
  // Eq. 37: K = M pi^2 / (tau_c^2 (1 - zeta^2)).
  return mass * pi * pi / (contact_time * contact_time * (1.0 - zeta) * (1.0 + zeta));
}

KelvinVoigtContactLaw::KelvinVoigtContactLaw(const KelvinVoigt& model, Separation separation)
    : rates_(RatesOf(model)), separation_(separation) {}

ContactResponse KelvinVoigtContactLaw::Respond(double v) const {
  return KelvinVoigtContact(rates_, v, separation_);
}

double KelvinVoigtContactLaw::Compression(double v, double t) const {
  return KelvinVoigtCompression(rates_, v, t);
}

}  // namespace impactlab
