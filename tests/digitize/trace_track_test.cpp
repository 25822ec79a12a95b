// The coarse tracking (digitize/trace_track.cpp) against lines that are not
// the beam's: a scratch that runs on beyond the CRT's face, a line beside
// the trace that the course reaches or leaves by a jump across a gap.
#include <algorithm>
#include <cmath>
#include <numbers>
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

// A calibration's release swing: 0.05 s/div, the release level flat over the
// sweep's first division, the bar at equilibrium at 7.5 divisions.
testing::RunScene ReleaseSwingScene() {
  testing::RunScene run;
  ScreenTrace trace{"calibration",         {}, {}, testing::Settings(0.05, 0.2, -2.0, {-3.5, 3.5}),
                    BeamMode::kContinuous, 0};
  for (int i = 0; i <= 2000; ++i) {
    const double t = 0.5 * i / 2000;
    trace.time_s.push_back(t);
    trace.volts.push_back(testing::PhotocellVolts(t, 1.0, 1.5, 0.8, 0.0));
  }
  run.scene.traces = {trace};
  run.requests.push_back({trace.name, trace.settings});
  return run;
}

// The trace's screen y at screen x (divisions), from the scene's truth.
double ReleaseSwingY(const testing::RunScene& run, double x_div) {
  const ScreenTrace& trace = run.scene.traces[0];
  const double t = x_div * trace.settings.time_per_div;
  return trace.settings.zero_div +
         testing::PhotocellVolts(t, 1.0, 1.5, 0.8, 0.0) / trace.settings.volts_per_div;
}

// A calibration's free swing from the release over the whole sweep (0.5 s,
// a third of the 1.5 s period: the bar passes equilibrium at 7.5 divisions
// and swings on to half its release displacement the other way), through
// the same curved cell. The trace falls across the screen, one way.
testing::RunScene CalibrationSwingScene() {
  testing::RunScene run;
  ScreenTrace trace{
      "right", {}, {}, testing::Settings(0.05, 0.2, -2.0, {-3.5, 3.5}), BeamMode::kContinuous, 0};
  for (int i = 0; i <= 2000; ++i) {
    const double t = 0.5 * i / 2000;
    const double x = std::cos(2.0 * std::numbers::pi * t / 1.5);
    trace.time_s.push_back(t);
    trace.volts.push_back(0.05 + 0.6 * x - 0.04 * x * x);
  }
  run.scene.traces = {trace};
  return run;
}

// A pen ring round a stretch of the trace, drawn as thin as the beam and
// brighter: an arc of a circle (screen divisions), from `from_deg` to
// `to_deg` counter-clockwise as seen on the screen (y up).
void PenArc(cv::Mat& image, const RenderedPhoto& photo, cv::Point2d centre_div, double radius_div,
            double from_deg, double to_deg, double level, int thickness_px) {
  std::vector<cv::Point> points;
  for (double a = from_deg; a <= to_deg; a += 1.0) {
    const double r = a * std::numbers::pi / 180.0;
    const cv::Point2d p = photo.ImageFromScreen(
        {centre_div.x + radius_div * std::cos(r), centre_div.y + radius_div * std::sin(r)});
    points.emplace_back(cvRound(p.x * 16), cvRound(p.y * 16));
  }
  const double full = image.depth() == CV_16U ? 65535.0 : 255.0;
  cv::polylines(image, points, false, cv::Scalar::all(level * full), thickness_px, cv::LINE_AA, 4);
}

}  // namespace

TEST_CASE("trace track: a calibration's course does not turn back along a pen ring") {
  // A ring drawn round the falling trace mid-sweep (randomised seed 4018's
  // calibration L-0.405, whose course took a ring's lower arc; 2009's
  // and 4027's L-0.713, strokes across the trace): as thin as the
  // beam, so no width test takes it for a mark, and brighter than the
  // trace, so column by column its arcs out-earn the trace inside it. Either
  // arc leaves the trace and comes back to it, rising and falling over half
  // a division. A free swing from the release moves the bar one way until
  // it passes equilibrium (a quarter period, 0.375 s here), and the cell's
  // output is monotone in its displacement: the trace never turns back
  // there, and a reading that does took something else.
  testing::RunScene run = CalibrationSwingScene();
  const ScreenTrace& truth = run.scene.traces[0];
  const double t = 3.0 * truth.settings.time_per_div;
  const double x = std::cos(2.0 * std::numbers::pi * t / 1.5);
  const double y =
      truth.settings.zero_div + (0.05 + 0.6 * x - 0.04 * x * x) / truth.settings.volts_per_div;
  constexpr double kQuarterPeriod = 0.375;
  for (const double one_way_until_s : {kQuarterPeriod, 0.0}) {
    RenderedPhoto photo = RenderOscillograph(run.scene, testing::CleanOptions(1600, 7));
    PenArc(photo.image, photo, {3.0, y}, 0.8, 0.0, 360.0, 1.0, 3);
    const std::vector<TraceRequest> requests = {{truth.name, truth.settings, one_way_until_s}};
    const DigitizeResult result =
        DigitizePhoto({photo.image, "ring-on-trace.png"}, {10, 8}, requests, {});
    REQUIRE(result.ok);
    const std::vector<double> misses = TrackMisses(result.traces[0], photo);
    const std::size_t far = TrackFarOff(misses, 3.0);
    const bool one_way = one_way_until_s > 0.0;
    INFO((one_way ? "one way" : "any course")
         << ": " << misses.size() << " samples, " << far << " more than 3 px off the trace");
    if (one_way) {
      CHECK(misses.size() > 800);
      CHECK(far <= misses.size() / 100);
    } else {
      // A course that may turn back takes an arc of the ring.
      CHECK(far > misses.size() / 50);
    }
  }
}

TEST_CASE("trace track: a calibration read without turning back is read as any trace is") {
  // The one-way reading is only a second look at a reading that turns back:
  // a clean calibration's reading is the same sample for sample.
  testing::RunScene run = CalibrationSwingScene();
  const ScreenTrace& truth = run.scene.traces[0];
  const RenderedPhoto photo = RenderOscillograph(run.scene, testing::CleanOptions(1600, 7));
  std::vector<std::vector<double>> volts;
  for (const double one_way_until_s : {0.375, 0.0}) {
    const std::vector<TraceRequest> requests = {{truth.name, truth.settings, one_way_until_s}};
    const DigitizeResult result =
        DigitizePhoto({photo.image, "clean-swing.png"}, {10, 8}, requests, {});
    REQUIRE(result.ok);
    volts.push_back(result.traces[0].trace.volts);
  }
  CHECK(volts[0].size() > 800);
  CHECK(volts[0] == volts[1]);
}

TEST_CASE("trace track: a line the course begins on and leaves by a jump across a gap") {
  // The trace's first 0.7 division hidden (a blot, glare burnt out) and a
  // brighter line 0.35 division beside that stretch, ending where the trace
  // reappears: a course begins on the line and steps across the gap onto the
  // trace, on course, with no slope yet to keep it from jumping. The trace is
  // continuous, so a jump its slope does not explain is not its own: the line
  // is no part of the course, whichever side of the trace it lies.
  const testing::RunScene run = ReleaseSwingScene();
  for (const double side : {0.35, -0.35}) {
    RenderedPhoto photo = RenderOscillograph(run.scene, testing::CleanOptions(1600, 7));
    const double y0 = ReleaseSwingY(run, 0.0), y1 = ReleaseSwingY(run, 0.7);
    const double px_per_div =
        photo.ImageFromScreen({1.0, 0.0}).x - photo.ImageFromScreen({0.0, 0.0}).x;
    const int blot_px = static_cast<int>(std::lround(0.15 * px_per_div));
    testing::Scratch(photo.image, photo, {-0.1, y0}, {0.7, y1}, 0.0, blot_px);
    testing::Scratch(photo.image, photo, {0.02, y0 + side}, {0.68, y1 + side}, 1.0, 3);
    const DigitizeResult result =
        DigitizePhoto({photo.image, "line-at-start.png"}, {10, 8}, run.requests, {});
    REQUIRE(result.ok);
    const std::vector<double> misses = TrackMisses(result.traces[0], photo);
    const std::size_t far = TrackFarOff(misses, 3.0);
    INFO("line " << side << " division beside the hidden start: " << misses.size() << " samples, "
                 << far << " more than 3 px off the trace");
    CHECK(misses.size() > 500);
    CHECK(far == 0);
  }
}

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
