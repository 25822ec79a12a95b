#include "synth/photocell.h"

#include <cmath>
#include <numeric>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "model/pendulum.h"

namespace impactlab {
namespace {

PhotocellOptions WithNonlinearity(double nonlinearity) {
  PhotocellOptions o;
  o.nonlinearity = nonlinearity;
  return o;
}

std::vector<double> Grid(double lo, double hi, int count) {
  std::vector<double> x(count);
  for (int i = 0; i < count; ++i) x[i] = lo + (hi - lo) * i / (count - 1);
  return x;
}

TEST_CASE("photocell: curves are strictly monotone over their range") {
  for (double nonlinearity : {0.0, 0.3, 1.0}) {
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      PhotocellOptions o = WithNonlinearity(nonlinearity);
      o.polarity = PhotocellPolarity::kRandom;
      const SimulatedPhotocell c = SimulatedPhotocell::FromSeed(seed, o);
      const double sign = c.gain_v_per_length() > 0.0 ? 1.0 : -1.0;
      const std::vector<double> x = Grid(o.x_lo, o.x_hi, 2001);
      for (std::size_t i = 1; i < x.size(); ++i) {
        CHECK(sign * (c.Volts(x[i]) - c.Volts(x[i - 1])) > 0.0);
        CHECK(sign * c.SlopeVoltsPerLength(x[i]) > 0.0);
      }
      // The span across the range is the nominal one within the cell's spread.
      const double span = std::abs(c.Volts(o.x_hi) - c.Volts(o.x_lo));
      CHECK(span >= 0.8 * o.nominal_span_v - 1e-12);
      CHECK(span <= 1.2 * o.nominal_span_v + 1e-12);
    }
  }
}

TEST_CASE("photocell: light falls as displacement grows unless the amplifier inverts it") {
  PhotocellOptions o;
  CHECK(SimulatedPhotocell::FromSeed(7, o).gain_v_per_length() < 0.0);
  o.polarity = PhotocellPolarity::kRising;
  CHECK(SimulatedPhotocell::FromSeed(7, o).gain_v_per_length() > 0.0);
  o.polarity = PhotocellPolarity::kRandom;
  int rising = 0;
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    rising += SimulatedPhotocell::FromSeed(seed, o).gain_v_per_length() > 0.0;
  }
  CHECK(rising > 5);
  CHECK(rising < 35);
}

TEST_CASE("photocell: the inverse undoes the curve to 1e-12") {
  for (double nonlinearity : {0.0, 0.5, 1.0}) {
    for (std::uint64_t seed = 100; seed < 110; ++seed) {
      const PhotocellOptions o = WithNonlinearity(nonlinearity);
      const SimulatedPhotocell c = SimulatedPhotocell::FromSeed(seed, o);
      for (double x : Grid(o.x_lo, o.x_hi, 501)) {
        CHECK(std::abs(c.Displacement(c.Volts(x)) - x) < /*max_inverse_error=*/1e-12);
      }
    }
  }
}

TEST_CASE("photocell: the inverse refuses voltages no displacement gives") {
  const SimulatedPhotocell c = SimulatedPhotocell::FromSeed(3, WithNonlinearity(1.0));
  const double saturation =
      c.volts_at_center() + std::abs(c.gain_v_per_length()) / c.rate_per_length();
  CHECK_THROWS_AS(c.Displacement(saturation + 0.1), std::domain_error);
}

TEST_CASE("photocell: nonlinearity 0 is linear and 1 is strongly curved") {
  const PhotocellOptions linear = WithNonlinearity(0.0);
  const SimulatedPhotocell flat = SimulatedPhotocell::FromSeed(11, linear);
  CHECK(flat.SlopeVoltsPerLength(linear.x_lo) == flat.SlopeVoltsPerLength(linear.x_hi));
  const PhotocellOptions strong = WithNonlinearity(1.0);
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    const SimulatedPhotocell c = SimulatedPhotocell::FromSeed(seed, strong);
    double lo = INFINITY, hi = 0.0;
    for (double x : Grid(strong.x_lo, strong.x_hi, 201)) {
      lo = std::min(lo, std::abs(c.SlopeVoltsPerLength(x)));
      hi = std::max(hi, std::abs(c.SlopeVoltsPerLength(x)));
    }
    CHECK(hi / lo > 2.0);
  }
}

TEST_CASE("photocell: the same seed gives the same curve, another seed another") {
  const PhotocellOptions o;
  const nlohmann::json a = SimulatedPhotocell::FromSeed(42, o);
  const nlohmann::json b = SimulatedPhotocell::FromSeed(42, o);
  const nlohmann::json c = SimulatedPhotocell::FromSeed(43, o);
  CHECK(a == b);
  CHECK(a != c);
}

TEST_CASE("photocell: JSON round trip keeps the curve exactly") {
  const SimulatedPhotocell c = SimulatedPhotocell::FromSeed(5, WithNonlinearity(0.8));
  const nlohmann::json j = c;
  CHECK(j.at("model") == "tanh");
  const SimulatedPhotocell back = nlohmann::json::parse(j.dump()).get<SimulatedPhotocell>();
  for (double x : Grid(-0.5, 1.6, 50)) CHECK(back.Volts(x) == c.Volts(x));
}

TEST_CASE("photocell: noise is reproducible and has the requested sigma") {
  const std::vector<double> clean(20000, 1.5);
  const std::vector<double> a = AddGaussianNoise(clean, 0.01, 9);
  const std::vector<double> b = AddGaussianNoise(clean, 0.01, 9);
  const std::vector<double> c = AddGaussianNoise(clean, 0.01, 10);
  CHECK(a == b);
  CHECK(a != c);
  double mean = 0.0;
  for (double v : a) mean += v - 1.5;
  mean /= a.size();
  double variance = 0.0;
  for (double v : a) variance += (v - 1.5 - mean) * (v - 1.5 - mean);
  variance /= a.size() - 1;
  CHECK(std::abs(mean) < 4.0 * 0.01 / std::sqrt(20000.0));
  CHECK(std::sqrt(variance) == Approx(0.01).epsilon(0.03));
  CHECK(AddGaussianNoise(clean, 0.0, 1) == clean);
}

TEST_CASE("photocell: a calibration sweep is the cell reading the exact free swing") {
  const SimulatedPhotocell cell = SimulatedPhotocell::FromSeed(21, WithNonlinearity(0.7));
  CalibrationSweepOptions o;
  o.release_x = 0.405;
  o.duration_s = 1.6;  // past a full period: the bar swings through -X0 and back
  o.sample_rate_hz = 1000.0;
  const CalibrationSweep sweep = MakeCalibrationSweep(cell, o);
  REQUIRE(sweep.time_s.size() == 1601);
  const Pendulum p{o.pendulum_length, o.gravity, PendulumConvention::kExact};
  const double quarter_s = 0.5 * HalfPeriod(p, o.release_x);
  double lowest = 0.0;
  for (std::size_t i = 0; i < sweep.time_s.size(); ++i) {
    const double t = sweep.time_s[i];
    CHECK(sweep.volts[i] == cell.Volts(sweep.x[i]));
    CHECK(std::abs(cell.Displacement(sweep.volts[i]) - sweep.x[i]) < 1e-12);
    if (t <= quarter_s) {
      CHECK(std::abs(sweep.x[i] - ReleaseSwingDisplacement(p, o.release_x, t)) < 1e-9);
    }
    lowest = std::min(lowest, sweep.x[i]);
  }
  // The lowest 1 ms sample, not the refined trough.
  CHECK(lowest == Approx(-o.release_x).epsilon(1e-5));
}

}  // namespace
}  // namespace impactlab
