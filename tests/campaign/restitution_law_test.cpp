// Restitution's speed law fitted to one session's impacts
// (campaign/restitution_law.h), against impacts made from a known law: runs
// whose every impact keeps e(v) of the speed it meets, as a pendulum's
// successive maxima do.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "campaign/restitution_law.h"
#include "model/power_law_contact.h"

namespace impactlab {
namespace {

// Runs from each release speed, `rebounds` impacts each, every speed read
// with relative error `sigma` (the noise drawn when `random` is given).
template <typename Law>
std::vector<ImpactRestitution> Impacts(const std::vector<double>& releases, int rebounds,
                                       double sigma, Law law, std::mt19937_64* random = nullptr) {
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<ImpactRestitution> out;
  for (std::size_t r = 0; r < releases.size(); ++r) {
    std::vector<double> read;
    double v = releases[r];
    for (int n = 0; n <= rebounds; ++n) {
      read.push_back(v * (random ? 1.0 + noise(*random) : 1.0));
      v *= law(v);
    }
    for (int n = 0; n < rebounds; ++n) {
      out.push_back(
          {"run" + std::to_string(r), n, read[n], read[n + 1] / read[n], 0.0, sigma, sigma});
    }
  }
  return out;
}

const std::vector<double> kReleases = {2.0, 5.0, 9.0, 15.0, 22.0, 30.0};  // in/s

TEST_CASE("restitution law: Hunt-Crossley's e(chi v) comes back as chi with beta = 1") {
  const double chi = 0.02;  // s/in: e from 0.98 to 0.67 over these speeds
  const auto hunt_crossley = [&](double v) { return HuntCrossleyRestitution(chi * v); };
  const SessionRestitutionLaw law = FitRestitutionLaw(Impacts(kReleases, 6, 1e-4, hunt_crossley));
  REQUIRE(law.ok);
  CHECK(law.impacts == 36);
  CHECK(law.dof == 34);
  CHECK(std::exp(law.log_eps) / law.reference_speed == Approx(chi).epsilon(1e-7));
  CHECK(law.exponent == Approx(1.0).epsilon(1e-7));
  CHECK(law.chi2 < 1e-6);
  CHECK(law.covariance[0] > 0.0);
  CHECK(law.covariance[1] == law.covariance[2]);
}

TEST_CASE("restitution law: a restitution whose damping grows as v^(1/5) gives beta = 1/5") {
  // eps = 0.1 (v/10)^(1/5): small damping, as a quasi-static viscoelastic
  // sphere's 1 - e ~ v^(1/5).
  const auto viscoelastic = [](double v) {
    return HuntCrossleyRestitution(0.1 * std::pow(v / 10.0, 0.2));
  };
  const SessionRestitutionLaw law = FitRestitutionLaw(Impacts(kReleases, 6, 1e-4, viscoelastic));
  REQUIRE(law.ok);
  CHECK(law.exponent == Approx(0.2).epsilon(1e-6));
  CHECK(std::exp(law.log_eps) * std::pow(10.0 / law.reference_speed, 0.2) ==
        Approx(0.1).epsilon(1e-6));
}

TEST_CASE("restitution law: its errors are honest for noisy maxima") {
  const double chi = 0.02;
  const auto hunt_crossley = [&](double v) { return HuntCrossleyRestitution(chi * v); };
  std::mt19937_64 random(7);
  std::vector<double> pulls_chi, pulls_beta, reduced;
  for (int trial = 0; trial < 200; ++trial) {
    const SessionRestitutionLaw law =
        FitRestitutionLaw(Impacts(kReleases, 6, 3e-4, hunt_crossley, &random));
    REQUIRE(law.ok);
    const double log_chi = law.log_eps - std::log(law.reference_speed);
    pulls_chi.push_back((log_chi - std::log(chi)) / std::sqrt(law.covariance[0]));
    pulls_beta.push_back((law.exponent - 1.0) / std::sqrt(law.covariance[3]));
    reduced.push_back(law.chi2 / law.dof);
  }
  const auto rms = [](const std::vector<double>& x) {
    double s = 0.0;
    for (double v : x) s += v * v;
    return std::sqrt(s / static_cast<double>(x.size()));
  };
  double mean_reduced = 0.0;
  for (double r : reduced) mean_reduced += r / static_cast<double>(reduced.size());
  // 200 trials: an honest RMS is 1 within about 0.05 x 3.
  CHECK(rms(pulls_chi) == Approx(1.0).margin(0.15));
  CHECK(rms(pulls_beta) == Approx(1.0).margin(0.15));
  CHECK(mean_reduced == Approx(1.0).margin(0.05));
}

TEST_CASE("restitution law: what cannot be fitted says why") {
  const auto elastic = [](double) { return 1.0; };
  SECTION("too few impacts") {
    const SessionRestitutionLaw law = FitRestitutionLaw(Impacts({5.0}, 2, 1e-4, elastic));
    CHECK_FALSE(law.ok);
    CHECK(law.reason.find("the law needs 3") != std::string::npos);
  }
  SECTION("no damping") {
    const SessionRestitutionLaw law = FitRestitutionLaw(Impacts(kReleases, 3, 1e-4, elastic));
    CHECK_FALSE(law.ok);
    CHECK(law.reason.find("no damping") != std::string::npos);
  }
  SECTION("maxima without errors") {
    const auto half = [](double) { return 0.5; };
    const SessionRestitutionLaw law = FitRestitutionLaw(Impacts(kReleases, 3, 0.0, half));
    CHECK_FALSE(law.ok);
  }
}

}  // namespace
}  // namespace impactlab
