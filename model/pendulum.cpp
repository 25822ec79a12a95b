#include "model/pendulum.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <boost/math/special_functions/ellint_1.hpp>
#include <boost/math/special_functions/jacobi_elliptic.hpp>

namespace impactlab {
namespace {

using std::numbers::pi;

bool IsThesis(const Pendulum& p) { return p.convention == PendulumConvention::kThesis; }

void CheckPendulum(const Pendulum& p) {
  if (!(p.length > 0.0) || !(p.gravity > 0.0) || !std::isfinite(p.length) ||
      !std::isfinite(p.gravity)) {
    throw std::invalid_argument(
        fmt::format("pendulum needs L > 0 and g > 0, got L = {}, g = {}", p.length, p.gravity));
  }
}

// k = sin(theta_m / 2), the modulus of the exact pendulum's elliptic functions.
double Modulus(const Pendulum& p, double xmax) { return std::sin(0.5 * SwingAngle(p, xmax)); }

// X = L sin(theta) = 2 L sin(theta/2) cos(theta/2) with sin(theta/2) = k sn(u).
// cos(theta/2) = dn(u) = sqrt(1 - k^2 sn^2): taken from sn because Boost 1.74's
// dn is wrong at the quarter period u = K (by 2e-3 at k = 0.2), and k^2 sn^2
// <= 1/2 leaves the square root well conditioned.
// Elliptic functions in double, not promoted to long double: they are on the
// rebound peak fit's hot path, and long-double argument reduction costs 10x
// for ~1 ulp.
using NoPromotion = boost::math::policies::policy<boost::math::policies::promote_double<false>>;

double DisplacementFromSn(const Pendulum& p, double k, double u) {
  const double sin_half_theta = k * boost::math::jacobi_sn(k, u, NoPromotion());
  return 2.0 * p.length * sin_half_theta *
         std::sqrt((1.0 - sin_half_theta) * (1.0 + sin_half_theta));
}

}  // namespace

double NaturalFrequency(const Pendulum& p) {
  CheckPendulum(p);
  return std::sqrt(p.gravity / p.length);
}

std::string SwingAmplitudeProblem(const Pendulum& p, double xmax) {
  CheckPendulum(p);
  if (xmax >= 0.0 && xmax < p.length) return {};
  return fmt::format("a swing amplitude must satisfy 0 <= X < L, got X = {} with L = {}", xmax,
                     p.length);
}

double SwingAngle(const Pendulum& p, double xmax) {
  if (std::string problem = SwingAmplitudeProblem(p, xmax); !problem.empty()) {
    throw std::domain_error(problem);
  }
  return IsThesis(p) ? xmax / p.length : std::asin(xmax / p.length);
}

double SpeedFromAmplitude(const Pendulum& p, double xmax) {
  if (IsThesis(p)) {
    SwingAngle(p, xmax);  // validates
    return xmax * NaturalFrequency(p);
  }
  return SpeedFromPeakEnergy(p, xmax);
}

double SpeedFromPeakEnergy(const Pendulum& p, double xmax) {
  // (1/2) v^2 = g L (1 - cos theta) = 2 g L sin^2(theta/2).
  return 2.0 * std::sqrt(p.gravity * p.length) * std::sin(0.5 * SwingAngle(p, xmax));
}

std::string SwingSpeedProblem(const Pendulum& p, double speed) {
  CheckPendulum(p);
  if (!(speed >= 0.0) || !std::isfinite(speed)) {
    return fmt::format("a swing speed must be >= 0, got {}", speed);
  }
  if (IsThesis(p)) {
    const double amplitude = speed / NaturalFrequency(p);
    if (amplitude < p.length) return {};
    return fmt::format("a swing at {} through equilibrium would reach X = {} >= L = {}", speed,
                       amplitude, p.length);
  }
  if (speed / (2.0 * std::sqrt(p.gravity * p.length)) < std::numbers::sqrt2 / 2.0) return {};
  return fmt::format("a swing at {} through equilibrium would pass the horizontal (L = {}, g = {})",
                     speed, p.length, p.gravity);
}

double AmplitudeFromSpeed(const Pendulum& p, double speed) {
  if (std::string problem = SwingSpeedProblem(p, speed); !problem.empty()) {
    throw std::domain_error(problem);
  }
  if (IsThesis(p)) return speed / NaturalFrequency(p);
  const double k = speed / (2.0 * std::sqrt(p.gravity * p.length));
  // X = L sin(theta_m) = 2 L sin(theta_m/2) cos(theta_m/2).
  return 2.0 * p.length * k * std::sqrt((1.0 - k) * (1.0 + k));
}

double HalfPeriod(const Pendulum& p, double xmax) {
  const double small_angle = pi / NaturalFrequency(p);
  if (IsThesis(p)) return small_angle;
  // 2 sqrt(L/g) K(k), K(0) = pi/2.
  return 2.0 * boost::math::ellint_1(Modulus(p, xmax)) / NaturalFrequency(p);
}

std::optional<double> HalfPeriodIfSwings(const Pendulum& p, double xmax) {
  if (!IsThesis(p) && !SwingAmplitudeProblem(p, xmax).empty()) return std::nullopt;
  return HalfPeriod(p, xmax);
}

double ReleaseSwingDisplacement(const Pendulum& p, double release_x, double t) {
  const double w0 = NaturalFrequency(p);
  if (IsThesis(p)) return release_x * std::cos(w0 * t);
  // sin(theta/2) = k sn(K - w0 t, k): at t = 0 sn(K) = 1, theta = theta_m.
  const double k = Modulus(p, release_x);
  return DisplacementFromSn(p, k, boost::math::ellint_1(k) - w0 * t);
}

double ReboundDisplacement(const Pendulum& p, double speed, double t) {
  const double w0 = NaturalFrequency(p);
  if (IsThesis(p)) return speed / w0 * std::sin(w0 * t);
  return DisplacementFromSn(p, speed / (2.0 * std::sqrt(p.gravity * p.length)), w0 * t);
}

SwingState ReboundState(const Pendulum& p, double speed, double t) {
  const double w0 = NaturalFrequency(p);
  if (IsThesis(p)) return {speed / w0 * std::sin(w0 * t), speed * std::cos(w0 * t)};
  const double k = speed / (2.0 * std::sqrt(p.gravity * p.length));
  double cn = 0.0, dn = 0.0;  // dn unused: Boost 1.74's is wrong at u = K (see above)
  const double sn = boost::math::jacobi_elliptic(k, w0 * t, &cn, &dn, NoPromotion());
  const double sin_half_theta = k * sn;
  const double cos_half_theta = std::sqrt((1.0 - sin_half_theta) * (1.0 + sin_half_theta));
  const double cos_theta = 1.0 - 2.0 * sin_half_theta * sin_half_theta;
  return {2.0 * p.length * sin_half_theta * cos_half_theta,
          p.length * cos_theta * 2.0 * k * w0 * cn};
}

}  // namespace impactlab
