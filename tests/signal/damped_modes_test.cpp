// Tests of the damped-mode fit: exact recovery of clean signals, and in white
// noise estimates that scatter as their reported sigmas and near the
// Cramér-Rao bound.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "signal/cramer_rao.h"
#include "signal/damped_modes.h"
#include "tests/signal/test_signals.h"

namespace impactlab {
namespace {

using testing::AddNoise;
using testing::DampedCosines;
using testing::Tone;

TEST_CASE("A clean damped cosine with an offset is recovered exactly", "[damped_modes]") {
  const double rate = 1000.0;
  const auto y = DampedCosines({{2.0, 0.7, 11.5, 0.02}}, rate, 3000, 0.3);
  const DampedModeFit fit = FitDampedModes(y, rate, {});
  REQUIRE(fit.ok);
  REQUIRE(fit.modes.size() == 1);  // the second mode asked for is not in the data
  const DampedMode& mode = fit.modes[0];
  CHECK(mode.frequency_hz.value == Approx(11.5).epsilon(1e-10));
  CHECK(mode.damping_ratio.value == Approx(0.02).epsilon(1e-8));
  CHECK(mode.amplitude.value == Approx(2.0).epsilon(1e-8));
  CHECK(mode.phase_rad.value == Approx(0.7).epsilon(1e-8));
  CHECK(mode.natural_frequency_hz == Approx(11.5 / std::sqrt(1 - 0.02 * 0.02)).epsilon(1e-10));
  CHECK(fit.offset.value == Approx(0.3).epsilon(1e-8));
  CHECK(fit.residual_rms < 1e-9);
}

TEST_CASE("Two modes, a real decay and an offset are recovered together", "[damped_modes]") {
  const double rate = 1000.0;
  const std::size_t n = 3000;
  auto y = DampedCosines({{1.0, 0.2, 11.5, 0.02}, {0.3, -1.0, 47.0, 0.01}}, rate, n, -0.2);
  for (std::size_t i = 0; i < n; ++i) y[i] += 0.8 * std::exp(-15.0 * static_cast<double>(i) / rate);
  const DampedModeFit fit = FitDampedModes(y, rate, {});
  REQUIRE(fit.ok);
  REQUIRE(fit.modes.size() == 2);
  REQUIRE(fit.decays.size() == 1);
  CHECK(fit.modes[0].frequency_hz.value == Approx(11.5).epsilon(1e-9));
  CHECK(fit.modes[0].damping_ratio.value == Approx(0.02).epsilon(1e-7));
  CHECK(fit.modes[1].frequency_hz.value == Approx(47.0).epsilon(1e-9));
  CHECK(fit.modes[1].damping_ratio.value == Approx(0.01).epsilon(1e-7));
  CHECK(fit.decays[0].rate_per_s.value == Approx(15.0).epsilon(1e-7));
  CHECK(fit.decays[0].amplitude.value == Approx(0.8).epsilon(1e-7));
  CHECK(fit.offset.value == Approx(-0.2).epsilon(1e-7));
  CHECK(fit.covariance_ok);
}

TEST_CASE("In white noise the fit scatters as its sigmas, near the Cramer-Rao bound",
          "[damped_modes]") {
  const double rate = 1000.0, f = 23.4, zeta = 0.01, amplitude = 1.0;
  const std::size_t n = 1000;
  const double noise = amplitude / std::sqrt(2.0 * 100.0);  // SNR 20 dB
  const CramerRaoBound bound = DampedCosineCrb({amplitude, 0.5, f, zeta}, rate, n, noise);
  const int trials = 60;
  double sum_z2_f = 0, sum_z2_zeta = 0, sum_e2_f = 0, sum_e2_zeta = 0, sum_sigma_f = 0;
  for (int trial = 0; trial < trials; ++trial) {
    auto y = DampedCosines({{amplitude, 0.5, f, zeta}}, rate, n);
    AddNoise(y, noise, 100 + trial);
    const DampedModeFit fit = FitDampedModes(y, rate, {.fit_offset = false});
    REQUIRE(fit.ok);
    const DampedMode& mode = fit.modes[0];
    const double ef = mode.frequency_hz.value - f, ez = mode.damping_ratio.value - zeta;
    sum_e2_f += ef * ef;
    sum_e2_zeta += ez * ez;
    sum_z2_f += ef * ef / (mode.frequency_hz.sigma * mode.frequency_hz.sigma);
    sum_z2_zeta += ez * ez / (mode.damping_ratio.sigma * mode.damping_ratio.sigma);
    sum_sigma_f += mode.frequency_hz.sigma;
  }
  // Ratios of RMS errors to the bound, and of errors to the reported sigmas
  // (60 trials: the RMS of a unit normal lies in [0.8, 1.2] with ~95 %).
  CHECK(std::sqrt(sum_e2_f / trials) / bound.frequency_hz < 1.3);
  CHECK(std::sqrt(sum_e2_zeta / trials) / bound.damping_ratio < 1.3);
  CHECK(std::sqrt(sum_z2_f / trials) == Approx(1.0).margin(0.3));
  CHECK(std::sqrt(sum_z2_zeta / trials) == Approx(1.0).margin(0.3));
  CHECK(sum_sigma_f / trials / bound.frequency_hz == Approx(1.0).margin(0.15));
}

TEST_CASE("The matrix pencil alone is close at high SNR", "[damped_modes]") {
  const double rate = 500.0;
  auto y = DampedCosines({{1.0, 0.0, 31.0, 0.03}}, rate, 2000);
  AddNoise(y, 0.01, 5);
  const std::vector<DampedMode> modes = MatrixPencilModes(y, rate, {});
  REQUIRE_FALSE(modes.empty());
  CHECK(modes[0].frequency_hz.value == Approx(31.0).epsilon(1e-3));
  CHECK(modes[0].damping_ratio.value == Approx(0.03).epsilon(0.05));
}

TEST_CASE("Pure noise or too short a window is a result that is not ok", "[damped_modes]") {
  std::vector<double> noise(2000, 0.0);
  AddNoise(noise, 1.0, 9);
  const DampedModeFit fit = FitDampedModes(noise, 1000.0, {});
  CHECK_FALSE(fit.ok);
  CHECK_FALSE(fit.reason.empty());
  const std::vector<double> short_window(20, 1.0);
  CHECK_FALSE(FitDampedModes(short_window, 1000.0, {}).ok);
}

TEST_CASE("Damped-mode options: the defaults pass Check and nonsense is refused",
          "[damped_modes]") {
  std::string error;
  CHECK(DampedModeOptions{}.Check(&error));
  CHECK_FALSE(DampedModeOptions{.modes = 0}.Check(&error));
  CHECK_FALSE(DampedModeOptions{.pencil_fraction = 0.9}.Check(&error));
  const std::vector<double> y(200, 0.0);
  CHECK_THROWS_AS(FitDampedModes(y, 1000.0, {.max_iterations = 0}), std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
