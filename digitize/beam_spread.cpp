#include "digitize/beam_spread.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "digitize/select.h"

namespace impactlab::digitize {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Walks the profile from index `from` in direction `step` (+-1) and notes
// where it first falls below each level above the background (offsets in
// pixels, NaN for a level it never falls below). Levels ascend, so the walk
// meets them from the last down, in one pass.
std::array<double, kSpreadLevels.size()> FallsBelow(
    const Profile& profile, double background,
    const std::array<double, kSpreadLevels.size()>& level, int from, int step) {
  std::array<double, kSpreadLevels.size()> at;
  at.fill(std::numeric_limits<double>::quiet_NaN());
  const std::vector<float>& v = profile.values;
  const int n = static_cast<int>(v.size());
  int j = static_cast<int>(level.size()) - 1;
  for (int i = from; j >= 0 && i + step >= 0 && i + step < n; i += step) {
    const double here = v[i] - background, next = v[i + step] - background;
    for (; j >= 0 && next < level[j]; --j) {
      if (here >= level[j]) {
        at[j] = profile.OffsetAt(i) + step * profile.step_px * (here - level[j]) / (here - next);
      }
    }
  }
  return at;
}

struct Line {
  double intercept = 0.0, slope = 0.0, slope_sigma = 0.0;
  int n = 0;
};

// Least squares y = a + b x over the points `use` marks.
Line FitLine(const std::vector<double>& x, const std::vector<double>& y,
             const std::vector<bool>& use) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!use[i]) continue;
    sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i], ++n;
  }
  Line line;
  line.n = n;
  if (n < 3) return line;
  const double mx = sx / n, my = sy / n;
  const double vxx = sxx - n * mx * mx;
  if (!(vxx > 0.0)) return line;
  line.slope = (sxy - n * mx * my) / vxx;
  line.intercept = my - line.slope * mx;
  double rss = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (use[i]) rss += std::pow(y[i] - line.intercept - line.slope * x[i], 2);
  }
  line.slope_sigma = std::sqrt(rss / (n - 2) / vxx);
  return line;
}

}  // namespace

LevelHalfWidths MeasureLevelHalfWidths(const Profile& profile, const LineCentre& centre,
                                       double typical_height) {
  LevelHalfWidths out;
  out.fill(kNaN);
  const int n = static_cast<int>(profile.values.size());
  if (!centre.found || n < 3 || !(typical_height > 0.0)) return out;
  const int middle = std::clamp(
      static_cast<int>(std::lround((centre.offset_px - profile.start_px) / profile.step_px)), 0,
      n - 1);
  std::array<double, kSpreadLevels.size()> level;
  for (std::size_t j = 0; j < level.size(); ++j) level[j] = kSpreadLevels[j] * typical_height;
  const auto left = FallsBelow(profile, centre.background, level, middle, -1);
  const auto right = FallsBelow(profile, centre.background, level, middle, +1);
  for (std::size_t j = 0; j < level.size(); ++j) {
    // A level near the line's top would read the flat of a saturated core.
    if (centre.height >= 1.25 * level[j] && std::isfinite(left[j]) && std::isfinite(right[j])) {
      out[j] = static_cast<float>(0.5 * (right[j] - left[j]));
    }
  }
  return out;
}

SpreadEstimate EstimateSpread(const std::vector<SpreadPoint>& points) {
  constexpr int kMinSamples = 30;
  SpreadEstimate best;
  for (std::size_t j = 0; j < kSpreadLevels.size(); ++j) {
    std::vector<double> x, y;
    for (const SpreadPoint& p : points) {
      const float h = p.half_widths[j];
      if (!std::isfinite(h) || !(p.writing_speed >= 1.0)) continue;
      x.push_back(std::log(p.writing_speed));
      y.push_back(static_cast<double>(h) * h);
    }
    if (static_cast<int>(x.size()) < kMinSamples) continue;
    const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
    if (*hi - *lo < std::log(kMinSpeedRatio)) continue;
    // Least squares, then again without the points beyond 3.5 robust sigmas
    // (a grid line's light, a speck widening one profile).
    std::vector<bool> use(x.size(), true);
    Line line = FitLine(x, y, use);
    std::vector<double> misses;
    for (std::size_t i = 0; i < x.size(); ++i) {
      misses.push_back(std::abs(y[i] - line.intercept - line.slope * x[i]));
    }
    const double limit = 3.5 * 1.4826 * Median(misses);
    for (std::size_t i = 0; i < x.size(); ++i) use[i] = misses[i] <= limit;
    line = FitLine(x, y, use);
    if (line.n < kMinSamples || !(line.slope_sigma > 0.0)) continue;
    const double variance = -0.5 * line.slope, sigma = 0.5 * line.slope_sigma;
    if (!best.found || sigma < best.sigma_px2) {
      best = {true, variance, sigma, line.n, kSpreadLevels[j]};
    }
  }
  // Only a spread clearly above zero: a faster stretch cannot be wider.
  if (best.found && !(best.variance_px2 > 2.0 * best.sigma_px2)) best.found = false;
  return best;
}

}  // namespace impactlab::digitize
