// The digitizer in conditions beyond the styles' ranges: extreme rotation and
// perspective, heavy noise, a trace touching its band's edge, traces lying on
// grid lines, saturated glare over a trace, a tiny photo.
#include <cmath>
#include <functional>
#include <numbers>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "render/oscillograph.h"
#include "tests/digitize/photo_scenes.h"

namespace impactlab {
namespace {

using testing::RunScene;
using testing::ScoreTrace;
using testing::Settings;
using testing::TraceScore;

RenderedPhoto Render(const RunScene& run, PhotoStyle style, int width_px,
                     const std::function<void(RenderOptions&)>& adjust = {}) {
  RenderOptions options;
  options.style = style;
  options.width_px = width_px;
  options.seed = 5;
  if (adjust) adjust(options);
  return RenderOscillograph(run.scene, options);
}

// Digitizes `image` (the photo's, or a spoiled copy) and checks every trace
// against the truth: centre RMS below `max_rms_px`, no sample off the trace.
DigitizeResult CheckTraces(const RunScene& run, const RenderedPhoto& photo, const cv::Mat& image,
                           double max_rms_px, double min_coverage = 0.6) {
  const DigitizeResult result = DigitizePhoto({image, "stress.png"}, {10, 8}, run.requests, {});
  for (std::size_t t = 0; t < result.traces.size(); ++t) {
    const TraceScore score = ScoreTrace(result.traces[t], photo, run.scene.traces[t], {10, 8});
    INFO(result.traces[t].name << ": rms " << score.rms_px << " px, max " << score.max_px
                               << " px, coverage " << score.coverage);
    CHECK(score.rms_px < max_rms_px);
    CHECK(score.far_samples == 0);
    CHECK(score.coverage > min_coverage);
  }
  return result;
}

double PulseError(const DigitizeResult& result) {
  const double truth = testing::kPulseFallS - testing::kPulseRiseS;
  for (const auto& pulse : result.pulses) {
    if (pulse) return std::abs(pulse->pulse.width_s.value - truth) / truth;
  }
  return HUGE_VAL;
}

}  // namespace

TEST_CASE("digitize stress: rotation of 15 degrees either way, and steep perspective") {
  const RunScene run = testing::StandardRunScene();
  for (const double degrees : {15.0, -15.0}) {
    INFO("rotation " << degrees);
    const RenderedPhoto photo = Render(run, PhotoStyle::kPolaroid, 1400,
                                       [&](RenderOptions& o) { o.rotation_deg = degrees; });
    CHECK(PulseError(CheckTraces(run, photo, photo.image, 0.35)) < 0.005);
  }
  const RenderedPhoto phone = Render(run, PhotoStyle::kPhone, 1400, [](RenderOptions& o) {
    o.tilt_deg = 30.0;
    o.barrel_k1 = -0.1;
  });
  const DigitizeResult result = CheckTraces(run, phone, phone.image, 0.35);
  CHECK(result.graticule.radial_fitted);
  CHECK(result.graticule.mapping.radial_k1 == Approx(-0.1).margin(0.01));
}

TEST_CASE("digitize stress: heavy noise") {
  const RunScene run = testing::StandardRunScene();
  const RenderedPhoto photo = Render(run, PhotoStyle::kPhone, 1400);
  cv::Mat noisy;
  photo.image.convertTo(noisy, CV_16S);
  cv::Mat noise(noisy.size(), noisy.type());
  cv::theRNG().state = 7;
  cv::randn(noise, 0.0, 20.0);  // 8 % of full scale per pixel, on top of the phone's own
  noisy += noise;
  noisy.convertTo(noisy, CV_8U);
  CHECK(PulseError(CheckTraces(run, photo, noisy, 0.6)) < 0.01);
}

TEST_CASE("digitize stress: a trace touching its band's edge on the ticked centre axis") {
  // Rebound arcs down to 0 V, which is the band's lower edge and the
  // graticule's horizontal axis with its minor ticks.
  RunScene run;
  ScreenTrace right{"right", {}, {}, Settings(0.5, 0.2, 0.0, {0.0, 4.0})};
  for (int i = 0; i <= 4000; ++i) {
    const double t = 5.0 * i / 4000;
    right.time_s.push_back(t);
    right.volts.push_back(0.6 * std::abs(std::sin(std::numbers::pi * t / 1.3)));
  }
  run.scene.traces = {right};
  run.requests = {{"right", right.settings}};
  const RenderedPhoto photo = Render(run, PhotoStyle::kClean, 1400);
  const DigitizeResult result = CheckTraces(run, photo, photo.image, 0.2, 0.7);
  double lowest = HUGE_VAL;
  for (const cv::Point2d& p : result.traces[0].screen_div) lowest = std::min(lowest, p.y);
  CHECK(lowest < 0.1);  // followed down to the edge
}

TEST_CASE("digitize stress: traces lying on grid lines") {
  // The contact levels on the lines y = -3 and y = -1 (the manifest example's
  // settings), and a flat trace along y = 2.
  RunScene run;
  ScreenTrace flat{"flat", {}, {}, Settings(0.5, 0.2, 2.0, {1.5, 3.0})};
  for (int i = 0; i <= 500; ++i) {
    flat.time_s.push_back(0.01 * i);
    flat.volts.push_back(0.0);
  }
  ScreenTrace contact{"contact", {}, {}, Settings(100e-6, 1.0, -3.0, {-4.0, -0.5})};
  contact.settings.impact = 1;
  for (int i = 0; i <= 1000; ++i) {
    const double t = i * 1e-6;
    contact.time_s.push_back(t);
    contact.volts.push_back(
        t > testing::kPulseRiseS - 0.5e-6 && t < testing::kPulseFallS + 0.5e-6 ? 2.0 : 0.0);
  }
  run.scene.traces = {flat, contact};
  run.requests = {{"flat", flat.settings}, {"contact", contact.settings}};
  for (const PhotoStyle style : {PhotoStyle::kClean, PhotoStyle::kPolaroid}) {
    INFO(PhotoStyleName(style));
    const RenderedPhoto photo = Render(run, style, 1400);
    CHECK(PulseError(CheckTraces(run, photo, photo.image, 0.3, 0.8)) < 0.005);
  }
}

TEST_CASE("digitize stress: a trace running beside a grid line all along the sweep") {
  // 0.1 division above the line y = 2: brighter than the line, it draws the
  // line's measurements to itself, yet the graticule and the trace are found.
  for (const double offset_div : {0.03, 0.1}) {
    RunScene run;
    ScreenTrace flat{"flat", {}, {}, Settings(0.5, 0.2, 2.0 + offset_div, {1.5, 3.0})};
    for (int i = 0; i <= 500; ++i) {
      flat.time_s.push_back(0.01 * i);
      flat.volts.push_back(0.0);
    }
    run.scene.traces = {flat};
    run.requests = {{"flat", flat.settings}};
    INFO("offset " << offset_div);
    const RenderedPhoto photo = Render(run, PhotoStyle::kPolaroid, 1400);
    CheckTraces(run, photo, photo.image, 0.15, 0.9);
  }
}

TEST_CASE("digitize stress: saturated glare over a trace leaves a gap, not a made-up trace") {
  const RunScene run = testing::StandardRunScene();
  const RenderedPhoto photo = Render(run, PhotoStyle::kPhone, 1400);
  cv::Mat glared = photo.image.clone();
  const cv::Point2d centre = photo.ImageFromScreen({3.0, 2.0});
  const double px_per_div = cv::norm(photo.ImageFromScreen({4.0, 2.0}) - centre);
  cv::ellipse(glared, cv::Point(centre), cv::Size(px_per_div * 0.8, px_per_div * 0.5), 20.0, 0.0,
              360.0, cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_AA);
  cv::GaussianBlur(glared, glared, cv::Size(), 1.0);
  const DigitizeResult result = CheckTraces(run, photo, glared, 0.35, 0.5);
  // Nothing inside the white blob.
  for (const cv::Point2d& p : result.traces[0].screen_div) {
    const double dx = (p.x - 3.0) / 0.75, dy = (p.y - 2.0) / 0.75;
    CHECK(dx * dx + dy * dy > 0.25);
  }
}

TEST_CASE("digitize stress: a tiny photo") {
  const RunScene run = testing::StandardRunScene();
  const RenderedPhoto photo = Render(run, PhotoStyle::kClean, 400);
  const DigitizeResult result = CheckTraces(run, photo, photo.image, 0.3, 0.2);
  // A pixel is a percent of this pulse: within 3 %, and within its stated uncertainty.
  REQUIRE(result.pulses[2]);
  const double truth = testing::kPulseFallS - testing::kPulseRiseS;
  CHECK(PulseError(result) < 0.03);
  const ContactPulse& pulse = result.pulses[2]->pulse;
  CHECK(std::abs(pulse.width_s.value - truth) < 3.0 * pulse.width_s.sigma);
}

}  // namespace impactlab
