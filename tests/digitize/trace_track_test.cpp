// The coarse tracking (digitize/trace_track.cpp) against lines that are not
// the beam's: a scratch that runs on beyond the CRT's face.
#include <algorithm>
#include <vector>

#include <catch2/catch.hpp>

#include "digitize/digitize.h"
#include "photo_scenes.h"
#include "render/oscillograph.h"

namespace impactlab {
namespace {

// Each sample's distance (photo pixels) from the true centre line.
std::vector<double> TrackMisses(const DigitizedTrace& trace, const RenderedPhoto& photo) {
  std::vector<double> misses;
  for (const TraceTruth& t : photo.traces) {
    if (t.name != trace.name) continue;
    std::size_t hint = 0;
    for (const cv::Point2d& p : trace.centre_px) {
      misses.push_back(testing::DistanceToPolyline(t.centre_px, p, hint));
    }
  }
  return misses;
}

std::size_t TrackFarOff(const std::vector<double>& misses, double limit_px) {
  return static_cast<std::size_t>(
      std::count_if(misses.begin(), misses.end(), [&](double d) { return d > limit_px; }));
}

}  // namespace

TEST_CASE("trace track: a scratch running on beyond the face is not the dotted trace's course") {
  // Sparse dots (a fifth of each 0.12-division chopper slot) crossed by a
  // long thin scratch that comes in from the photo's surround, over the
  // bezel, and runs at a shallow angle across the right trace's band for
  // several divisions: column by column the continuous scratch earns more
  // than the dots, and the course took it wherever the trace swings away
  // from it. The beam draws nowhere beyond the face, so the scratch is not
  // the trace.
  const testing::RunScene run = testing::StandardRunScene();
  for (const auto& [level, thickness] : {std::pair{0.5, 1}, std::pair{0.35, 3}}) {
    RenderOptions options = testing::CleanOptions(2000, 5);
    options.chop_dash_div = 0.12;
    options.chop_duty = 0.22;
    options.beam_fwhm_div = 0.025;
    RenderedPhoto photo = RenderOscillograph(run.scene, options);
    testing::Scratch(photo.image, photo, {-1.6, 3.1}, {6.0, 1.9}, level, thickness);
    const DigitizeResult result =
        DigitizePhoto({photo.image, "scratch-beyond-face.png"}, {10, 8}, run.requests, {});
    const DigitizedTrace& right = result.traces[0];
    const std::vector<double> misses = TrackMisses(right, photo);
    const std::size_t far = TrackFarOff(misses, 3.0);
    INFO("scratch " << thickness << " px at " << level << " of full scale: " << misses.size()
                    << " samples, " << far << " more than 3 px off the trace");
    // Along the dots, but for the few samples where the scratch crosses them.
    CHECK(misses.size() > 150);
    CHECK(far <= misses.size() / 20);
  }
}

}  // namespace impactlab
