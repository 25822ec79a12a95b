#include "model/power_law_contact.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <fmt/format.h>
#include <boost/math/special_functions/beta.hpp>
#include <boost/math/tools/roots.hpp>

#include "model/contact_integration.h"
#include "model/hunt_crossley_terms.h"
#include "model/power_law_tables.h"

namespace impactlab {
namespace {

bool Positive(double x) { return std::isfinite(x) && x > 0.0; }

void CheckPowerLaw(double mass, double stiffness, double exponent, double impact_speed) {
  if (!Positive(mass) || !Positive(stiffness) || !Positive(exponent) || !(exponent <= 10.0) ||
      !Positive(impact_speed)) {
    throw std::invalid_argument(fmt::format(
        "power-law contact needs M, k and v0 > 0 and 0 < n <= 10, got M = {}, k = {}, n = {}, "
        "v0 = {}",
        mass, stiffness, exponent, impact_speed));
  }
}

void CheckDamping(const char* name, double value) {
  if (!std::isfinite(value) || value < 0.0) {
    throw std::invalid_argument(fmt::format("{} must be finite and >= 0, got {}", name, value));
  }
}

// a^n for a >= 0. The laws' exponents are mostly whole or half numbers
// (3/2 for spheres, 1 and 2 for other shapes): then products and one square
// root, a few ulp from pow and some twenty times cheaper, where an impact's
// integration evaluates it at every stage of every step.
double Power(double a, double exponent) {
  const double twice = 2.0 * exponent;
  if (twice == std::floor(twice) && exponent <= 10.0) {
    const auto whole = static_cast<int>(std::floor(exponent));
    double p = twice == 2.0 * whole ? 1.0 : std::sqrt(a);
    for (int k = 0; k < whole; ++k) p *= a;
    return p;
  }
  return std::pow(a, exponent);
}

// The scaled spring force ((n+1)/2) u^n, continued oddly below u = 0 so that
// an integration step that overshoots the contact's end stays defined.
double ScaledSpring(double exponent, double u) {
  return 0.5 * (exponent + 1.0) * std::copysign(Power(std::abs(u), exponent), u);
}

ScaledForce HuntCrossleyForce(double exponent, double eps) {
  return
      [exponent, eps](double u, double w) { return ScaledSpring(exponent, u) * (1.0 + eps * w); };
}

ScaledForce HertzDamperForce(double exponent, double beta) {
  return [exponent, beta](double u, double w) { return ScaledSpring(exponent, u) + beta * w; };
}

// beta = c x* / (M v0): the damper in the Hertz scaling.
double ScaledDamping(const HertzDamper& model, double impact_speed) {
  return model.damping *
         HertzPeakCompression(model.mass, model.stiffness, model.exponent, impact_speed) /
         (model.mass * impact_speed);
}

ContactResponse Scaled(double peak_scale, double impact_speed, double contact_time,
                       double restitution, double peak_compression, double peak_time,
                       Separation separation) {
  const double time_scale = peak_scale / impact_speed;
  ContactResponse r;
  r.contact_time = time_scale * contact_time;
  r.restitution = restitution;
  r.log_restitution = std::log(restitution);
  r.peak_compression = peak_scale * peak_compression;
  r.peak_time = time_scale * peak_time;
  r.separation = separation;
  return r;
}

ContactState PhysicalState(double peak_scale, double impact_speed, const ScaledState& s) {
  return {peak_scale * s.compression, impact_speed * s.rate, 0.0};
}

std::vector<double> EvenTimes(double end, int samples) {
  if (samples < 2)
    throw std::invalid_argument(fmt::format("samples must be >= 2, got {}", samples));
  std::vector<double> t(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) t[static_cast<std::size_t>(i)] = end * i / (samples - 1);
  return t;
}

}  // namespace

double HertzPeakCompression(double mass, double stiffness, double exponent, double impact_speed) {
  CheckPowerLaw(mass, stiffness, exponent, impact_speed);
  // ((n+1)/2 M v0^2 / k)^(1/(n+1)) in logs: M v0^2/k may overflow for soft units.
  const double log_scale = std::log(0.5 * (exponent + 1.0)) + std::log(mass) - std::log(stiffness) +
                           2.0 * std::log(impact_speed);
  return std::exp(log_scale / (exponent + 1.0));
}

ContactResponse HertzContact(const Hertz& model, double impact_speed) {
  const double x_star =
      HertzPeakCompression(model.mass, model.stiffness, model.exponent, impact_speed);
  // Scaled: w^2 = 1 - u^(n+1), so s_c/2 = int_0^1 du / sqrt(1 - u^(n+1))
  // = B(1/(n+1), 1/2) / (n+1).
  const double a = 1.0 / (model.exponent + 1.0);
  const double half = a * boost::math::beta(a, 0.5);
  return Scaled(x_star, impact_speed, 2.0 * half, 1.0, 1.0, half, Separation::kKinematic);
}

double HuntCrossleyRestitution(double eps) {
  if (!(eps >= 0.0) || std::isinf(eps)) {
    throw std::invalid_argument(fmt::format("eps = chi v0 must be finite and >= 0, got {}", eps));
  }
  return hunt_crossley::ExitOf(eps).restitution;
}

ContactResponse HuntCrossleyContact(const HuntCrossley& model, double impact_speed) {
  const double x_star =
      HertzPeakCompression(model.mass, model.stiffness, model.exponent, impact_speed);
  CheckDamping("damping factor chi", model.damping_factor);
  const double n = model.exponent;
  const double eps = model.damping_factor * impact_speed;
  const hunt_crossley::Exit exit = hunt_crossley::ExitOf(eps);
  if (!(exit.gap > 0.0)) {
    throw std::invalid_argument(fmt::format(
        "Hunt-Crossley: eps = chi v0 = {} is beyond the range where 1 - eps e is representable "
        "(~700): the exit speed sits at the damping factor's zero",
        eps));
  }
  const auto times = hunt_crossley::ContactTimes(n, eps, exit.restitution, exit.gap);
  return Scaled(x_star, impact_speed, times.compression + times.restitution, exit.restitution,
                hunt_crossley::PeakCompression(n, eps), times.compression, Separation::kKinematic);
}

ContactResponse HertzDamperContact(const HertzDamper& model, double impact_speed,
                                   Separation separation) {
  const double x_star =
      HertzPeakCompression(model.mass, model.stiffness, model.exponent, impact_speed);
  CheckDamping("damping c", model.damping);
  const double beta = ScaledDamping(model, impact_speed);
  const ScaledImpact s = IntegrateScaledImpact(HertzDamperForce(model.exponent, beta), separation);
  if (!s.ok) throw NoSeparationError(s.reason);
  return Scaled(x_star, impact_speed, s.contact_time, -s.exit_rate, s.peak_compression, s.peak_time,
                separation);
}

HertzDamperScaled HertzDamperScaledImpact(double exponent, double beta, Separation separation,
                                          double tolerance) {
  if (const auto t = power_law_tables::HertzDamperImpact(exponent, beta, separation)) {
    return {t->contact_time.value,
            t->restitution.value,
            t->contact_time.slope,
            t->restitution.slope,
            true,
            {}};
  }
  return IntegrateHertzDamperScaledImpact(exponent, beta, separation, tolerance);
}

HertzDamperScaled IntegrateHertzDamperScaledImpact(double exponent, double beta,
                                                   Separation separation, double tolerance) {
  const double half = 0.5 * (exponent + 1.0);
  const ScaledForceWithPartials force{[=](double u, double w) {
    const double a = std::abs(u);
    // f = ((n+1)/2) sign(u) |u|^n + beta w; f_u, f_w, f_beta.
    // f_u from a^n itself where a > 0 (a^(n-1) = a^n / a): one power, not two.
    const double power = Power(a, exponent);
    const double slope = a > 0.0 ? power / a : std::pow(a, exponent - 1.0);
    return std::array<double, 4>{half * std::copysign(power, u) + beta * w, half * exponent * slope,
                                 beta, w};
  }};
  ScaledIntegrationOptions options;
  options.tolerance = tolerance;
  const ScaledImpactSensitivity s =
      IntegrateScaledImpactWithSensitivity(force, separation, options);
  if (!s.impact.ok) return {0.0, 0.0, 0.0, 0.0, false, s.impact.reason};
  return {s.impact.contact_time, -s.impact.exit_rate, s.d_contact_time, -s.d_exit_rate, true, {}};
}

const char* DampingFactorConventionName(DampingFactorConvention convention) {
  switch (convention) {
    case DampingFactorConvention::kExact:
      return "exact";
    case DampingFactorConvention::kHuntCrossley:
      return "hunt-crossley";
    case DampingFactorConvention::kLankaraniNikravesh:
      return "lankarani-nikravesh";
    case DampingFactorConvention::kFlores:
      return "flores";
  }
  return "exact";
}

DampingFactorConvention ParseDampingFactorConvention(const std::string& name) {
  for (auto c : {DampingFactorConvention::kExact, DampingFactorConvention::kHuntCrossley,
                 DampingFactorConvention::kLankaraniNikravesh, DampingFactorConvention::kFlores}) {
    if (name == DampingFactorConventionName(c)) return c;
  }
  throw std::invalid_argument(fmt::format(
      "damping-factor convention must be exact, hunt-crossley, lankarani-nikravesh or flores, "
      "got \"{}\"",
      name));
}

double DampingFactorFor(double restitution, double impact_speed,
                        DampingFactorConvention convention) {
  const double e = restitution;
  if (!(e > 0.0 && e <= 1.0) || !Positive(impact_speed)) {
    throw std::invalid_argument(fmt::format(
        "target restitution must be in (0, 1] and impact speed > 0, got e = {}, v0 = {}", e,
        impact_speed));
  }
  switch (convention) {
    case DampingFactorConvention::kHuntCrossley:
      return 1.5 * (1.0 - e) / impact_speed;
    case DampingFactorConvention::kLankaraniNikravesh:
      return 0.75 * (1.0 - e) * (1.0 + e) / impact_speed;
    case DampingFactorConvention::kFlores:
      return 1.6 * (1.0 - e) / (e * impact_speed);
    case DampingFactorConvention::kExact:
      break;
  }
  if (e == 1.0) return 0.0;
  // Solve psi(-y) = psi(y/e) for y = eps e in (0, 1) (y = 0 is the trivial
  // root). Divided by y^2 the equation is regular at y = 0, where it is
  // (1 - 1/e^2)/2 < 0. Past y = 1/2 it runs on t = -ln(1 - y), so roots with
  // 1 - y far below the double spacing near 1 are still found.
  using hunt_crossley::Psi2;
  const auto tolerance = boost::math::tools::eps_tolerance<double>(52);
  std::uintmax_t iterations = 200;
  auto near = [e](double y) { return Psi2(-y) - Psi2(y / e) / (e * e); };
  double y = 0.0;
  if (near(0.5) >= 0.0) {
    const auto b = boost::math::tools::toms748_solve(near, 0.0, 0.5, tolerance, iterations);
    y = 0.5 * (b.first + b.second);
  } else {
    auto far = [e](double t) {
      const double yt = -std::expm1(-t);
      return t - yt - (yt / e - std::log1p(yt / e));
    };
    // far(t) < 0 up to t = 700: 1 - y is below 1e-304, y = 1 to every digit.
    if (far(700.0) <= 0.0) return 1.0 / (e * impact_speed);
    const auto b =
        boost::math::tools::toms748_solve(far, std::log(2.0), 700.0, tolerance, iterations);
    y = -std::expm1(-0.5 * (b.first + b.second));
  }
  return y / e / impact_speed;
}

ContactState HuntCrossleyStateAt(const HuntCrossley& model, double impact_speed, double t) {
  const double x_star =
      HertzPeakCompression(model.mass, model.stiffness, model.exponent, impact_speed);
  const double eps = model.damping_factor * impact_speed;
  ContactState s = PhysicalState(
      x_star, impact_speed,
      ScaledStateAt(HuntCrossleyForce(model.exponent, eps), t * impact_speed / x_star));
  s.force = model.stiffness * std::pow(std::fmax(s.compression, 0.0), model.exponent) *
            (1.0 + model.damping_factor * s.velocity);
  return s;
}

ContactState HertzDamperStateAt(const HertzDamper& model, double impact_speed, double t) {
  const double x_star =
      HertzPeakCompression(model.mass, model.stiffness, model.exponent, impact_speed);
  const double beta = ScaledDamping(model, impact_speed);
  ContactState s = PhysicalState(
      x_star, impact_speed,
      ScaledStateAt(HertzDamperForce(model.exponent, beta), t * impact_speed / x_star));
  s.force = model.stiffness *
                std::copysign(std::pow(std::abs(s.compression), model.exponent), s.compression) +
            model.damping * s.velocity;
  return s;
}

namespace {

template <typename StateAt>
ContactHistory History(double contact_time, int samples, StateAt state_at) {
  ContactHistory h;
  h.time = EvenTimes(contact_time, samples);
  for (double t : h.time) {
    const ContactState s = state_at(t);
    h.compression.push_back(s.compression);
    h.velocity.push_back(s.velocity);
    h.force.push_back(s.force);
  }
  return h;
}

}  // namespace

ContactHistory HuntCrossleyHistory(const HuntCrossley& model, double impact_speed, int samples) {
  const ContactResponse r = HuntCrossleyContact(model, impact_speed);
  return History(r.contact_time, samples,
                 [&](double t) { return HuntCrossleyStateAt(model, impact_speed, t); });
}

ContactHistory HertzDamperHistory(const HertzDamper& model, double impact_speed,
                                  Separation separation, int samples) {
  const ContactResponse r = HertzDamperContact(model, impact_speed, separation);
  return History(r.contact_time, samples,
                 [&](double t) { return HertzDamperStateAt(model, impact_speed, t); });
}

HuntCrossleyContactLaw::HuntCrossleyContactLaw(const HuntCrossley& model) : model_(model) {
  CheckPowerLaw(model.mass, model.stiffness, model.exponent, 1.0);
  CheckDamping("damping factor chi", model.damping_factor);
}

ContactResponse HuntCrossleyContactLaw::Respond(double impact_speed) const {
  return HuntCrossleyContact(model_, impact_speed);
}

double HuntCrossleyContactLaw::Compression(double impact_speed, double t) const {
  return HuntCrossleyStateAt(model_, impact_speed, t).compression;
}

HertzDamperContactLaw::HertzDamperContactLaw(const HertzDamper& model, Separation separation)
    : model_(model), separation_(separation) {
  CheckPowerLaw(model.mass, model.stiffness, model.exponent, 1.0);
  CheckDamping("damping c", model.damping);
}

ContactResponse HertzDamperContactLaw::Respond(double impact_speed) const {
  return HertzDamperContact(model_, impact_speed, separation_);
}

double HertzDamperContactLaw::Compression(double impact_speed, double t) const {
  return HertzDamperStateAt(model_, impact_speed, t).compression;
}

}  // namespace impactlab
