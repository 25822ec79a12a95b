// Tests of the spectrum: peak frequencies against the tones' exact values (bias
// far below a bin), leakage not taken for peaks, PSD scaling against white
// noise's closed form.
#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>
#include <vector>

#include "signal/spectrum.h"
#include "tests/signal/test_signals.h"

namespace impactlab {
namespace {

using testing::AddNoise;
using testing::DampedCosines;
using testing::Tone;

TEST_CASE("The dominant frequency of a clean tone is within 1e-4 bin", "[spectrum]") {
  const double rate = 1000.0;
  const std::size_t n = 1000;
  const double bin = rate / n;
  for (double fraction : {0.0, 0.13, 0.5, 0.77}) {
    const double f = (37.0 + fraction) * bin;
    const auto y = DampedCosines({{1.0, 0.4, f, 0.0}}, rate, n);
    const Spectrum spectrum = ComputeSpectrum(y, rate, {});
    REQUIRE_FALSE(spectrum.peaks.empty());
    INFO("fraction of a bin " << fraction);
    CHECK(std::abs(spectrum.peaks[0].frequency_hz - f) / bin < 1e-4);
    CHECK(spectrum.peaks[0].amplitude == Approx(1.0).epsilon(0.02));
  }
}

TEST_CASE("The dominant frequency of a damped tone is its damped frequency", "[spectrum]") {
  // A real envelope makes the windowed magnitude symmetric about the tone.
  const double rate = 1000.0;
  const std::size_t n = 3000;
  const double f = 11.5175;
  const auto y = DampedCosines({{6.0, 1.1, f, 0.0196}}, rate, n, 0.3);
  const Spectrum spectrum = ComputeSpectrum(y, rate, {.detrend = Detrend::kMean});
  REQUIRE_FALSE(spectrum.peaks.empty());
  CHECK(std::abs(spectrum.peaks[0].frequency_hz - f) / spectrum.resolution_hz < 1e-4);
  CHECK(spectrum.resolution_hz == Approx(rate / n));
}

TEST_CASE("A weak second tone is a next peak; sidelobes of a strong one are not", "[spectrum]") {
  const double rate = 1000.0;
  const std::size_t n = 2000;
  auto y = DampedCosines({{1.0, 0.0, 50.3, 0.0}, {0.02, 1.0, 80.7, 0.0}}, rate, n);
  AddNoise(y, 1e-4, 7);
  const Spectrum spectrum = ComputeSpectrum(y, rate, {});
  REQUIRE(spectrum.peaks.size() == 2);
  CHECK(spectrum.peaks[0].frequency_hz == Approx(50.3).margin(1e-4));
  CHECK(spectrum.peaks[1].frequency_hz == Approx(80.7).margin(1e-3));
  CHECK(spectrum.peaks[1].relative_db == Approx(20.0 * std::log10(0.02)).margin(1.0));

  auto alone = DampedCosines({{1.0, 0.0, 50.3, 0.0}}, rate, n);
  AddNoise(alone, 1e-4, 8);
  CHECK(ComputeSpectrum(alone, rate, {}).peaks.size() == 1);
}

TEST_CASE("White noise: the PSD averages to 2 sigma^2 / rate, Welch's too", "[spectrum]") {
  const double rate = 2000.0, sigma = 0.3;
  std::vector<double> y(65536, 0.0);
  AddNoise(y, sigma, 11);
  const Spectrum spectrum = ComputeSpectrum(y, rate, {});
  const double expected = 2.0 * sigma * sigma / rate;
  auto mean_of = [](const std::vector<double>& v) {
    return std::accumulate(v.begin() + 10, v.end() - 10, 0.0) / static_cast<double>(v.size() - 20);
  };
  CHECK(mean_of(spectrum.psd) == Approx(expected).epsilon(0.03));
  CHECK(spectrum.segments_averaged > 8);
  REQUIRE(spectrum.welch_psd.size() == 4096 / 2 + 1);
  CHECK(spectrum.welch_frequency_hz.back() == Approx(rate / 2));
  CHECK(mean_of(spectrum.welch_psd) == Approx(expected).epsilon(0.03));
  CHECK(spectrum.peaks.empty());  // no noise bump passes the false-alarm threshold
}

TEST_CASE("A weak tone in a long noisy record is found at the record's resolution", "[spectrum]") {
  const double rate = 1000.0;
  auto y = DampedCosines({{0.1, 0.2, 123.456, 0.0}}, rate, 100000);
  AddNoise(y, 0.5, 12);  // -20 dB per sample, +27 dB in the record's resolution
  const Spectrum spectrum = ComputeSpectrum(y, rate, {});
  REQUIRE(spectrum.peaks.size() == 1);
  CHECK(spectrum.segments_averaged > 1);
  CHECK(spectrum.peaks[0].frequency_hz == Approx(123.456).margin(0.1 * spectrum.resolution_hz));
}

TEST_CASE("Trend removal takes out a ramp exactly", "[spectrum]") {
  std::vector<double> y(101);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] = 3.0 - 0.25 * static_cast<double>(i);
  RemoveTrend(y, Detrend::kLinear);
  for (double v : y) CHECK(std::abs(v) < 1e-12);
}

TEST_CASE("Spectrum options: the defaults pass Check and nonsense is refused", "[spectrum]") {
  std::string error;
  CHECK(SpectrumOptions{}.Check(&error));
  CHECK_FALSE(SpectrumOptions{.zero_padding = 0.5}.Check(&error));
  CHECK_FALSE(SpectrumOptions{.min_frequency_hz = 5, .max_frequency_hz = 2}.Check(&error));
  const std::vector<double> short_record(8, 1.0);
  CHECK_THROWS_AS(ComputeSpectrum(short_record, 100.0, {}), std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
