#include "digitize/line_profile.h"
#include "digitize/select.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace impactlab::digitize {

namespace {

// The indices in [first, last] whose offsets may lie within [lo, hi]: a
// sample more either way than rounding could move them. Loops over a part
// of the profile take these bounds and keep their own exact test.
std::pair<int, int> IndicesNear(const Profile& profile, double lo, double hi, int first, int last) {
  const double a = std::floor((lo - profile.start_px) / profile.step_px) - 1.0;
  const double b = std::ceil((hi - profile.start_px) / profile.step_px) + 1.0;
  if (!(a <= b)) return {first, last};  // NaN bounds (no width found): the exact test decides
  return {static_cast<int>(std::clamp(a, static_cast<double>(first), static_cast<double>(last))),
          static_cast<int>(std::clamp(b, static_cast<double>(first), static_cast<double>(last)))};
}

// Linear interpolation of the profile at an offset; false off its ends.
bool ValueAt(const Profile& profile, double offset_px, double* value) {
  const double position = (offset_px - profile.start_px) / profile.step_px;
  const int i = static_cast<int>(std::floor(position));
  if (i < 0 || i + 1 >= static_cast<int>(profile.values.size())) return false;
  const double f = position - i;
  *value = profile.values[i] * (1.0 - f) + profile.values[i + 1] * f;
  return true;
}

// A crossing runs along the measured line when the profile crosses it no
// wider than this many of its widths (within about 30 degrees of square).
constexpr double kAlongWidths = 1.15;

bool NearCrossing(const std::vector<Profile::Crossing>& crossings, double offset_px) {
  for (const Profile::Crossing& c : crossings) {
    if (std::abs(offset_px - c.offset_px) < c.reach_px) return true;
  }
  return false;
}

// The crossings' light at an offset, each a unit-height Gaussian of its width.
double CrossingLight(const std::vector<Profile::Crossing>& crossings, double offset_px) {
  double sum = 0.0;
  for (const Profile::Crossing& c : crossings) {
    const double z = (offset_px - c.offset_px) / (c.fwhm_px / 2.3548);
    if (std::abs(z) < 4.0) sum += std::exp(-0.5 * z * z);
  }
  return sum;
}

// The centre where the profile (less its background) is most nearly
// symmetric, allowing for the crossings' light (see line_profile.h), within
// +-`window` of the centre, searched within `reach` of `guess`. Returns the
// crossings' share of the asymmetry explained (0..1), a measure of how much
// they mattered.
template <typename Background>
double SymmetricCentre(const Profile& profile, const Background& background,
                       const std::vector<Profile::Crossing>& crossings, double guess, double reach,
                       double window, double* centre) {
  // Trial centres lie on a grid of a quarter sample about the guess, so every
  // value needed (the profile and the crossings' light at trial centre +- k
  // samples) lies on that grid too: tabulated once.
  constexpr int kSub = 4;
  const double step = profile.step_px, h = step / kSub;
  const int pairs = std::max(2, static_cast<int>(window / step));
  const int steps = static_cast<int>(std::ceil(reach / h));
  const int half = steps + kSub * pairs;  // table index j <-> guess + (j - half) h
  std::vector<double> value(2 * half + 1), light(2 * half + 1);
  std::vector<unsigned char> inside(2 * half + 1);
  for (int j = 0; j <= 2 * half; ++j) {
    const double u = guess + (j - half) * h;
    double v = 0.0;
    inside[j] = ValueAt(profile, u, &v);
    value[j] = v - background(u);
    light[j] = CrossingLight(crossings, u);
  }
  double explained = 0.0;
  auto misfit = [&](int m) {
    int used = 0;
    double dd = 0.0, dm = 0.0, mm = 0.0;
    for (int k = 1; k <= pairs; ++k) {
      const int a = half + m - kSub * k, b = half + m + kSub * k;
      if (!inside[a] || !inside[b]) continue;
      const double d = value[b] - value[a], g = light[b] - light[a];
      dd += d * d, dm += d * g, mm += g * g;
      ++used;
    }
    if (used == 0) return std::numeric_limits<double>::max();
    // The crossing's height: least squares, never negative (it adds light).
    const double height = mm > 0.0 ? std::max(0.0, dm / mm) : 0.0;
    const double residual = dd - 2.0 * height * dm + height * height * mm;
    explained = dd > 0.0 ? 1.0 - residual / dd : 0.0;
    return residual / used;
  };
  // The best trial centre, then a parabola through it and its neighbours.
  std::vector<double> f(2 * steps + 1);
  int best = 0;
  for (int m = -steps; m <= steps; ++m) {
    f[m + steps] = misfit(m);
    if (f[m + steps] < f[best + steps]) best = m;
  }
  *centre = guess + best * h;
  if (best > -steps && best < steps) {
    const double a = f[best + steps - 1], b = f[best + steps], c = f[best + steps + 1];
    const double curvature = a - 2.0 * b + c;
    if (curvature > 0.0) *centre += 0.5 * (a - c) / curvature * h;
  }
  misfit(best);
  return std::clamp(explained, 0.0, 1.0);
}

}  // namespace

Profile ReadProfile(const InkSampler& ink, cv::Point2d origin_px, cv::Point2d direction,
                    double half_length_px, double step_px) {
  Profile profile;
  profile.origin_px = origin_px;
  profile.direction = direction;
  profile.step_px = step_px;
  const int half = static_cast<int>(std::ceil(half_length_px / step_px));
  profile.start_px = -half * step_px;
  profile.values.resize(2 * half + 1);
  const auto point = [&](int i) { return profile.PointAt(profile.OffsetAt(i)); };
  ink.Read(2 * half + 1, point, profile.values.data());
  return profile;
}

bool CutToClearStretch(Profile& profile, double min_reach_px) {
  if (!profile.BesideShortLine()) return true;
  if (!(profile.clear_lo_px <= -min_reach_px && profile.clear_hi_px >= min_reach_px)) return false;
  const double n = static_cast<double>(profile.values.size());
  // In doubles first: a side no line lit stays at +-infinity.
  const int first = static_cast<int>(
      std::clamp(std::ceil((profile.clear_lo_px - profile.start_px) / profile.step_px), 0.0, n));
  const int last = static_cast<int>(std::clamp(
      std::floor((profile.clear_hi_px - profile.start_px) / profile.step_px), -1.0, n - 1.0));
  profile.values.erase(profile.values.begin() + last + 1, profile.values.end());
  profile.values.erase(profile.values.begin(), profile.values.begin() + first);
  profile.start_px += first * profile.step_px;
  profile.clear_lo_px = -HUGE_VAL, profile.clear_hi_px = HUGE_VAL;
  return true;
}

LineCentre FindLineCentre(const Profile& profile, const CentreSettings& settings) {
  LineCentre result;
  const std::vector<float>& v = profile.values;
  const int n = static_cast<int>(v.size());
  if (n < 7) return result;

  // Background: a straight line through the medians of the outer fifths,
  // which a symmetric line's glow raises equally on both sides.
  const int fifth = std::max(1, n / 5);
  std::vector<float> left, right;
  left.reserve(fifth), right.reserve(fifth);
  for (int i = 0; i < fifth; ++i) {
    if (!NearCrossing(profile.crossings, profile.OffsetAt(i))) left.push_back(v[i]);
    if (!NearCrossing(profile.crossings, profile.OffsetAt(n - 1 - i)))
      right.push_back(v[n - 1 - i]);
  }
  if (left.empty()) left.push_back(v[0]);
  if (right.empty()) right.push_back(v[n - 1]);
  const double background_left = MedianOf(left), background_right = MedianOf(right);
  result.background_step = background_right - background_left;
  const double u_left = profile.OffsetAt((fifth - 1) / 2);
  const double u_right = profile.OffsetAt(n - 1 - (fifth - 1) / 2);
  auto background = [&](double u) {
    return background_left +
           (background_right - background_left) * (u - u_left) / (u_right - u_left);
  };

  // The brightest (lightly smoothed) sample within the search range, crossing
  // lines' light discounted.
  int peak = -1;
  double peak_height = 0.0;
  const auto [search_first, search_last] =
      IndicesNear(profile, -settings.search_px, settings.search_px, 1, n - 2);
  for (int i = search_first; i <= search_last; ++i) {
    const double u = profile.OffsetAt(i);
    if (std::abs(u) > settings.search_px) continue;
    double smoothed = 0.25 * (v[i - 1] + 2.0 * v[i] + v[i + 1]) - background(u);
    smoothed -= settings.crossing_height * CrossingLight(profile.crossings, u);
    if (smoothed > peak_height) peak_height = smoothed, peak = i;
  }
  if (peak < 0) return result;
  peak_height +=
      settings.crossing_height * CrossingLight(profile.crossings, profile.OffsetAt(peak));

  // A grid line running beside the trace, along it and clear of its core (a
  // level of the contact trace just off the centre axis), would merge with
  // it at half maximum where ink saturates (printed figures) or glow fills
  // the gap: its modelled light is taken off the profile for the width.
  // One crossing the trace is left to the symmetric centre below.
  std::vector<Profile::Crossing> beside;
  const double peak_u = profile.OffsetAt(peak);
  for (const Profile::Crossing& c : profile.crossings) {
    const bool along = c.fwhm_px <= kAlongWidths * settings.crossing_fwhm_px;
    if (along && std::abs(c.offset_px - peak_u) > c.fwhm_px) beside.push_back(c);
  }
  auto lit = [&](double u) {
    return background(u) + settings.crossing_height * CrossingLight(beside, u);
  };
  // Half-maximum crossings either side of the peak.
  auto above = [&](int i) { return v[i] - lit(profile.OffsetAt(i)) - 0.5 * peak_height; };
  int l = peak;
  while (l > 0 && above(l - 1) >= 0.0) --l;
  int r = peak;
  while (r + 1 < n && above(r + 1) >= 0.0) ++r;
  if (l == 0 || r == n - 1) return result;  // the line is wider than the profile
  const double cross_left =
      profile.OffsetAt(l - 1) + profile.step_px * above(l - 1) / (above(l - 1) - above(l));
  const double cross_right =
      profile.OffsetAt(r) + profile.step_px * above(r) / (above(r) - above(r + 1));
  result.fwhm_px = cross_right - cross_left;
  double centre = 0.5 * (cross_left + cross_right);

  const double window = result.fwhm_px + 2.0 * profile.step_px;
  result.found = true;
  result.height = peak_height;

  // Crossing lines whose light reaches the line's core call for the
  // symmetric centre; further out they hardly matter, and the chosen
  // method is steadier.
  std::vector<Profile::Crossing> near;
  for (const Profile::Crossing& c : profile.crossings) {
    const bool reaches_core = std::abs(c.offset_px - centre) < 0.75 * result.fwhm_px;
    if (settings.symmetric_near_crossings && reaches_core) near.push_back(c);
  }
  if (!near.empty()) {
    result.crossing_share = SymmetricCentre(profile, background, near, centre, 0.5 * result.fwhm_px,
                                            window + near.front().reach_px, &centre);
    result.offset_px = centre;
    result.background = background(centre);
    return result;
  }

  switch (settings.method) {
    case SubpixelMethod::kCentroid: {
      for (int iteration = 0; iteration < 4; ++iteration) {
        const double level = settings.centroid_level * peak_height;
        double sum = 0.0, moment = 0.0;
        const auto [first, last] = IndicesNear(profile, centre - window, centre + window, 0, n - 1);
        for (int i = first; i <= last; ++i) {
          const double u = profile.OffsetAt(i);
          if (std::abs(u - centre) > window) continue;
          const double w = v[i] - lit(u) - level;
          if (w <= 0.0) continue;
          sum += w;
          moment += w * u;
        }
        if (sum <= 0.0) return LineCentre{};
        const double next = moment / sum;
        const bool settled = std::abs(next - centre) < 1e-4;
        centre = next;
        if (settled) break;
      }
      break;
    }
    case SubpixelMethod::kGaussian: {
      // ln(v - background) = a + b d + c d^2 with d = u - centre, weighed by
      // (v - background)^2 (Caruana's weights, which undo the log's
      // amplification of noise in the tails).
      for (int iteration = 0; iteration < 2; ++iteration) {
        cv::Matx33d normal = cv::Matx33d::zeros();
        cv::Vec3d rhs(0.0, 0.0, 0.0);
        int weighed = 0;
        const auto [first, last] = IndicesNear(profile, centre - window, centre + window, 0, n - 1);
        for (int i = first; i <= last; ++i) {
          const double u = profile.OffsetAt(i);
          if (std::abs(u - centre) > window) continue;
          const double height = v[i] - lit(u);
          if (height <= 0.15 * peak_height) continue;
          const double d = u - centre, w = height * height;
          const cv::Vec3d basis(1.0, d, d * d);
          normal += w * basis * basis.t();
          rhs += w * std::log(height) * basis;
          ++weighed;
        }
        if (weighed < 3) return LineCentre{};
        cv::Vec3d a;
        if (!cv::solve(normal, rhs, a, cv::DECOMP_CHOLESKY) || !(a[2] < 0.0)) return LineCentre{};
        const double shift = -a[1] / (2.0 * a[2]);
        if (!(std::abs(shift) < result.fwhm_px)) return LineCentre{};
        centre += shift;
      }
      break;
    }
    case SubpixelMethod::kParabola: {
      // Through the brightest sample and those about a pixel either side.
      int top = peak;
      for (int i = l; i <= r; ++i) {
        if (v[i] - lit(profile.OffsetAt(i)) > v[top] - lit(profile.OffsetAt(top))) {
          top = i;
        }
      }
      const int d = std::max(1, static_cast<int>(std::lround(1.0 / profile.step_px)));
      if (top - d >= 0 && top + d < n) {
        const double a = v[top - d], b = v[top], c = v[top + d];
        const double curvature = a - 2.0 * b + c;
        if (curvature < 0.0) {
          const double shift = 0.5 * (a - c) / curvature * d * profile.step_px;
          if (std::abs(shift) <= d * profile.step_px) centre = profile.OffsetAt(top) + shift;
        }
      }
      break;
    }
  }
  result.offset_px = centre;
  result.background = background(centre);
  return result;
}

}  // namespace impactlab::digitize
