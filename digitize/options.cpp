// Range checks of the digitizer's options, run before any work.
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "digitize/options.h"

namespace impactlab {

namespace {

bool Fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

bool InRange(double value, double lo, double hi) { return value >= lo && value <= hi; }

}  // namespace

bool GraticuleOptions::Check(std::string* error) const {
  if (detect_width_px < 160 || detect_width_px > 4000) {
    return Fail(error,
                fmt::format("detect_width_px must lie in [160, 4000], got {}", detect_width_px));
  }
  if (!InRange(radial_min_gain, 0.0, 1.0)) {
    return Fail(error, fmt::format("radial_min_gain must lie in [0, 1], got {}", radial_min_gain));
  }
  if (samples_per_div < 1 || samples_per_div > 50) {
    return Fail(error, fmt::format("samples_per_div must lie in [1, 50], got {}", samples_per_div));
  }
  if (!InRange(line_average_div, 0.0, 0.3)) {
    return Fail(error,
                fmt::format("line_average_div must lie in [0, 0.3], got {}", line_average_div));
  }
  if (!(max_residual_px > 0.0 && max_residual_px <= 50.0)) {
    return Fail(error, fmt::format("max_residual_px must lie in (0, 50], got {}", max_residual_px));
  }
  if (!(max_residual_widths >= 0.0 && max_residual_widths <= 2.0)) {
    return Fail(error,
                fmt::format("max_residual_widths must lie in [0, 2], got {}", max_residual_widths));
  }
  if (!InRange(max_residual_div, 0.0, 0.2)) {
    return Fail(error,
                fmt::format("max_residual_div must lie in [0, 0.2], got {}", max_residual_div));
  }
  if (!InRange(max_rotation_deg, 0.0, 40.0)) {
    return Fail(error,
                fmt::format("max_rotation_deg must lie in [0, 40], got {}", max_rotation_deg));
  }
  if (corners_px) {
    for (const auto& corner : *corners_px) {
      if (!std::isfinite(corner[0]) || !std::isfinite(corner[1])) {
        return Fail(error,
                    fmt::format("corners_px must be finite, got [{}, {}]", corner[0], corner[1]));
      }
    }
  }
  return true;
}

bool TraceOptions::Check(std::string* error) const {
  if (!InRange(samples_per_px, 0.05, 4.0)) {
    return Fail(error, fmt::format("samples_per_px must lie in [0.05, 4], got {}", samples_per_px));
  }
  if (!InRange(centroid_level, 0.0, 0.9)) {
    return Fail(error, fmt::format("centroid_level must lie in [0, 0.9], got {}", centroid_level));
  }
  if (!InRange(profile_half_widths, 1.0, 10.0)) {
    return Fail(
        error, fmt::format("profile_half_widths must lie in [1, 10], got {}", profile_half_widths));
  }
  if (track_px_per_div != 0.0 && !InRange(track_px_per_div, 8.0, 200.0)) {
    return Fail(error, fmt::format("track_px_per_div must be 0 or lie in [8, 200], got {}",
                                   track_px_per_div));
  }
  if (!InRange(max_gap_div, 0.0, 5.0)) {
    return Fail(error, fmt::format("max_gap_div must lie in [0, 5], got {}", max_gap_div));
  }
  if (!InRange(min_relative_height, 0.0, 1.0)) {
    return Fail(error,
                fmt::format("min_relative_height must lie in [0, 1], got {}", min_relative_height));
  }
  if (!InRange(min_local_height, 0.0, 1.0)) {
    return Fail(error,
                fmt::format("min_local_height must lie in [0, 1], got {}", min_local_height));
  }
  if (!InRange(max_relative_width, 1.0, 10.0)) {
    return Fail(error,
                fmt::format("max_relative_width must lie in [1, 10], got {}", max_relative_width));
  }
  if (!(outlier_sigmas >= 2.0 && std::isfinite(outlier_sigmas))) {
    return Fail(error, fmt::format("outlier_sigmas must be at least 2, got {}", outlier_sigmas));
  }
  if (!InRange(min_confidence, 0.0, 1.0)) {
    return Fail(error, fmt::format("min_confidence must lie in [0, 1], got {}", min_confidence));
  }
  if (!InRange(min_height_over_grid, 0.0, 100.0)) {
    return Fail(error, fmt::format("min_height_over_grid must lie in [0, 100], got {}",
                                   min_height_over_grid));
  }
  if (!InRange(min_coverage, 0.0, 1.0)) {
    return Fail(error, fmt::format("min_coverage must lie in [0, 1], got {}", min_coverage));
  }
  if (!InRange(grid_reach_widths, 0.0, 5.0)) {
    return Fail(error,
                fmt::format("grid_reach_widths must lie in [0, 5], got {}", grid_reach_widths));
  }
  return true;
}

bool DigitizeOptions::Check(std::string* error) const {
  std::string detail;
  if (!graticule.Check(&detail)) return Fail(error, "graticule: " + detail);
  if (!traces.Check(&detail)) return Fail(error, "traces: " + detail);
  return true;
}

}  // namespace impactlab
