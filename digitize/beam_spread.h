// How far a curved trace's measured centre lies inside the curve, and the
// spread that sets it (internal to digitize/).
//
// A trace's exposure is its path swept by the beam's spot and blurred by the
// camera: a 2-D spread of variance s^2 about the path. Where the path curves
// (curvature kappa) more of that spread falls on the inner side, and the
// line's centre, however it is found, moves inwards by s^2 kappa / 2. At a
// slow sweep's peaks this flattens every maximum by s^2 omega^2 / 2 of its
// height (omega in radians per pixel): about 0.1 % at 1000 px.
//
// The tone curve hides s^2 from the line's width, but not from how the width
// changes: the exposure falls as 1 / writing speed, so at a fixed brightness
// level a Gaussian cross-section's half-width h obeys
//   h^2 = const - 2 s^2 ln(speed),
// whatever the (monotone) tone curve. The steep stretches of a slow sweep
// write several times faster than its peaks, which measures s^2.
#pragma once

#include <array>
#include <vector>

#include "digitize/line_profile.h"

namespace impactlab::digitize {

// Brightness levels, as fractions of the trace's typical height above the
// screen, at which a profile's half-width is read.
inline constexpr std::array<double, 8> kSpreadLevels = {0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.5, 0.6};
using LevelHalfWidths = std::array<float, kSpreadLevels.size()>;

// The spread is measured only over writing speeds at least this factor apart.
inline constexpr double kMinSpeedRatio = 1.5;

// Half-widths (pixels, across the line) where the profile falls to each level
// times `typical_height` above its background; NaN where the line's peak is
// not clearly above the level (the level would graze its top).
LevelHalfWidths MeasureLevelHalfWidths(const Profile& profile, const LineCentre& centre,
                                       double typical_height);

struct SpreadPoint {
  double writing_speed = 1.0;  // relative to the sweep's: sqrt(1 + slope^2) on the screen
  LevelHalfWidths half_widths{};
};

struct SpreadEstimate {
  bool found = false;
  double variance_px2 = 0.0;  // s^2
  double sigma_px2 = 0.0;     // its one-sigma
  int samples = 0;            // used at the chosen level
  double level = 0.0;         // the chosen level (fraction of the typical height)
};

// s^2 from the half-widths' fall with writing speed, at whichever level gives
// the tightest estimate. Not found unless the points span writing speeds
// kMinSpeedRatio apart and the estimate is clearly above zero.
SpreadEstimate EstimateSpread(const std::vector<SpreadPoint>& points);

}  // namespace impactlab::digitize
