// The beam on the screen (internal to render/): where each trace's beam runs,
// how bright it writes, where the chopper blanks it, and its analytic drawing.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "render/oscillograph.h"

namespace impactlab::render {

// A straight stretch of unblanked beam on the screen.
struct BeamSegment {
  cv::Point2d from_div;
  cv::Point2d to_div;
  float brightness = 1.0f;  // relative exposure: 1 at the sweep's own writing speed
};

struct ChopperSettings {
  double dash_div = 0.2;   // length of one chopper slot along the sweep
  double duty = 0.75;      // fraction of its slot a trace is unblanked
  double phase_div = 0.0;  // where the slots start along the sweep
};

// One trace's beam and its truth (centre_px still empty: the camera fills it).
struct TraceBeam {
  std::vector<BeamSegment> segments;
  TraceTruth truth;
};

// The faintest a fast beam is drawn, relative to the sweep's brightness: the
// exposure falls as 1 / writing speed, but scattered light and the photo's
// toe keep a fast edge from vanishing entirely.
inline constexpr float kMinBeamBrightness = 0.02f;

// The beams of the scene's traces, clipped to `visible_div` (the screen face);
// the truth lists the samples on the graticule.
std::vector<TraceBeam> LayOutBeams(const OscillographScene& scene, const ChopperSettings& chopper,
                                   const cv::Rect2d& graticule_div, const cv::Rect2d& visible_div);

// Draws the segments into `layer` (CV_32FC1) as a beam with a Gaussian cross
// section of `sigma_px`: each pixel gets brightness * exp(-d^2 / 2 sigma^2),
// d the distance of its centre to the nearest segment, so the centre line is
// exactly where the segments are. Overlapping segments of one trace take the
// maximum, so joints do not double-expose. `canvas_from_screen` maps screen
// divisions to layer pixels.
void DrawBeam(const std::vector<BeamSegment>& segments, const cv::Matx23d& canvas_from_screen,
              double sigma_px, cv::Mat& layer);

}  // namespace impactlab::render
