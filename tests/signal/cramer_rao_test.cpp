// Tests of the Cramér-Rao bound against the closed form for a tone.
#include <catch2/catch.hpp>

#include "signal/cramer_rao.h"

namespace impactlab {
namespace {

TEST_CASE("With zeta = 0 known, the frequency bound is the classical tone bound", "[crb]") {
  const double rate = 1000.0, sigma = 0.1, amplitude = 1.0;
  const double eta = amplitude * amplitude / (2.0 * sigma * sigma);
  for (std::size_t n : {256, 1024, 4096}) {
    const CramerRaoBound bound =
        DampedCosineCrb({amplitude, 0.3, 123.4, 0.0}, rate, n, sigma, /*decay_known=*/true);
    INFO("N = " << n);
    CHECK(bound.frequency_hz / rate ==
          Approx(ToneFrequencyCrbCyclesPerSample(n, eta)).epsilon(0.01));
    CHECK(bound.damping_ratio == 0.0);
  }
}

TEST_CASE("The bounds scale with the noise and grow when the decay is estimated", "[crb]") {
  const DampedCosine signal{2.0, 0.5, 11.5, 0.02};
  const CramerRaoBound a = DampedCosineCrb(signal, 1000.0, 3000, 0.1);
  const CramerRaoBound b = DampedCosineCrb(signal, 1000.0, 3000, 0.2);
  CHECK(b.frequency_hz == Approx(2.0 * a.frequency_hz).epsilon(1e-12));
  CHECK(b.damping_ratio == Approx(2.0 * a.damping_ratio).epsilon(1e-12));
  CHECK(b.amplitude == Approx(2.0 * a.amplitude).epsilon(1e-12));
  const CramerRaoBound known = DampedCosineCrb(signal, 1000.0, 3000, 0.1, true);
  CHECK(a.frequency_hz > known.frequency_hz);
  CHECK_THROWS_AS(DampedCosineCrb({1, 0, 1, 1.5}, 1000.0, 100, 0.1), std::invalid_argument);
}

}  // namespace
}  // namespace impactlab
