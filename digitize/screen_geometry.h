// Screen geometry used by several measurements (internal to digitize/):
// the mapping both ways for many points, and which graticule lines cross a
// profile.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <opencv2/core.hpp>

#include "digitize/digitize.h"
#include "digitize/line_profile.h"

namespace impactlab::digitize {

// GraticuleMapping::ImageFromScreen (which calls this), inline for the loops
// that map thousands of points: the call cost as much as the mapping.
inline cv::Point2d ImageFromScreen(const GraticuleMapping& mapping, cv::Point2d screen_div) {
  const cv::Matx33d& h = mapping.homography;
  const double w = h(2, 0) * screen_div.x + h(2, 1) * screen_div.y + h(2, 2);
  const cv::Point2d q((h(0, 0) * screen_div.x + h(0, 1) * screen_div.y + h(0, 2)) / w,
                      (h(1, 0) * screen_div.x + h(1, 1) * screen_div.y + h(1, 2)) / w);
  if (mapping.radial_k1 == 0.0) return q;
  const cv::Point2d d = q - mapping.distortion_centre_px;
  const double r2 = d.dot(d) / (mapping.distortion_radius_px * mapping.distortion_radius_px);
  return mapping.distortion_centre_px + d * (1.0 + mapping.radial_k1 * r2);
}

// ScreenFromImage with the inverse homography computed once.
class ScreenFromPixel {
 public:
  explicit ScreenFromPixel(const GraticuleMapping& mapping)
      : mapping_(mapping), inverse_(mapping.homography.inv()) {}

  cv::Point2d operator()(cv::Point2d p) const {
    if (mapping_.radial_k1 != 0.0) {
      const cv::Point2d d = p - mapping_.distortion_centre_px;
      const double distorted = std::hypot(d.x, d.y);
      if (distorted > 0.0) {
        const double k =
            mapping_.radial_k1 / (mapping_.distortion_radius_px * mapping_.distortion_radius_px);
        double r = distorted;
        for (int iteration = 0; iteration < 6; ++iteration) {
          r -= (r + k * r * r * r - distorted) / (1.0 + 3.0 * k * r * r);
        }
        p = mapping_.distortion_centre_px + d * (r / distorted);
      }
    }
    const cv::Vec3d s = inverse_ * cv::Vec3d(p.x, p.y, 1.0);
    return {s[0] / s[2], s[1] / s[2]};
  }

 private:
  const GraticuleMapping& mapping_;
  cv::Matx33d inverse_;
};

// The graticule's lines and the centre axes' minor ticks (every 0.2
// division, 0.2 division long) that cross a profile, found from the screen
// positions of its ends (the mapping is as good as straight over a profile).
class GridCrossings {
 public:
  // `fwhm_div`: a grid line's width; its light is taken to reach
  // `reach_widths` of them either side.
  GridCrossings(std::array<int, 2> divisions, double fwhm_div, double reach_widths)
      : nx_(divisions[0]), ny_(divisions[1]), fwhm_div_(fwhm_div), m_(reach_widths * fwhm_div) {}

  void AddTo(Profile& profile, cv::Point2d first_div, cv::Point2d last_div) const {
    if (m_ <= 0.0) return;
    const double u0 = profile.OffsetAt(0);
    const double length = profile.OffsetAt(static_cast<int>(profile.values.size()) - 1) - u0;
    const cv::Point2d per_px = (last_div - first_div) / length;
    const double half = 0.5 * ny_;
    // Lines y = value where x lies in [x_lo, x_hi], and x = value where y does.
    auto add = [&](bool horizontal, double value, double lo, double hi) {
      const double rate = horizontal ? per_px.y : per_px.x;
      const double reach = std::abs(rate) > 1e-12 ? m_ / std::abs(rate) : HUGE_VAL;
      if (reach > 0.5 * length) {
        // Along the profile. A line covering all of it is an even
        // background, harmless; one ending within it (a tick, the
        // graticule's edge) lights part of it: the profile is spoiled.
        const double c0 = horizontal ? first_div.y : first_div.x;
        const double c1 = horizontal ? last_div.y : last_div.x;
        if (std::min(std::abs(c0 - value), std::abs(c1 - value)) > m_) return;
        const double o0 =
            std::min(horizontal ? first_div.x : first_div.y, horizontal ? last_div.x : last_div.y);
        const double o1 =
            std::max(horizontal ? first_div.x : first_div.y, horizontal ? last_div.x : last_div.y);
        const bool covers = lo - m_ <= o0 && o1 <= hi + m_;
        if (covers) return;
        // The stretch of the profile within m_ of the line: beside it, or
        // round either of its ends. (Distance from a segment is convex, so
        // the stretch is one interval: the union of the three.)
        const double a0 = horizontal ? first_div.x : first_div.y;
        const double along_rate = horizontal ? per_px.x : per_px.y;
        const auto [across_lo, across_hi] = Within(c0, rate, value - m_, value + m_);
        const auto [along_lo, along_hi] = Within(a0, along_rate, lo, hi);
        double lit_lo = std::max(across_lo, along_lo), lit_hi = std::min(across_hi, along_hi);
        for (const double end : {lo, hi}) {
          const auto [round_lo, round_hi] =
              WithinDisc({c0 - value, a0 - end}, {rate, along_rate}, m_);
          lit_lo = std::min(lit_lo, round_lo), lit_hi = std::max(lit_hi, round_hi);
        }
        lit_lo = std::max(lit_lo, 0.0), lit_hi = std::min(lit_hi, length);
        if (!(lit_lo <= lit_hi)) return;
        // What lies on the origin's side of the lit stretch stays clear.
        if (u0 + lit_hi < 0.0) {
          profile.clear_lo_px = std::max(profile.clear_lo_px, u0 + lit_hi);
        } else if (u0 + lit_lo > 0.0) {
          profile.clear_hi_px = std::min(profile.clear_hi_px, u0 + lit_lo);
        } else {
          profile.clear_lo_px = profile.clear_hi_px = 0.0;
        }
        return;
      }
      const double u = u0 + (value - (horizontal ? first_div.y : first_div.x)) / rate;
      if (u < u0 - reach || u > u0 + length + reach) return;
      const double other =
          horizontal ? first_div.x + per_px.x * (u - u0) : first_div.y + per_px.y * (u - u0);
      if (other < lo - m_ || other > hi + m_) return;
      profile.crossings.push_back({u, fwhm_div_ / std::abs(rate), reach});
    };
    const double y_lo = std::min(first_div.y, last_div.y) - 0.5,
                 y_hi = std::max(first_div.y, last_div.y) + 0.5;
    const double x_lo = std::min(first_div.x, last_div.x) - 0.5,
                 x_hi = std::max(first_div.x, last_div.x) + 0.5;
    for (int k = 0; k <= ny_; ++k) {
      const double y = k - half;
      if (y >= y_lo && y <= y_hi) add(true, y, 0.0, nx_);
    }
    for (int k = 0; k <= nx_; ++k) {
      if (k >= x_lo && k <= x_hi) add(false, k, -half, half);
    }
    for (int k = 0; k <= 5 * nx_; ++k) {
      const double x = kTickDiv * k;
      if (k % 5 != 0 && x >= x_lo && x <= x_hi) add(false, x, -kTickHalfDiv, kTickHalfDiv);
    }
    for (int k = 0; k <= 5 * ny_; ++k) {
      const double y = kTickDiv * k - half;
      if (k % 5 != 0 && y >= y_lo && y <= y_hi) {
        add(true, y, 0.5 * nx_ - kTickHalfDiv, 0.5 * nx_ + kTickHalfDiv);
      }
    }
  }

 private:
  // Where along a profile (distance from its first point) a coordinate
  // starting at `start` and changing by `rate` per pixel lies in [lo, hi].
  static std::pair<double, double> Within(double start, double rate, double lo, double hi) {
    if (std::abs(rate) < 1e-12) {
      return start >= lo && start <= hi ? std::pair(-HUGE_VAL, HUGE_VAL)
                                        : std::pair(HUGE_VAL, -HUGE_VAL);
    }
    const double a = (lo - start) / rate, b = (hi - start) / rate;
    return {std::min(a, b), std::max(a, b)};
  }

  // Where a point starting at `start` and moving by `rate` per pixel lies
  // within `radius` of the origin (empty: lo > hi).
  static std::pair<double, double> WithinDisc(cv::Point2d start, cv::Point2d rate, double radius) {
    const double a = rate.dot(rate), b = start.dot(rate), c = start.dot(start) - radius * radius;
    const double discriminant = b * b - a * c;
    if (!(a > 0.0) || discriminant < 0.0) return {HUGE_VAL, -HUGE_VAL};
    const double root = std::sqrt(discriminant);
    return {(-b - root) / a, (-b + root) / a};
  }

  static constexpr double kTickDiv = 0.2, kTickHalfDiv = 0.1;
  int nx_, ny_;
  double fwhm_div_, m_;
};

}  // namespace impactlab::digitize
