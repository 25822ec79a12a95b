// The contact edge from the levels' ends (digitize/level_jump.h) on profiles
// made in closed form: a beam of Gaussian section whose level ends in a round
// cap (as the renderer draws it), a grid line near the edge, a saturating
// tone curve acting on their sum, and noise.
#include <cmath>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "digitize/level_jump.h"

namespace impactlab::digitize {
namespace {

constexpr double kBeamSigmaPx = 1.5;
constexpr double kJumpBackground = 0.1, kLevel = 1.0, kLineHeight = 0.35, kLineSigmaPx = 0.8;

// A photo's saturating response to exposure.
double SaturatingTone(double exposure) { return 1.0 - std::exp(-1.5 * exposure); }

// The beam's exposure `beyond_px` past its level's end (negative: on it).
double Cap(double beyond_px) {
  if (beyond_px <= 0.0) return 1.0;
  const double z = beyond_px / kBeamSigmaPx;
  return std::exp(-0.5 * z * z);
}

double Line(double u, double line_px) {
  const double z = (u - line_px) / kLineSigmaPx;
  return kLineHeight * std::exp(-0.5 * z * z);
}

struct Rows {
  std::vector<double> offsets, leaving, reaching;
  std::vector<double> line;  // the line's own light where no level is, as a template is read
};

Rows MakeRows(double edge_px, double line_px, double noise, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, noise);
  Rows rows;
  for (double u = -20.0; u <= 20.0; u += 0.5) {
    const double line = Line(u, line_px);
    rows.offsets.push_back(u);
    rows.leaving.push_back(SaturatingTone(kJumpBackground + kLevel * Cap(u - edge_px) + line) +
                           normal(random));
    rows.reaching.push_back(SaturatingTone(kJumpBackground + kLevel * Cap(edge_px - u) + line) +
                            normal(random));
    rows.line.push_back(SaturatingTone(kJumpBackground + line) - SaturatingTone(kJumpBackground));
  }
  return rows;
}

LevelJump Fit(const Rows& rows, bool with_line) {
  LevelJumpSearch search;
  search.centre_lo_px = -6.0;
  search.centre_hi_px = 6.0;
  search.half_window_px = 2.0 * 2.355 * kBeamSigmaPx + 2.0;
  if (with_line) search.lines.push_back(rows.line);
  return FitLevelJump(rows.offsets, rows.leaving, rows.reaching, search);
}

}  // namespace

TEST_CASE("level jump: the edge is where the two levels' ends mirror each other") {
  for (const double edge : {-2.3, 0.0, 0.37, 3.1}) {
    const LevelJump jump = Fit(MakeRows(edge, 100.0, 0.0, 1), false);
    INFO("edge at " << edge << " px");
    REQUIRE(jump.found);
    CHECK(jump.centre_px == Approx(edge).margin(0.01));
    CHECK(jump.step > 0.5);
  }
}

TEST_CASE(
    "level jump: a grid line on or beside the edge, under a saturating tone, moves it little") {
  // The line shows fainter on the bright level than on the dark background:
  // what is left of it in the difference is fitted as its profile times how
  // differently bright the two rows are.
  const double edge = 0.4;
  for (const double from_edge : {-4.0, -1.5, -0.6, 0.0, 0.8, 2.0, 5.0}) {
    const Rows rows = MakeRows(edge, edge + from_edge, 0.0, 1);
    const LevelJump jump = Fit(rows, true);
    INFO("line " << from_edge << " px from the edge, centre " << jump.centre_px);
    REQUIRE(jump.found);
    CHECK(std::abs(jump.centre_px - edge) < 0.1);
  }
}

TEST_CASE("level jump: under noise the centre stays within a few of its sigmas") {
  const double edge = 1.2;
  int within = 0;
  constexpr int kSeeds = 40;
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    const LevelJump jump = Fit(MakeRows(edge, edge + 1.0, 0.02, seed), true);
    REQUIRE(jump.found);
    REQUIRE(jump.sigma_px > 0.0);
    CHECK(std::abs(jump.centre_px - edge) < 0.5);
    if (std::abs(jump.centre_px - edge) < 2.0 * jump.sigma_px) ++within;
  }
  // The digitizer scales this sigma for what real photos add (correlated
  // noise); on white noise it is about right by itself.
  CHECK(within >= 0.8 * kSeeds);
}

TEST_CASE("level jump: rows without a step between them give no edge") {
  Rows rows = MakeRows(0.0, 2.0, 0.01, 3);
  rows.reaching = rows.leaving;  // the same level in both
  CHECK_FALSE(Fit(rows, true).found);
}

}  // namespace impactlab::digitize
