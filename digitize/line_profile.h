// A bright line's centre across it, to a fraction of a pixel (internal to
// digitize/). Grid lines and traces are both measured this way: the photo is
// read along a short straight profile crossing the line, and the line's
// centre along the profile is found by one of the sub-pixel methods.
#pragma once

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "digitize/digitize.h"
#include "digitize/ink_sampler.h"

namespace impactlab::digitize {

// Ink read at origin + direction * (start_px + i * step_px), i = 0 .. n-1.
struct Profile {
  cv::Point2d origin_px;
  cv::Point2d direction;  // unit vector in the photo
  double start_px = 0.0;
  double step_px = 1.0;
  std::vector<float> values;
  // Other lines (the graticule's) crossing the profile: where, and how far
  // along the profile either side their light reaches.
  struct Crossing {
    double offset_px = 0.0;  // where its centre crosses
    double fwhm_px = 0.0;    // its full width at half maximum, along the profile
    double reach_px = 0.0;   // how far either side its light is taken to reach
  };
  std::vector<Crossing> crossings;
  // Where a short line (a minor tick, the graticule's end) runs along part
  // of the profile, it lights a stretch that no crossing model describes:
  // the stretch on the origin's side of every such line (offsets) is clear
  // of their light. Both infinite: nothing lit.
  double clear_lo_px = -HUGE_VAL, clear_hi_px = HUGE_VAL;

  bool BesideShortLine() const { return clear_lo_px > -HUGE_VAL || clear_hi_px < HUGE_VAL; }

  double OffsetAt(int i) const { return start_px + i * step_px; }
  cv::Point2d PointAt(double offset_px) const { return origin_px + direction * offset_px; }
};

// Cuts a profile beside a short line to its clear stretch (Profile::clear_*)
// when that still reaches `min_reach_px` either side of the origin; returns
// whether the profile can be used.
bool CutToClearStretch(Profile& profile, double min_reach_px);

// Reads a profile of half-length `half_length_px` centred on `origin_px`.
Profile ReadProfile(const InkSampler& ink, cv::Point2d origin_px, cv::Point2d direction,
                    double half_length_px, double step_px);

struct LineCentre {
  bool found = false;
  double offset_px = 0.0;        // the centre along the profile, from its origin
  double height = 0.0;           // peak above the background, ink units
  double background = 0.0;       // at the centre, ink units
  double background_step = 0.0;  // right side's background less the left's, ink units: a
                                 // line has the same either side, an edge does not
  double fwhm_px = 0.0;          // full width at half maximum
  double crossing_share = 0.0;   // share of the profile's asymmetry a crossing line explained
                                 // (0: none crossed near, or it did not matter)
};

struct CentreSettings {
  SubpixelMethod method = SubpixelMethod::kCentroid;
  double centroid_level = 0.5;   // kCentroid: fraction of the height the weights start at
  double search_px = 1e9;        // the peak is looked for within this distance of offset 0
  double crossing_height = 0.0;  // a crossing line's height: its light counts this much less
                                 // in the search for the peak
  // A grid line's full width at half maximum across it, pixels (0: not
  // known): a crossing no wider than about this in the profile runs along
  // the measured line rather than across it.
  double crossing_fwhm_px = 0.0;
  // Where a crossing line reaches the core, the symmetric centre below
  // instead of `method`.
  bool symmetric_near_crossings = true;
};

// The centre of the brightest line within `search_px` of the profile's
// origin. The background is the straight line through the medians of the
// profile's outer fifths. found = false when no peak stands out (height <= 0
// or no half-maximum crossing on either side).
//
// A crossing line near the measured one would pull any weighted mean towards
// it. With `symmetric_near_crossings` the centre is then instead where the profile is most nearly
// symmetric once the crossing's light is allowed for: for each trial centre c the differences v(c +
// d) - v(c - d) are fitted by A (g(c + d) - g(c - d)), g the crossing's Gaussian profile and A >= 0
// its height there (lower than on the bare screen where the line's glow already saturates the
// photo), and the c leaving the least residual wins. The measured line's own shape cancels in the
// differences, whatever it is, as long as it is symmetric.
LineCentre FindLineCentre(const Profile& profile, const CentreSettings& settings);

}  // namespace impactlab::digitize
