#include "rebounds/bar_rebounds.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

namespace impactlab {
namespace {

// Appends a rebound row built by hand: its maximum and standard error and
// its peak time, a half period of 0.75 s its duration, the clock's errors
// those of a well-read trace.
void AppendRow(BarRebounds& bar, double xmax, double xmax_sigma, double t_peak) {
  bar.xmax.push_back(xmax);
  bar.xmax_sigma.push_back(xmax_sigma);
  bar.t_peak.push_back(t_peak);
  bar.t_peak_sigma.push_back(2e-4);
  bar.duration.push_back(0.75);
  bar.duration_sigma.push_back(1e-3);
}

// A pair's maxima (the mean of its bars) over five rebounds, and its typed X0.
constexpr double kPairMean[] = {0.250, 0.199, 0.158, 0.126, 0.100};
constexpr double kPairX0 = 0.405;

// Bars let go at X0 +- d about the typed X0 (half the gap between them): the
// centre of mass starts d from the impact point and swings on, so at session
// rebound n (first_rebound 1: n + 1 half periods on) the right bar's maximum
// is the pair's plus this, the left bar's less it.
double ReleaseSwingAt(int n, double d) { return n % 2 == 0 ? -d : d; }

TEST_CASE("bar_rebounds: session numbering starts at first_rebound and keeps rows past a gap") {
  ReboundExtraction e;
  for (int number : {1, 2, 3, 5, 6}) {
    ExtractedRebound r;
    r.number = number;
    r.xmax = {0.5 / number, 1e-4};
    r.t_peak = {0.75 * number, 1e-4};
    r.duration = {0.75, 1e-4};
    e.rebounds.push_back(r);
  }
  // PENDUL's rebound 2 is the session's rebound 0; 4 was left out, so 5 and
  // 6 are the session's 3 and 4, with no row for 2.
  const BarRebounds bar = InSessionNumbering(e, 2);
  REQUIRE(bar.xmax.size() == 4);
  CHECK(bar.rebound == std::vector<int>{0, 1, 3, 4});
  CHECK(bar.xmax[0] == 0.25);
  CHECK(bar.t_peak[1] == 2.25);
  CHECK(bar.RowOf(3) == std::optional<std::size_t>(2));
  CHECK_FALSE(bar.RowOf(2).has_value());
  CHECK(bar.GapFreeRows() == 2);
  // Read alone, a history gives the session's maxima only unbroken.
  const BarRebounds alone = GapFree(bar);
  CHECK(alone.xmax.size() == 2);
  CHECK(alone.rebound == std::vector<int>{0, 1});
  CHECK(alone.xmax_sigma == std::vector<double>{1e-4, 1e-4});
}

TEST_CASE("bar_rebounds: a cell curve's error adds to each maximum's in quadrature") {
  BarRebounds bar;
  bar.xmax = {0.4, 0.2};
  bar.xmax_sigma = {3e-4, 3e-4};
  AddCurveSigma(bar, [](double x) { return x * 1e-3; });  // 4e-4 and 2e-4
  CHECK(bar.xmax_sigma[0] == Approx(5e-4));
  CHECK(bar.xmax_sigma[1] == Approx(std::hypot(3e-4, 2e-4)));
}

TEST_CASE("bar_rebounds: the session's maxima are the bars' mean, then the average's own") {
  const auto bar = [](std::vector<double> xmax, double sigma, double t0) {
    BarRebounds b;
    for (std::size_t n = 0; n < xmax.size(); ++n) {
      b.xmax.push_back(xmax[n]);
      b.xmax_sigma.push_back(sigma);
      b.t_peak.push_back(t0 + 0.75 * n);
      b.t_peak_sigma.push_back(0.1 * sigma);
      b.duration.push_back(0.75 + 0.01 * n);
    }
    return b;
  };
  // The left bar lost its last rebound; the averaged history has one more,
  // which agrees with the right bar's through the common swing.
  // The bars' maxima differ by a common swing of alternating sign (0.01).
  const BarRebounds right = bar({0.50, 0.40, 0.32}, 3e-4, 0.75);
  const BarRebounds left = bar({0.52, 0.38}, 4e-4, 0.76);
  const BarRebounds averaged = bar({0.5101, 0.3902, 0.3303}, 2e-4, 0.755);
  const BarRebounds both = MeanOfBars(right, left, averaged);
  REQUIRE(both.xmax.size() == 3);
  CHECK(both.xmax[0] == Approx(0.51));
  CHECK(both.xmax[1] == Approx(0.39));
  CHECK(both.xmax_sigma[0] == Approx(0.5 * std::hypot(3e-4, 4e-4)));  // 2.5e-4
  CHECK(both.t_peak[1] == Approx(0.755 + 0.75));
  CHECK(both.xmax[2] == Approx(0.3303));  // past what both bars have
  CHECK(both.xmax_sigma[2] == Approx(2e-4));
}

TEST_CASE(
    "bar_rebounds: where one bar's rebounds slipped against the other's, the clock tells which") {
  // The right bar misread its rebound 2 (a scratch near the peak) and from
  // there on numbers each rebound one early: its rebound 2 peaks 0.29 s after
  // the left bar's, its rebound 3 is the left bar's 4. Averaged by number,
  // rebound 3 would mix two rebounds (randomised seed 1011's run 0.713: 9.4 %
  // of X0 off, with a sigma of 0.03 %).
  BarRebounds right, left;
  const double left_peaks[] = {0.75, 1.50, 2.25, 3.00, 3.75};
  const double right_peaks[] = {0.75, 1.50, 2.54, 3.75, 4.50};
  const double left_xmax[] = {0.57, 0.46, 0.37, 0.30, 0.24};
  const double right_xmax[] = {0.57, 0.46, 0.50, 0.24, 0.19};
  for (int n = 0; n < 5; ++n) {
    left.xmax.push_back(left_xmax[n]);
    right.xmax.push_back(right_xmax[n]);
    left.t_peak.push_back(left_peaks[n]);
    right.t_peak.push_back(right_peaks[n] + 2e-4);
    for (BarRebounds* b : {&right, &left}) {
      b->xmax_sigma.push_back(1e-3);
      b->t_peak_sigma.push_back(1e-4);
      b->duration.push_back(0.75);
    }
  }
  const std::optional<BarDisagreement> disagreement = FirstDisagreement(right, left);
  REQUIRE(disagreement.has_value());
  CHECK(disagreement->rebound == 2);
  CHECK_THAT(disagreement->why, Catch::Contains("slipped"));
  // The pendulum's clock (rebounds 0 and 1, 0.75 s apart) puts rebound 2 at
  // 2.25 s: the left bar's, read right. From there on the left bar alone
  // gives the rebounds, less the bars' common swing (none here).
  BarRebounds both = MeanOfBars(right, left, left);
  REQUIRE(both.xmax.size() == 5);
  CHECK(both.xmax[1] == Approx(0.46));
  CHECK(both.xmax[2] == Approx(0.37));
  CHECK(both.xmax[4] == Approx(0.24));
  CHECK(both.t_peak[3] == Approx(3.00));
  CHECK(both.xmax_sigma[2] > 1e-3);  // the bar's own and the common swing's

  // Neither bar's rebound 2 on the clock: nothing tells which was read
  // right, and the maxima stop there (the averaged history's own are not
  // appended either).
  left.t_peak[2] = 2.10;
  both = MeanOfBars(right, left, left);
  REQUIRE(both.xmax.size() == 2);

  // Peaks 0.2 ms apart, maxima 6 % apart (the bars' exchange of momentum
  // leaves them a constant length apart): they agree.
  right = left;
  for (std::size_t n = 0; n < 5; ++n) {
    right.t_peak[n] += 2e-4;
    right.xmax[n] += (n % 2 == 0 ? 1.0 : -1.0) * 0.014;
  }
  CHECK_FALSE(FirstDisagreement(right, left).has_value());
  CHECK(MeanOfBars(right, left, left).xmax.size() == 5);
}

TEST_CASE("bar_rebounds: the average's rows stop where its numbering slipped against a bar's") {
  // The left bar's trace is lost under a label until after rebound 0 (the
  // external session annotated-e903's run 0.314): the left bar has no rebound
  // numbered, and the average of the two histories, read only where both
  // are, begins at rebound 1 and calls it rebound 0.
  BarRebounds right, averaged;
  const double peaks[] = {0.75, 1.50, 2.25, 3.00, 3.75};
  const double xmax[] = {0.250, 0.199, 0.158, 0.126, 0.100};
  for (int n = 0; n < 5; ++n) {
    right.xmax.push_back(xmax[n]);
    right.t_peak.push_back(peaks[n]);
    if (n > 0) {
      averaged.xmax.push_back(xmax[n]);
      averaged.t_peak.push_back(peaks[n] + 3e-4);
    }
  }
  for (BarRebounds* b : {&right, &averaged}) {
    b->xmax_sigma.assign(b->xmax.size(), 3e-4);
    b->t_peak_sigma.assign(b->xmax.size(), 2e-4);
    b->duration.assign(b->xmax.size(), 0.75);
  }
  const BarRebounds left;  // nothing numbered
  const std::optional<BarDisagreement> slip = AverageSlip(right, left, averaged);
  REQUIRE(slip.has_value());
  CHECK(slip->rebound == 0);
  CHECK_THAT(slip->why, Catch::Contains("right bar's at 0.75 s"));
  // Not 0.199 as rebound 0; and with no rebound both bars read, nothing
  // tells the bars' common swing that would let the right bar's stand alone.
  CHECK(MeanOfBars(right, left, averaged).xmax.empty());

  // Numbered alike, the average's rows stand past what both bars have.
  averaged = right;
  CHECK_FALSE(AverageSlip(right, left, averaged).has_value());
  CHECK(MeanOfBars(right, left, averaged).xmax.size() == 5);
}

TEST_CASE("bar_rebounds: rebounds one bar lost are the other's less the bars' common swing") {
  // The pair's centre of mass swings on through every impact: each bar's
  // maximum is the mean of the two plus a constant length with alternating
  // sign. The left bar reads rebounds 0 and 1, then its trace is lost; the
  // right bar reads all five.
  const double mean[] = {0.250, 0.199, 0.158, 0.126, 0.100};
  constexpr double kCommon = 2e-4;
  BarRebounds right, left;
  for (int n = 0; n < 5; ++n) {
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    AppendRow(right, mean[n] + sign * kCommon, 3e-4, 0.75 + 0.75 * n);
    if (n < 2) AppendRow(left, mean[n] - sign * kCommon, 3e-4, 0.75 + 0.75 * n);
  }
  const BarRebounds averaged;  // the average has nothing past what both have
  const BarRebounds both = MeanOfBars(right, left, averaged);
  REQUIRE(both.xmax.size() == 5);
  for (std::size_t n = 0; n < 5; ++n) CHECK(both.xmax[n] == Approx(mean[n]).epsilon(1e-12));
  // The common swing from two rebounds, each 0.5 hypot(3e-4, 3e-4): its
  // standard error 1.5e-4 / sqrt(2), in quadrature with the right bar's own.
  const double common_sigma = 0.5 * std::hypot(3e-4, 3e-4) / std::sqrt(2.0);
  CHECK(both.xmax_sigma[1] == Approx(0.5 * std::hypot(3e-4, 3e-4)));
  CHECK(both.xmax_sigma[3] == Approx(std::hypot(3e-4, common_sigma)));
  CHECK(both.t_peak[4] == Approx(3.75));
  const std::optional<std::string> note = OneBarStretch(right, left, both.xmax.size());
  REQUIRE(note.has_value());
  CHECK_THAT(*note, Catch::Contains("left bar's trace gives no rebound 2 to 4"));
  CHECK_FALSE(OneBarStretch(right, right, 5).has_value());
}

TEST_CASE(
    "bar_rebounds: a bar whose trace is lost leaves the other's maxima less the common swing "
    "from its release") {
  // The left bar's trace is lost but for one stray rebound: the bars share
  // none, and only the right bar's release measures d (ReleaseSwingAt;
  // randomised seeds 2011's, 3008's, 3017's runs 0.405).
  const auto& mean = kPairMean;
  constexpr double kX0 = kPairX0, kD = 8e-4;
  BarRebounds right, left;
  for (int n = 0; n < 5; ++n)
    AppendRow(right, mean[n] + ReleaseSwingAt(n, kD), 3e-4, 0.75 + 0.75 * n);
  right.release = {kX0 + kD, 4e-4};
  left.rebound = {4};
  left.xmax = {0.2};  // read off the trace: far from the pair's 0.100 +- d
  left.xmax_sigma = {3e-4};
  left.t_peak = {1.6};  // and off the pendulum's clock
  left.t_peak_sigma = {2e-4};
  left.duration = {0.75};
  left.duration_sigma = {1e-3};
  const BarRebounds averaged;
  // Without the typed X0 nothing gives the common swing: refused as before.
  CHECK(MeanOfBars(right, left, averaged).xmax.empty());
  const BarRebounds both = MeanOfBars(right, left, averaged, {kX0, 1});
  // Rebound 4's peaks disagree, and the lost bar's row gives way to the
  // other's. One release, which nothing tests: its reading of the common
  // swing, 2 of its sigmas, may as well be the release misread, and the
  // common swing's sigma is at least that reading.
  REQUIRE(both.xmax.size() == 5);
  for (std::size_t n = 0; n < 5; ++n) {
    CHECK(both.xmax[n] == Approx(mean[n]).epsilon(1e-12));
    CHECK(both.xmax_sigma[n] == Approx(std::hypot(3e-4, kD)));
  }
  // Read within its sigma, the release's own sigma stands.
  right.release = {kX0 + 0.5 * kD, 4e-4};
  const BarRebounds near = MeanOfBars(right, left, averaged, {kX0, 1});
  REQUIRE(near.xmax.size() == 5);
  CHECK(near.xmax_sigma[0] == Approx(std::hypot(3e-4, 4e-4)));
  right.release = {kX0 + kD, 4e-4};
  // A release further from the typed X0 than 3 % of it is a slip in one of
  // them, which gives no common swing.
  right.release = {1.04 * kX0, 4e-4};
  CHECK(MeanOfBars(right, left, averaged, {kX0, 1}).xmax.empty());
  // Where the other bar shows two or more rebounds, it is not lost: bars
  // that share too few rebounds then are refused, not one taken alone.
  right.release = {kX0 + kD, 4e-4};
  left.rebound = {3, 4};
  left.xmax = {0.3, 0.2};
  left.xmax_sigma = {3e-4, 3e-4};
  left.t_peak = {1.0, 1.6};
  left.t_peak_sigma = {2e-4, 2e-4};
  left.duration = {0.75, 0.75};
  left.duration_sigma = {1e-3, 1e-3};
  CHECK(MeanOfBars(right, left, averaged, {kX0, 1}).xmax.empty());
}

TEST_CASE(
    "bar_rebounds: bars that share one rebound read their common swing there and at their "
    "releases") {
  // Randomised seeds 2033's, 4010's and 6003's runs 0.713: each bar's trace
  // lost over some rebounds, the bars share one, and a rebound only one bar
  // shows needs the common swing, which one shared rebound alone cannot
  // test. Each bar's release reads it too (ReleaseSwingAt): three
  // readings, which must agree.
  const auto& mean = kPairMean;
  constexpr double kX0 = kPairX0, kD = 8e-4;
  BarRebounds right, left;
  for (int n = 0; n < 5; ++n) {
    const double d = ReleaseSwingAt(n, kD);
    if (n <= 2) {
      right.rebound.push_back(n);
      AppendRow(right, mean[n] + d, 3e-4, 0.75 + 0.75 * n);
    }
    if (n >= 2) {
      left.rebound.push_back(n);
      AppendRow(left, mean[n] - d, 3e-4, 0.75 + 0.75 * n);
    }
  }
  right.release = {kX0 + kD, 4e-4};
  left.release = {kX0 - kD, 4e-4};
  const BarRebounds averaged;
  // Without the typed X0 the shared rebound alone gives the common swing:
  // untested, refused.
  CHECK(MeanOfBars(right, left, averaged).xmax.empty());
  const BarRebounds both = MeanOfBars(right, left, averaged, {kX0, 1});
  REQUIRE(both.xmax.size() == 5);
  // The common swing's sigma from its three readings: the shared rebound's
  // (half the bars' sigmas in quadrature) and the two releases'.
  const double shared_sigma = 0.5 * std::hypot(3e-4, 3e-4);
  const double common_sigma = 1.0 / std::sqrt(1.0 / (shared_sigma * shared_sigma) + 2.0 / 16e-8);
  for (std::size_t n = 0; n < 5; ++n) {
    CHECK(both.xmax[n] == Approx(mean[n]).epsilon(1e-12));
    if (n != 2) CHECK(both.xmax_sigma[n] == Approx(std::hypot(3e-4, common_sigma)));
  }
  // A release read 25 sigmas off (a hold's corner taken for it) is the one
  // left out: the other two agree.
  left.release = {kX0 - kD - 0.01, 4e-4};
  const BarRebounds without_it = MeanOfBars(right, left, averaged, {kX0, 1});
  REQUIRE(without_it.xmax.size() == 5);
  CHECK(without_it.xmax[0] == Approx(mean[0]).epsilon(1e-12));
  // Where no two readings agree nothing gives the common swing: refused as
  // before.
  right.release = {kX0 + kD + 0.01, 4e-4};
  left.release = {kX0 - kD + 0.008, 4e-4};
  CHECK(MeanOfBars(right, left, averaged, {kX0, 1}).xmax.empty());
}

TEST_CASE("bar_rebounds: rows stated to more than their own size are no rows of the bar") {
  // Randomised seed 2034's run 0.405: the left bar's rows read through a
  // curve unknown there, each maximum stated to several times X0. As rows
  // they made the common swing as uncertain as they are; read as no rows,
  // the left bar is lost and the right one gives the pair's maxima less the
  // common swing from its release.
  const auto& mean = kPairMean;
  constexpr double kX0 = kPairX0, kD = 2e-4;
  BarRebounds right, left;
  for (int n = 0; n < 5; ++n) {
    AppendRow(right, mean[n] + ReleaseSwingAt(n, kD), 3e-4, 0.75 + 0.75 * n);
    AppendRow(left, mean[n] - ReleaseSwingAt(n, kD) + 0.05, 3.0, 0.75 + 0.75 * n);
  }
  right.release = {kX0 + kD, 4e-4};
  const BarRebounds informative = Informative(left);
  CHECK(informative.xmax.empty());
  CHECK(Informative(right).xmax.size() == 5);
  const BarRebounds both = MeanOfBars(right, left, BarRebounds{}, {kX0, 1});
  REQUIRE(both.xmax.size() == 5);
  for (std::size_t n = 0; n < 5; ++n) {
    CHECK(both.xmax[n] == Approx(mean[n]).epsilon(1e-12));
    CHECK(both.xmax_sigma[n] == Approx(std::hypot(3e-4, 4e-4)));
  }
}

TEST_CASE("bar_rebounds: a bar read badly at one rebound gives way to the other") {
  // Randomised seed 1028's run 0.405: the left bar's rebound 3 crest was
  // misread (0.0416 +- 0.0095 where the truth is 0.0790), the right bar's
  // read well (0.0791 +- 0.00035). The plain mean was 4 sigma off.
  const double mean[] = {0.2688, 0.1786, 0.1187, 0.0789, 0.0524};
  constexpr double kCommon = -3e-4;  // right_n - left_n = 2 (-1)^n c
  BarRebounds right, left;
  for (int n = 0; n < 5; ++n) {
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    AppendRow(right, mean[n] + sign * kCommon, 3e-4, 0.75 + 0.75 * n);
    AppendRow(left, mean[n] - sign * kCommon, 3e-4, 0.75 + 0.75 * n);
  }
  // Clean, the bars agree: the plain mean, the sigmas combined.
  const BarRebounds clean = MeanOfBars(right, left, BarRebounds{});
  REQUIRE(clean.xmax.size() == 5);
  for (std::size_t n = 0; n < 5; ++n) {
    CHECK(clean.xmax[n] == Approx(mean[n]).epsilon(1e-12));
    CHECK(clean.xmax_sigma[n] == Approx(0.5 * std::hypot(3e-4, 3e-4)));
  }

  left.xmax[3] = 0.0416;
  left.xmax_sigma[3] = 0.0095;
  const BarRebounds both = MeanOfBars(right, left, BarRebounds{});
  REQUIRE(both.xmax.size() == 5);
  // The right bar through the common swing of the other rebounds: within a
  // few of its own sigma of the truth, where the plain mean (0.0604) is 0.019 off.
  CHECK(std::abs(both.xmax[3] - mean[3]) < 3e-4);
  // The two disagree by about 4 of their combined sigma: the standard error
  // is scaled by that, and still covers the error.
  CHECK(both.xmax_sigma[3] > 3.0 * 3e-4);
  CHECK(both.xmax_sigma[3] < 0.5 * 0.0095);
  // The other rebounds are as clean.
  CHECK(both.xmax[2] == Approx(mean[2]).epsilon(1e-12));

  // Seed 1009's run 0.405: the right bar's rebound 1 read 0.0358 low with a
  // sigma of 0.019, which the disagreement does not exceed twice; the plain
  // mean's sigma (0.0097) is nine times the weighted one's, so the left bar
  // carries it.
  right.xmax[1] = mean[1] - kCommon - 0.0358;
  right.xmax_sigma[1] = 0.0194;
  const BarRebounds wide = MeanOfBars(right, left, BarRebounds{});
  REQUIRE(wide.xmax.size() == 5);
  CHECK(std::abs(wide.xmax[1] - mean[1]) < 5e-4);
  CHECK(wide.xmax_sigma[1] < 0.1 * 0.5 * std::hypot(0.0194, 3e-4));
  CHECK(std::abs(wide.xmax[1] - mean[1]) < 2.0 * wide.xmax_sigma[1]);
}

// Two bars with a common swing `common` (right_n - left_n = 2 (-1)^n c) about
// the means `mean`, each missing the rebounds listed (a mark over its peak).
std::pair<BarRebounds, BarRebounds> BarsMissing(const std::vector<double>& mean, double common,
                                                const std::vector<int>& right_missing,
                                                const std::vector<int>& left_missing) {
  BarRebounds right, left;
  for (int n = 0; n < static_cast<int>(mean.size()); ++n) {
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    for (auto [bar, side, missing] :
         {std::tuple{&right, 1.0, &right_missing}, std::tuple{&left, -1.0, &left_missing}}) {
      if (std::find(missing->begin(), missing->end(), n) != missing->end()) continue;
      bar->rebound.push_back(n);
      AppendRow(*bar, mean[static_cast<std::size_t>(n)] + side * sign * common, 3e-4,
                0.75 + 0.75 * n);
    }
  }
  return {right, left};
}

TEST_CASE("bar_rebounds: a rebound one bar does not show is the other's; its later ones count") {
  // Randomised seeds 1004 and 1018's runs 0.405: a mark over the right bar's
  // first peak. The right bar has no rebound 0 but reads 1 to 4; the left
  // reads all. Neither bar's trace nor their average (read where both are)
  // gave rebound 0 before, and the run had no rebound from 0.
  const std::vector<double> mean = {0.250, 0.199, 0.158, 0.126, 0.100};
  constexpr double kCommon = 4e-4;
  {
    const auto [right, left] = BarsMissing(mean, kCommon, {0}, {});
    const BarRebounds both = MeanOfBars(right, left, BarRebounds{});
    REQUIRE(both.xmax.size() == 5);
    for (std::size_t n = 0; n < 5; ++n) CHECK(both.xmax[n] == Approx(mean[n]).epsilon(1e-12));
    // Rebound 0 from the left bar alone, the common swing from rebounds 1 to 4.
    const double common_sigma = 0.5 * std::hypot(3e-4, 3e-4) / 2.0;
    CHECK(both.xmax_sigma[0] == Approx(std::hypot(3e-4, common_sigma)));
    CHECK(both.t_peak[0] == Approx(0.75));
    const std::optional<std::string> note = OneBarStretch(right, left, both.xmax.size());
    REQUIRE(note.has_value());
    CHECK_THAT(*note, Catch::Contains("right bar's trace gives no rebound 0 of its own"));
  }
  {
    // The external session annotated-e903's run 0.314: the left bar's
    // rebounds 1 and 2 under crossing scratches and a ringed label, 3 and 4
    // read again. Its later rebounds pair with the right bar's again.
    const auto [right, left] = BarsMissing(mean, kCommon, {}, {1, 2});
    const BarRebounds both = MeanOfBars(right, left, BarRebounds{});
    REQUIRE(both.xmax.size() == 5);
    for (std::size_t n = 0; n < 5; ++n) CHECK(both.xmax[n] == Approx(mean[n]).epsilon(1e-12));
    CHECK(both.xmax_sigma[3] == Approx(0.5 * std::hypot(3e-4, 3e-4)));
    CHECK(both.xmax_sigma[1] > both.xmax_sigma[3]);
    const std::optional<std::string> note = OneBarStretch(right, left, both.xmax.size());
    REQUIRE(note.has_value());
    CHECK_THAT(*note, Catch::Contains("left bar's trace gives no rebound 1 to 2 of its own"));
  }
  {
    // As e903's run 0.314 was read: the right bar's rebound 0 crest misread
    // by 0.003 in (ten of its sigmas, 3.5 of c's): c from rebounds 0, 3 and 4
    // would move rebounds 1 and 2 by a third of that; it is left out.
    auto [right, left] = BarsMissing(mean, kCommon, {}, {1, 2});
    right.xmax[0] -= 0.003;
    const BarRebounds both = MeanOfBars(right, left, BarRebounds{});
    REQUIRE(both.xmax.size() == 5);
    CHECK(both.xmax[1] == Approx(mean[1]).epsilon(1e-12));
    CHECK(both.xmax[2] == Approx(mean[2]).epsilon(1e-12));
  }
  {
    // Two readings of c that disagree (a bar misread at one of them, no
    // telling which) give no rebound from one bar: the sequence ends there.
    auto [right, left] = BarsMissing(mean, kCommon, {}, {1, 2});
    left.xmax.resize(2), left.rebound.resize(2), left.xmax_sigma.resize(2);
    left.t_peak.resize(2), left.t_peak_sigma.resize(2), left.duration.resize(2);
    left.duration_sigma.resize(2);  // rebounds 0 and 3
    left.xmax[1] += 0.003;
    CHECK(MeanOfBars(right, left, BarRebounds{}).xmax.size() == 1);
    // Or one reading alone: nothing checks it.
    left = BarsMissing(mean, kCommon, {}, {1, 2, 3, 4}).second;
    CHECK(MeanOfBars(right, left, BarRebounds{}).xmax.size() == 1);
  }
  {
    // A rebound neither bar shows ends the sequence: it stays gap-free.
    const auto [right, left] = BarsMissing(mean, kCommon, {2}, {2});
    CHECK(MeanOfBars(right, left, BarRebounds{}).xmax.size() == 2);
  }
}

// Randomised seed 5020's run 0.713: the right bar's trace lost for 0.57 s
// over rebound 0's crest. The averaged history, read only where both bars
// are, had the crest's flanks alone and stated 0.357 +- 0.022 for 0.575;
// the left bar saw the crest. An averaged row that disagrees with the bar
// that shows the rebound (through the bars' common swing) gives way to it;
// one that agrees is kept.
TEST_CASE("bar_rebounds: an averaged row the bar that saw its crest disagrees with gives way") {
  const std::vector<double> mean = {0.250, 0.199, 0.158, 0.126, 0.100};
  constexpr double kCommon = 4e-4;
  const auto [right, left] = BarsMissing(mean, kCommon, {0}, {});
  const auto averaged_with_first = [&](double first, double sigma) {
    BarRebounds averaged;
    for (std::size_t n = 0; n < mean.size(); ++n) {
      AppendRow(averaged, n == 0 ? first : mean[n], n == 0 ? sigma : 2e-4,
                0.75 + 0.75 * static_cast<double>(n));
    }
    return averaged;
  };
  {
    // Extrapolated over a lost crest: 38 % low, at ten of its sigmas.
    const BarRebounds both = MeanOfBars(right, left, averaged_with_first(0.62 * mean[0], 0.01));
    REQUIRE(both.xmax.size() == 5);
    CHECK(both.xmax[0] == Approx(mean[0]).epsilon(1e-12));  // the left bar's less c
    const double common_sigma = 0.5 * std::hypot(3e-4, 3e-4) / 2.0;
    CHECK(both.xmax_sigma[0] == Approx(std::hypot(3e-4, common_sigma)));
    for (std::size_t n = 1; n < 5; ++n) CHECK(both.xmax[n] == Approx(mean[n]).epsilon(1e-12));
  }
  {
    // Within its error of the left bar's: the average's row stands.
    const double first = mean[0] + 2e-4;
    const BarRebounds both = MeanOfBars(right, left, averaged_with_first(first, 3e-4));
    REQUIRE(both.xmax.size() == 5);
    CHECK(both.xmax[0] == Approx(first).epsilon(1e-12));
    CHECK(both.xmax_sigma[0] == Approx(3e-4));
  }
}

TEST_CASE("bar_rebounds: a rebound from one history alone must peak on the pendulum's clock") {
  // Randomised seed 3033's run 0.405: the left bar's trace shows no rebound
  // 0, and the right bar's rebound 0 was read at 0.92 s, 0.17 s after the
  // rebound peaks (its maximum 26 % of X0 off, with a sigma of 2 %).
  const std::vector<double> mean = {0.269, 0.179, 0.119, 0.079, 0.053};
  constexpr double kCommon = 3e-4;
  auto [right, left] = BarsMissing(mean, kCommon, {}, {0});
  // On the clock (within a tenth of the 0.75 s half period): taken.
  right.t_peak[0] += 0.06;
  CHECK(MeanOfBars(right, left, BarRebounds{}).xmax.size() == 5);
  // Off it: the sequence ends before it, and the run has no rebound from 0.
  right.t_peak[0] += 0.11;
  right.xmax[0] = 0.372;
  CHECK(MeanOfBars(right, left, BarRebounds{}).xmax.empty());
  const std::optional<BarDisagreement> why = OffTheClock(right, left, 0);
  REQUIRE(why.has_value());
  CHECK_THAT(why->why, Catch::Contains("right bar's rebound 0"));
  CHECK_FALSE(OffTheClock(right, left, 1).has_value());
  // The same for a later rebound one bar lost: the sequence ends there.
  auto [right2, left2] = BarsMissing(mean, kCommon, {}, {3});
  right2.t_peak[3] -= 0.2;
  CHECK(MeanOfBars(right2, left2, BarRebounds{}).xmax.size() == 3);
  // And for the averaged history's own rows past what both bars show.
  auto [right3, left3] = BarsMissing(mean, kCommon, {3, 4}, {2, 3, 4});
  BarRebounds averaged;
  for (std::size_t n = 0; n < mean.size(); ++n) {
    AppendRow(averaged, mean[n], 3e-4, 0.75 + 0.75 * static_cast<double>(n));
  }
  CHECK(MeanOfBars(right3, left3, averaged).xmax.size() == 5);
  averaged.t_peak[3] += 0.1;
  CHECK(MeanOfBars(right3, left3, averaged).xmax.size() == 3);
}

TEST_CASE(
    "bar_rebounds: where the bars share one rebound, the clock runs at their peaks' spacing") {
  // Randomised seed 2029's run 0.405: the bars share only rebound 4, and
  // every duration read 0.772 s for the true half period of 0.750 (each read
  // between crossings of X = 0, which the calibration curve's error there
  // moves alike). Four such half periods back from rebound 4 put rebound 0
  // 0.09 s early, and the left bar's true rebound 0 was refused as off the
  // clock. The bars' peaks are 0.750 s apart.
  const std::vector<double> mean = {0.269, 0.179, 0.119, 0.079, 0.053, 0.035};
  auto [right, left] = BarsMissing(mean, 3e-4, {0, 1, 2, 5}, {3});
  for (BarRebounds* bar : {&right, &left}) {
    std::fill(bar->duration.begin(), bar->duration.end(), 0.772);
  }
  CHECK_FALSE(OffTheClock(right, left, 0).has_value());
  // A rebound 0 read 0.2 s late is still off it.
  left.t_peak[left.RowOf(0).value()] += 0.2;
  const std::optional<BarDisagreement> why = OffTheClock(right, left, 0);
  REQUIRE(why.has_value());
  CHECK_THAT(why->why, Catch::Contains("left bar's rebound 0"));
  // The peak tested does not set the clock that tests it: with no other
  // rows beside the shared one, one rebound's durations do, as before.
  auto [right2, left2] = BarsMissing(mean, 3e-4, {0, 1, 2, 3, 5}, {1, 2, 3, 5});
  left2.t_peak[left2.RowOf(0).value()] += 0.2;
  CHECK(OffTheClock(right2, left2, 0).has_value());
}

// The pulls (error over stated sigma) of the session's maxima over `runs`
// runs of six rebounds, each bar read with independent Gaussian errors of
// sigma `right_sigma` and `left_sigma` about the truth (the bars a common
// swing apart), and the bars' errors correlated by `rho`.
double PullRms(double right_sigma, double left_sigma, double rho, int runs) {
  std::mt19937 random(20261130);
  std::normal_distribution<double> gauss;
  const std::vector<double> mean = {0.269, 0.179, 0.119, 0.079, 0.053, 0.035};
  constexpr double kCommon = 3e-4;
  double sum = 0.0;
  int count = 0;
  for (int run = 0; run < runs; ++run) {
    auto [right, left] = BarsMissing(mean, kCommon, {}, {});
    for (std::size_t n = 0; n < mean.size(); ++n) {
      const double a = gauss(random), b = gauss(random);
      right.xmax[n] += right_sigma * a;
      left.xmax[n] += left_sigma * (rho * a + std::sqrt(1.0 - rho * rho) * b);
      right.xmax_sigma[n] = right_sigma;
      left.xmax_sigma[n] = left_sigma;
    }
    const BarRebounds both = MeanOfBars(right, left, BarRebounds{});
    for (std::size_t n = 0; n < both.xmax.size(); ++n) {
      sum += std::pow((both.xmax[n] - mean[n]) / both.xmax_sigma[n], 2);
      ++count;
    }
  }
  return std::sqrt(sum / count);
}

TEST_CASE("bar_rebounds: the session's maxima state their error where the bars err independently") {
  // Each bar is read from its own trace through its own calibration, so the
  // standard error of their mean combines the two as independent. Read about
  // as well, or one three times as badly (weighted through the common
  // swing), the pulls have an RMS of about 1: 0.98 and 0.92 (the Birge
  // scaling where two bars disagree widens a few sigmas that needed none).
  CHECK(PullRms(3e-4, 3e-4, 0.0, 2000) == Approx(1.0).margin(0.05));
  CHECK(PullRms(3e-4, 9e-4, 0.0, 2000) == Approx(0.95).margin(0.05));
  // Bars whose errors are anti-correlated (r = -0.8, as annotated-e907's 15
  // rebounds happen to be) err in their mean by far less than that: the pull
  // RMS falls to about sqrt(0.2) (0.43). The sigma cannot tell this from one
  // run's bars, whose difference may as well mean that a bar's sigma is too
  // small; over our own generator's and the external sessions' runs the
  // bars' errors hardly correlate on average (+0.10 and -0.01).
  CHECK(PullRms(3e-4, 3e-4, -0.8, 2000) == Approx(std::sqrt(0.2)).margin(0.07));
}

}  // namespace
TEST_CASE("bar_rebounds: a bar read wrong throughout states the bars' distance") {
  // Randomised seed 3031's run 0.405: the left bar read through a calibration
  // misread over a stretch of its swing, every maximum low by a share that
  // falls with the amplitude, each at a few tenths of a percent. The bars'
  // differences then follow no common swing (it alternates in sign), so
  // nothing tells which bar is right: each maximum's sigma covers half the
  // bars' distance, and its error is no more than about one sigma.
  const double mean[] = {0.2688, 0.1786, 0.1187, 0.0789, 0.0524};
  const double low[] = {0.28, 0.19, 0.11, 0.06, 0.03};  // the left bar's shortfall, of X
  BarRebounds right, left;
  for (int n = 0; n < 5; ++n) {
    AppendRow(right, mean[n], 5e-4, 0.75 + 0.75 * n);
    AppendRow(left, mean[n] * (1.0 - low[n]), 5e-4, 0.75 + 0.75 * n);
  }
  const BarRebounds both = MeanOfBars(right, left, BarRebounds{});
  REQUIRE(both.xmax.size() == 5);
  for (std::size_t n = 0; n < 5; ++n) {
    CHECK(both.xmax_sigma[n] >= 0.5 * (right.xmax[n] - left.xmax[n]) - 1e-12);
    CHECK(std::abs(both.xmax[n] - mean[n]) <= 1.05 * both.xmax_sigma[n]);
  }
}

}  // namespace impactlab
