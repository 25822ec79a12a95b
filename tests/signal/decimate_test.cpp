// Tests of the decimators: streaming equals batch, the FIR's pass and stop
// bands, and the plot decimation keeping spikes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "signal/decimate.h"
#include "tests/signal/test_signals.h"

namespace impactlab {
namespace {

using testing::DampedCosines;

// Amplitude of a steady sinusoid of `f_hz` after decimation, away from the edges.
double GainAt(double f_hz, double rate_hz, int factor) {
  const auto y = DampedCosines({{1.0, 0.3, f_hz, 0.0}}, rate_hz, 40000);
  const std::vector<double> out = Decimate(y, factor);
  double peak = 0.0;
  for (std::size_t i = 100; i + 100 < out.size(); ++i) peak = std::max(peak, std::abs(out[i]));
  return peak;
}

TEST_CASE("Streaming in uneven blocks gives the batch result exactly", "[decimate]") {
  std::mt19937_64 engine(3);
  std::normal_distribution<double> normal;
  std::vector<double> x(10007);
  for (double& v : x) v = normal(engine);
  for (int factor : {1, 3, 7}) {
    const std::vector<double> batch = Decimate(x, factor);
    CHECK(batch.size() == (x.size() + factor - 1) / factor);
    StreamingDecimator decimator(factor);
    std::vector<double> streamed;
    std::size_t at = 0;
    std::uniform_int_distribution<std::size_t> size(1, 900);
    while (at < x.size()) {
      const std::size_t n = std::min(size(engine), x.size() - at);
      decimator.Push(std::span<const double>(x).subspan(at, n), streamed);
      at += n;
    }
    decimator.Finish(streamed);
    CHECK(streamed == batch);
  }
}

TEST_CASE("The decimation FIR is flat in the band and rejects aliases", "[decimate]") {
  const double rate = 10000.0;
  const int factor = 10;  // output rate 1000 Hz
  CHECK(GainAt(50.0, rate, factor) == Approx(1.0).margin(1e-3));
  CHECK(GainAt(350.0, rate, factor) == Approx(1.0).margin(1e-2));
  CHECK(GainAt(600.0, rate, factor) < 1e-3);  // would alias to 400 Hz
  CHECK(GainAt(2300.0, rate, factor) < 1e-3);
  const std::vector<double> taps = DecimationTaps(factor);
  CHECK(taps.size() == 2 * kDecimationEdgeSamples * factor + 1);
  double sum = 0.0;
  for (double t : taps) sum += t;
  CHECK(sum == Approx(1.0).epsilon(1e-14));
}

TEST_CASE("Plot decimation keeps a one-sample spike and the point budget", "[decimate]") {
  std::vector<double> y(100000, 0.0);
  y[54321] = 7.0;
  const DecimatedSeries plot = MinMaxDecimate(y, 2.0, 1e-3, 1000);
  CHECK(plot.value.size() <= 1000);
  CHECK(*std::max_element(plot.value.begin(), plot.value.end()) == 7.0);
  const auto at = std::max_element(plot.value.begin(), plot.value.end()) - plot.value.begin();
  CHECK(plot.time_s[static_cast<std::size_t>(at)] == Approx(2.0 + 54.321));
  const std::vector<double> small(10, 1.0);
  CHECK(MinMaxDecimate(small, 0.0, 1.0, 1000).value.size() == 10);
}

}  // namespace
}  // namespace impactlab
