// Synthetic photocells: displacement X (length units) -> volts, and the
// calibration sweep of the thesis's Chapter III (one bar released alone from X0,
// its cell's voltage against time, read against the free pendulum's X(t)).
//
// A cell is a smooth saturating curve (the bar's edge shutters a lamp aperture):
//   V(X) = volts_at_center + gain * tanh(rate (X - x_center)) / rate
// (V = volts_at_center + gain (X - x_center) when rate = 0). dV/dX = gain
// sech^2(rate (X - x_center)) never vanishes, so V is strictly monotone on the
// whole line, and the inverse is exact in closed form:
//   X = x_center + atanh(rate (V - volts_at_center) / gain) / rate.
// Light falls as X grows, so the voltage falls (gain < 0) unless the amplifier
// inverts it (gain > 0).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace impactlab {

enum class PhotocellPolarity {
  kFalling,  // volts fall as X grows (the bar shutters the lamp)
  kRising,   // the amplifier inverts the signal
  kRandom,   // drawn from the seed
};

struct PhotocellOptions {
  double x_lo = -0.5;  // lower end of the stated range, length units (the calibration
                       // sweep swings to -X0)
  double x_hi = 1.6;   // upper end, length units (> x_lo)
  // 0: linear; 1: strongly nonlinear (the slope varies ~7x across the range,
  // as the CALIBR-era cells did). Values in [0, 1].
  double nonlinearity = 0.5;
  double nominal_span_v = 1.0;  // |V(x_hi) - V(x_lo)| before the cell's +-20 % spread, V
  double nominal_mid_v = 0.0;   // V at the middle of the range before the cell's spread, V
  PhotocellPolarity polarity = PhotocellPolarity::kFalling;
  void Check() const;  // throws std::invalid_argument
};

class SimulatedPhotocell {
 public:
  SimulatedPhotocell() = default;
  // Explicit parameters (rate >= 0, gain != 0); throws std::invalid_argument.
  SimulatedPhotocell(double x_center, double rate_per_length, double gain_v_per_length,
                 double volts_at_center, double x_lo, double x_hi);
  // A cell drawn from `seed`: the same seed and options give the same curve on
  // every platform (the generator is std::mt19937_64 with its bits turned into
  // doubles here, not by the library's distributions).
  static SimulatedPhotocell FromSeed(std::uint64_t seed, const PhotocellOptions& options);

  double Volts(double x) const;                // V(X), V
  double SlopeVoltsPerLength(double x) const;  // dV/dX, V per length unit
  // The exact inverse X(V). Throws std::domain_error outside the curve's
  // open image (the saturation levels), where no displacement gives V.
  double Displacement(double volts) const;
  std::vector<double> Volts(std::span<const double> x) const;

  double x_center() const { return x_center_; }
  double rate_per_length() const { return rate_; }
  double gain_v_per_length() const { return gain_; }
  double volts_at_center() const { return volts_at_center_; }
  double x_lo() const { return x_lo_; }  // the stated range, length units
  double x_hi() const { return x_hi_; }

 private:
  double x_center_ = 0.0;
  double rate_ = 0.0;  // 1 / length units
  double gain_ = -1.0;
  double volts_at_center_ = 0.0;
  double x_lo_ = 0.0;
  double x_hi_ = 1.0;
};

// {"model": "tanh", "formula": ..., parameters, "x_lo", "x_hi"}; from_json
// reads it back (throws nlohmann::json::exception or std::invalid_argument).
void to_json(nlohmann::json& j, const SimulatedPhotocell& curve);
void from_json(const nlohmann::json& j, SimulatedPhotocell& curve);

// `volts` plus independent Gaussian noise of standard deviation sigma_v (V),
// reproducible from `seed` on every platform (Box-Muller on std::mt19937_64).
std::vector<double> AddGaussianNoise(std::span<const double> volts, double sigma_v,
                                     std::uint64_t seed);

struct CalibrationSweepOptions {
  double pendulum_length = 22.0;    // L, length units
  double gravity = 385.644;         // g, length/s^2
  double release_x = 0.234;         // X0 of the bar released alone, length units
  double duration_s = 0.5;          // sweep length from the release, s (the example
                                    // session's 0.05 s/div x 10 div)
  double sample_rate_hz = 10000.0;  // Hz
};

struct CalibrationSweep {
  std::vector<double> time_s;  // s since release
  std::vector<double> x;       // the free pendulum's X(t), length units (integrated)
  std::vector<double> volts;   // the cell's noiseless output, V
};

// The bar swings freely from rest at X0 (exact pendulum, integrated by
// SimulateFreeSwing); volts = curve(X(t)). Add noise with AddGaussianNoise.
CalibrationSweep MakeCalibrationSweep(const SimulatedPhotocell& curve,
                                      const CalibrationSweepOptions& options);

}  // namespace impactlab
