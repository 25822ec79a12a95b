#include "synth/photocell.h"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "synth/experiment.h"

namespace impactlab {
namespace {

// Uniform in [0, 1) from the top 53 bits: the same on every platform, unlike
// std::uniform_real_distribution whose algorithm is unspecified.
double Uniform01(std::mt19937_64& engine) {
  return static_cast<double>(engine() >> 11) * 0x1.0p-53;
}

double UniformIn(std::mt19937_64& engine, double lo, double hi) {
  return lo + (hi - lo) * Uniform01(engine);
}

// tanh(r u) / r, continuous through r = 0.
double Saturate(double rate, double u) { return rate == 0.0 ? u : std::tanh(rate * u) / rate; }

}  // namespace

void PhotocellOptions::Check() const {
  if (!(x_hi > x_lo) || !std::isfinite(x_lo) || !std::isfinite(x_hi)) {
    throw std::invalid_argument(
        fmt::format("photocell range needs x_lo < x_hi, got [{}, {}]", x_lo, x_hi));
  }
  if (!(nonlinearity >= 0.0 && nonlinearity <= 1.0)) {
    throw std::invalid_argument(
        fmt::format("photocell nonlinearity must be in [0, 1], got {}", nonlinearity));
  }
  if (!(nominal_span_v > 0.0) || !std::isfinite(nominal_span_v) || !std::isfinite(nominal_mid_v)) {
    throw std::invalid_argument(
        fmt::format("photocell needs nominal_span_v > 0 and a finite nominal_mid_v, got {}, {}",
                    nominal_span_v, nominal_mid_v));
  }
}

SimulatedPhotocell::SimulatedPhotocell(double x_center, double rate, double gain,
                                       double volts_at_center, double x_lo, double x_hi)
    : x_center_(x_center),
      rate_(rate),
      gain_(gain),
      volts_at_center_(volts_at_center),
      x_lo_(x_lo),
      x_hi_(x_hi) {
  if (!std::isfinite(x_center) || !(rate >= 0.0) || !std::isfinite(rate) || gain == 0.0 ||
      !std::isfinite(gain) || !std::isfinite(volts_at_center) || !(x_hi > x_lo)) {
    throw std::invalid_argument(fmt::format(
        "photocell curve needs rate >= 0, gain != 0, x_lo < x_hi, got x_center = {}, rate = {}, "
        "gain = {}, volts_at_center = {}, range [{}, {}]",
        x_center, rate, gain, volts_at_center, x_lo, x_hi));
  }
}

SimulatedPhotocell SimulatedPhotocell::FromSeed(std::uint64_t seed, const PhotocellOptions& o) {
  o.Check();
  std::mt19937_64 engine(seed);
  // Always draw the same number of values, so that one option does not shift
  // the others' randomness.
  const double center_offset = UniformIn(engine, -0.35, 0.35);  // of the half range
  const double span_factor = UniformIn(engine, 0.8, 1.2);
  const double mid_offset = UniformIn(engine, -0.1, 0.1);  // of the span
  const bool random_rising = Uniform01(engine) < 0.5;

  const double half_range = 0.5 * (o.x_hi - o.x_lo);
  const double mid = 0.5 * (o.x_hi + o.x_lo);
  const double x_center = mid + center_offset * half_range;
  // At nonlinearity 1 the tanh argument reaches 1.2 * 1.35 = 1.62 at the far
  // end of the range: the slope there is sech^2(1.62) ~ 0.14 of the centre's.
  const double rate = 1.2 * o.nonlinearity / half_range;
  const double span_v = o.nominal_span_v * span_factor;
  const double unit_span = Saturate(rate, o.x_hi - x_center) - Saturate(rate, o.x_lo - x_center);
  const bool rising = o.polarity == PhotocellPolarity::kRising ||
                      (o.polarity == PhotocellPolarity::kRandom && random_rising);
  const double gain = (rising ? 1.0 : -1.0) * span_v / unit_span;
  // Place V(mid) at the nominal level plus the cell's offset.
  const double volts_at_center =
      o.nominal_mid_v + mid_offset * span_v - gain * Saturate(rate, mid - x_center);
  return SimulatedPhotocell(x_center, rate, gain, volts_at_center, o.x_lo, o.x_hi);
}

double SimulatedPhotocell::Volts(double x) const {
  return volts_at_center_ + gain_ * Saturate(rate_, x - x_center_);
}

double SimulatedPhotocell::SlopeVoltsPerLength(double x) const {
  if (rate_ == 0.0) return gain_;
  const double c = std::cosh(rate_ * (x - x_center_));
  return gain_ / (c * c);
}

double SimulatedPhotocell::Displacement(double volts) const {
  const double u = (volts - volts_at_center_) / gain_;  // tanh(rate s) / rate
  if (rate_ == 0.0) return x_center_ + u;
  const double t = rate_ * u;
  if (!(std::abs(t) < 1.0)) {
    throw std::domain_error(fmt::format(
        "{} V is outside the photocell's output range ({} V to {} V)", volts,
        volts_at_center_ - std::abs(gain_) / rate_, volts_at_center_ + std::abs(gain_) / rate_));
  }
  return x_center_ + std::atanh(t) / rate_;
}

std::vector<double> SimulatedPhotocell::Volts(std::span<const double> x) const {
  std::vector<double> volts;
  volts.reserve(x.size());
  for (double xi : x) volts.push_back(Volts(xi));
  return volts;
}

void to_json(nlohmann::json& j, const SimulatedPhotocell& c) {
  j = {{"model", "tanh"},
       {"formula", "V = volts_at_center + gain * tanh(rate * (X - x_center)) / rate"},
       {"x_center", c.x_center()},
       {"rate_per_length", c.rate_per_length()},
       {"gain_v_per_length", c.gain_v_per_length()},
       {"volts_at_center", c.volts_at_center()},
       {"x_lo", c.x_lo()},
       {"x_hi", c.x_hi()}};
}

void from_json(const nlohmann::json& j, SimulatedPhotocell& c) {
  if (j.at("model").get<std::string>() != "tanh") {
    throw std::invalid_argument(
        fmt::format("unknown photocell model '{}'", j.at("model").get<std::string>()));
  }
  c = SimulatedPhotocell(j.at("x_center").get<double>(), j.at("rate_per_length").get<double>(),
                         j.at("gain_v_per_length").get<double>(),
                         j.at("volts_at_center").get<double>(), j.at("x_lo").get<double>(),
                         j.at("x_hi").get<double>());
}

std::vector<double> AddGaussianNoise(std::span<const double> volts, double sigma_v,
                                     std::uint64_t seed) {
  if (!(sigma_v >= 0.0) || !std::isfinite(sigma_v)) {
    throw std::invalid_argument(fmt::format("noise sigma must be >= 0, got {} V", sigma_v));
  }
  std::mt19937_64 engine(seed);
  std::vector<double> out(volts.begin(), volts.end());
  for (std::size_t i = 0; i < out.size(); i += 2) {
    // Box-Muller: two independent normals from two uniforms; 1 - u is in (0, 1].
    const double radius = std::sqrt(-2.0 * std::log(1.0 - Uniform01(engine)));
    const double angle = 2.0 * std::numbers::pi * Uniform01(engine);
    out[i] += sigma_v * radius * std::cos(angle);
    if (i + 1 < out.size()) out[i + 1] += sigma_v * radius * std::sin(angle);
  }
  return out;
}

CalibrationSweep MakeCalibrationSweep(const SimulatedPhotocell& curve,
                                      const CalibrationSweepOptions& o) {
  FreeSwingOptions swing;
  swing.pendulum_length = o.pendulum_length;
  swing.gravity = o.gravity;
  swing.release_x = o.release_x;
  swing.duration_s = o.duration_s;
  swing.sample_rate_hz = o.sample_rate_hz;
  SampledSwing s = SimulateFreeSwing(swing);
  // A free swing from a checked release, at the default tolerances, is
  // smooth and bounded: an integration that stops on it is a bug.
  if (!s.ok) throw std::logic_error("calibration sweep: " + s.reason);
  CalibrationSweep out;
  out.volts = curve.Volts(s.x);
  out.time_s = std::move(s.time_s);
  out.x = std::move(s.x);
  return out;
}

}  // namespace impactlab
