// The comb's local floor (digitize/grid_comb.h) against its definition, the
// median of each window computed afresh, and the comb found in a profile of
// known lines.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "digitize/grid_comb.h"

namespace impactlab::digitize {
namespace {

// The profile less the median of the positions within `half` either side
// (the upper median where the window is even, at the ends), never below 0.
std::vector<double> AboveFloorByDefinition(const std::vector<double>& profile, int half) {
  const int size = static_cast<int>(profile.size());
  std::vector<double> lifted(size);
  for (int i = 0; i < size; ++i) {
    std::vector<double> window(profile.begin() + std::max(0, i - half),
                               profile.begin() + std::min(size, i + half + 1));
    std::sort(window.begin(), window.end());
    lifted[i] = std::max(0.0, profile[i] - window[window.size() / 2]);
  }
  return lifted;
}

TEST_CASE("the comb's floor is each window's median, ties and ends included",
          "[digitize][grid_comb]") {
  std::mt19937 random(31);
  for (const int size : {1, 2, 5, 17, 18, 40, 700}) {
    for (const int half : {0, 1, 3, 8, 30}) {
      // Whole values from a few levels: many ties, entering and leaving
      // values equal, runs of one value.
      std::uniform_int_distribution<int> level(0, 6);
      std::vector<double> profile(size);
      for (double& v : profile) v = level(random);
      CHECK(AboveFloor(profile, half) == AboveFloorByDefinition(profile, half));
      std::normal_distribution<double> noise(5.0, 2.0);
      for (double& v : profile) v = noise(random);
      CHECK(AboveFloor(profile, half) == AboveFloorByDefinition(profile, half));
    }
  }
}

TEST_CASE("the comb's lines are found where they were put", "[digitize][grid_comb]") {
  // Eleven lines 23.4 positions apart from 40.3, on a slope and noise.
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::vector<double> profile(400);
  for (int i = 0; i < 400; ++i) profile[i] = 10.0 + 0.02 * i + noise(random);
  for (int k = 0; k < 11; ++k) {
    const double at = 40.3 + 23.4 * k;
    for (int i = 0; i < 400; ++i) profile[i] += 6.0 * std::exp(-0.5 * std::pow((i - at) / 0.8, 2));
  }
  const std::vector<CombLine> lines = FindComb(profile, 11, 15.0, 40.0);
  REQUIRE(lines.size() == 11);
  for (int k = 0; k < 11; ++k) CHECK(std::abs(lines[k].rho - (40.3 + 23.4 * k)) < 0.3);
}

}  // namespace
}  // namespace impactlab::digitize
