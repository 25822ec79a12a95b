// Tests of the oscillograph renderer against its own truth: the traces and the
// graticule are measured in the rendered images and compared with where the
// renderer says it drew them.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <catch2/catch.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "render/oscillograph.h"
#include "render/styles.h"
#include "tests/render/sweep_settings.h"

namespace impactlab {
namespace {

constexpr std::array<PhotoStyle, 5> kAllStyles = {PhotoStyle::kClean, PhotoStyle::kPolaroid,
                                                  PhotoStyle::kPhone, PhotoStyle::kNegative,
                                                  PhotoStyle::kLowres};

// Two slow, continuous displacement-like traces, one in each half of the
// screen, clear of the graticule rows y = +-1 where the graticule is measured.
OscillographScene TwoSineScene() {
  OscillographScene scene;
  ScreenTrace right{"right", {}, {}, testing::SweepSettings(0.5, 0.2, 2.0)};
  ScreenTrace left{"left", {}, {}, testing::SweepSettings(0.5, 0.2, -2.5)};
  for (int i = 0; i <= 2000; ++i) {
    const double t = 5.0 * i / 2000;
    right.time_s.push_back(t);
    right.volts.push_back(0.14 * std::sin(2.0 * std::numbers::pi * t / 4.0));
    left.time_s.push_back(t);
    left.volts.push_back(0.12 * std::cos(2.0 * std::numbers::pi * t / 3.0));
  }
  scene.traces = {right, left};
  return scene;
}

// The image as one float channel in which the traces are bright: grey, scaled
// to [0, 1], inverted for the negative.
cv::Mat1f BrightTraces(const RenderedPhoto& photo, PhotoStyle style) {
  cv::Mat grey = photo.image;
  if (grey.channels() == 3) cv::cvtColor(grey, grey, cv::COLOR_BGR2GRAY);
  cv::Mat1f values;
  grey.convertTo(values, CV_32F, grey.depth() == CV_16U ? 1.0 / 65535 : 1.0 / 255);
  if (style == PhotoStyle::kNegative) values = 1.0f - values;
  return values;
}

float Bilinear(const cv::Mat1f& image, cv::Point2d p) {
  const int x0 = static_cast<int>(std::floor(p.x)), y0 = static_cast<int>(std::floor(p.y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= image.cols || y0 + 1 >= image.rows) return 0.0f;
  const float fx = static_cast<float>(p.x - x0), fy = static_cast<float>(p.y - y0);
  return (image(y0, x0) * (1 - fx) + image(y0, x0 + 1) * fx) * (1 - fy) +
         (image(y0 + 1, x0) * (1 - fx) + image(y0 + 1, x0 + 1) * fx) * fy;
}

// Where a bright line crossing `point` along `normal` (unit) really lies: the
// intensity-weighted centroid of the profile across it, above a background
// that is linear between the profile's two ends. The profile is averaged over
// `along_px` either side along the line. Pixels from `point`, along `normal`.
double MeasureLineOffsetPx(const cv::Mat1f& image, cv::Point2d point, cv::Point2d normal,
                           double half_width_px, double along_px = 0.0) {
  constexpr double kStepPx = 0.25;
  const cv::Point2d tangent(normal.y, -normal.x);
  std::vector<double> offsets, values;
  for (double s = -half_width_px; s <= half_width_px + 1e-9; s += kStepPx) {
    double sum = 0.0;
    int count = 0;
    for (double t = -along_px; t <= along_px + 1e-9; t += 1.0, ++count) {
      sum += Bilinear(image, point + normal * s + tangent * t);
    }
    offsets.push_back(s);
    values.push_back(sum / count);
  }
  const std::size_t n = values.size(), end = n / 6;
  double left = 0.0, right = 0.0;
  for (std::size_t i = 0; i < end; ++i) left += values[i] / end, right += values[n - 1 - i] / end;
  double weight = 0.0, moment = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double background = left + (right - left) * i / (n - 1.0);
    const double w = std::max(0.0, values[i] - background);
    weight += w;
    moment += w * offsets[i];
  }
  return weight > 0.0 ? moment / weight : 1e9;
}

cv::Point2d Unit(cv::Point2d v) { return v / std::hypot(v.x, v.y); }

// How far the truth and the measured beam centre line disagree along a trace,
// at samples clear of the graticule, the chopper's gaps and the image edges.
struct Disagreement {
  double median_px = 0.0;
  double p90_px = 0.0;
  double mean_px = 0.0;  // signed: a bias
  std::size_t count = 0;
};

constexpr double kMaxCurvaturePerDiv = 0.25;

Disagreement MeasureTrace(const cv::Mat1f& image, const TraceTruth& truth, double px_per_div,
                          double along_px = 0.0) {
  std::vector<double> errors;
  const double half_width_px = std::max(6.0, 0.08 * px_per_div);
  for (std::size_t i = 1; i + 1 < truth.centre_px.size(); i += 7) {
    const cv::Point2d s = truth.screen_div[i];
    const double off_x = std::abs(s.x - std::round(s.x)), off_y = std::abs(s.y - std::round(s.y));
    // Clear of the division lines, the centre axes' ticks, and not too near
    // the graticule's edge.
    if (off_x < 0.15 || off_y < 0.15 || std::abs(s.y) < 0.3 || std::abs(s.x - 5.0) < 0.3) continue;
    if (!truth.drawn[i - 1] || !truth.drawn[i] || !truth.drawn[i + 1]) continue;
    // Where the trace bends, the glow and the blur, which spread light to both
    // sides, pile it up on the inner side: a real shift of the photo's line
    // (about sigma^2 / 2R) but not of the beam's centre, which the truth is.
    if (i >= 5 && i + 5 < truth.screen_div.size()) {
      const cv::Point2d bend =
          truth.screen_div[i + 5] + truth.screen_div[i - 5] - 2.0 * truth.screen_div[i];
      const double step_div = cv::norm(truth.screen_div[i + 5] - truth.screen_div[i - 5]) / 2;
      if (cv::norm(bend) / (step_div * step_div) > kMaxCurvaturePerDiv) continue;
    }
    const cv::Point2d tangent = Unit(truth.centre_px[i + 1] - truth.centre_px[i - 1]);
    const cv::Point2d normal(-tangent.y, tangent.x);
    errors.push_back(
        MeasureLineOffsetPx(image, truth.centre_px[i], normal, half_width_px, along_px));
  }
  Disagreement d;
  d.count = errors.size();
  if (errors.empty()) return d;
  for (const double e : errors) d.mean_px += e / errors.size();
  std::vector<double> magnitudes;
  for (const double e : errors) magnitudes.push_back(std::abs(e));
  std::sort(magnitudes.begin(), magnitudes.end());
  d.median_px = magnitudes[magnitudes.size() / 2];
  d.p90_px = magnitudes[magnitudes.size() * 9 / 10];
  return d;
}

double PixelsPerDivision(const RenderedPhoto& photo) {
  return cv::norm(photo.ImageFromScreen({6.0, 0.0}) - photo.ImageFromScreen({4.0, 0.0})) / 2.0;
}

// Tolerances per style, about 1.5 times the worst seen over seeds 1..20 at
// 1600 px (lowres: 1000 px). The clean photo agrees with its truth to about
// 0.02 px; grain, dust, glare, JPEG and blur scatter single measurements
// (the 90th percentile) but hardly bias them.
struct Tolerance {
  double median_px;    // of |measured - truth| along a trace
  double p90_px;       // its 90th percentile
  double bias_px;      // |mean of measured - truth|
  double crossing_px;  // a graticule intersection's distance from the truth
};

// The randomised style (the last tests): median and bias of |measured - truth|.
constexpr double kRandomisedMedianPx = 0.2;  // worst seen 0.12 px
constexpr double kRandomisedBiasPx = 0.1;    // worst seen 0.054 px
constexpr double kPrintMedianPx = 0.7;       // randomised prints: worst seen 0.46 px
constexpr double kPrintBiasPx = 0.4;         // worst seen 0.24 px

const std::map<PhotoStyle, Tolerance> kTolerance = {
    {PhotoStyle::kClean, {0.05, 0.1, 0.05, 0.05}}, {PhotoStyle::kPolaroid, {0.2, 0.4, 0.08, 0.5}},
    {PhotoStyle::kPhone, {0.1, 0.2, 0.05, 0.5}},   {PhotoStyle::kNegative, {0.2, 0.4, 0.08, 0.4}},
    {PhotoStyle::kLowres, {0.15, 0.3, 0.05, 0.6}},
};

}  // namespace

TEST_CASE("oscillograph: trace centre lies where the truth says in every style") {
  const OscillographScene scene = TwoSineScene();
  for (const PhotoStyle style : kAllStyles) {
    for (const std::uint64_t seed : {1u, 2u}) {
      RenderOptions options;
      options.style = style;
      options.seed = seed;
      if (style != PhotoStyle::kLowres) options.width_px = 1600;
      const RenderedPhoto photo = RenderOscillograph(scene, options);
      const cv::Mat1f image = BrightTraces(photo, style);
      const Tolerance tolerance = kTolerance.at(style);
      for (const TraceTruth& truth : photo.traces) {
        const Disagreement d = MeasureTrace(image, truth, PixelsPerDivision(photo));
        INFO(PhotoStyleName(style)
             << " seed " << seed << " trace " << truth.name << ": median " << d.median_px
             << " px, p90 " << d.p90_px << " px, bias " << d.mean_px << " px over " << d.count);
        REQUIRE(d.count > 40);
        CHECK(d.median_px <= tolerance.median_px);
        CHECK(d.p90_px <= tolerance.p90_px);
        CHECK(std::abs(d.mean_px) <= tolerance.bias_px);
      }
    }
  }
}

TEST_CASE("oscillograph: graticule intersections lie at ImageFromScreen of the grid points") {
  const OscillographScene scene = TwoSineScene();
  // Intersections off the centre axes (ticks) and clear of the traces.
  const std::vector<cv::Point2d> grid_points = {{2, 1}, {3, -1}, {4, 1}, {6, -1}, {7, 1}, {8, -1}};
  for (const PhotoStyle style : kAllStyles) {
    RenderOptions options;
    options.style = style;
    options.seed = 3;
    if (style != PhotoStyle::kLowres) options.width_px = 1600;
    const RenderedPhoto photo = RenderOscillograph(scene, options);
    const cv::Mat1f image = BrightTraces(photo, style);
    const double px_per_div = PixelsPerDivision(photo);
    const double half_width_px = std::max(5.0, 0.06 * px_per_div);
    const double along_px = 0.08 * px_per_div;
    double worst_px = 0.0;
    for (const cv::Point2d& grid : grid_points) {
      // Both lines' positions across them, a quarter division to either side
      // of the crossing: their mean is where the crossing is.
      const cv::Point2d across_vertical =
          Unit(photo.ImageFromScreen(grid + cv::Point2d(0.01, 0)) - photo.ImageFromScreen(grid));
      const cv::Point2d across_horizontal =
          Unit(photo.ImageFromScreen(grid + cv::Point2d(0, 0.01)) - photo.ImageFromScreen(grid));
      double vertical_px = 0.0, horizontal_px = 0.0;
      for (const double side : {-0.25, 0.25}) {
        vertical_px +=
            0.5 * MeasureLineOffsetPx(image, photo.ImageFromScreen(grid + cv::Point2d(0.0, side)),
                                      across_vertical, half_width_px, along_px);
        horizontal_px +=
            0.5 * MeasureLineOffsetPx(image, photo.ImageFromScreen(grid + cv::Point2d(side, 0.0)),
                                      across_horizontal, half_width_px, along_px);
      }
      worst_px = std::max(worst_px, std::hypot(vertical_px, horizontal_px));
    }
    INFO(PhotoStyleName(style) << ": worst intersection offset " << worst_px << " px");
    CHECK(worst_px <= kTolerance.at(style).crossing_px);
  }
}

TEST_CASE("oscillograph: truth is the mapping applied to the samples' screen positions") {
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.style = PhotoStyle::kPhone;  // perspective and barrel distortion
  options.width_px = 1000;
  const RenderedPhoto photo = RenderOscillograph(scene, options);
  REQUIRE(photo.mapping.radial_k1 < 0.0);
  for (const TraceTruth& truth : photo.traces) {
    REQUIRE(truth.centre_px.size() == truth.screen_div.size());
    REQUIRE(truth.time_s.size() == truth.screen_div.size());
    for (std::size_t i = 0; i < truth.centre_px.size(); i += 50) {
      CHECK(cv::norm(truth.centre_px[i] - photo.ImageFromScreen(truth.screen_div[i])) == 0.0);
      CHECK(cv::norm(photo.mapping.ScreenFromImage(truth.centre_px[i]) - truth.screen_div[i]) <
            1e-9);
    }
  }
  // The sweep covers 10 divisions of 0.5 s: the last sample is on the edge.
  CHECK(photo.traces[0].time_s.back() == Approx(5.0));
}

TEST_CASE("oscillograph: samples off the graticule are clipped and have no truth") {
  OscillographScene scene;
  // A calibration swing of 12 divisions peak to peak, sampled beyond the sweep.
  ScreenTrace swing{"calibration", {}, {}, testing::SweepSettings(0.5, 0.1, 0.0)};
  for (int i = 0; i <= 3000; ++i) {
    swing.time_s.push_back(-1.0 + 7.0 * i / 3000);
    swing.volts.push_back(0.6 * std::sin(2.0 * std::numbers::pi * swing.time_s.back() / 2.0));
  }
  scene.traces = {swing};
  RenderOptions options;
  options.width_px = 800;
  const RenderedPhoto photo = RenderOscillograph(scene, options);
  const TraceTruth& truth = photo.traces[0];
  CHECK(truth.time_s.size() < swing.time_s.size() / 2);
  for (const cv::Point2d& p : truth.screen_div) {
    CHECK((p.x >= 0.0 && p.x <= 10.0 && p.y >= -4.0 && p.y <= 4.0));
  }
  CHECK(truth.time_s.front() >= 0.0);
  CHECK(truth.time_s.back() <= 5.0);
}

namespace {

// Two flat traces chopped on one beam, 1.5 divisions above and below the
// centre, over a 5 s sweep.
OscillographScene TwoFlatChoppedTraces() {
  OscillographScene scene;
  ScreenTrace upper{"right", {}, {}, testing::SweepSettings(0.5, 0.2, 1.5), BeamMode::kChopped, 0};
  ScreenTrace lower{"left", {}, {}, testing::SweepSettings(0.5, 0.2, -1.5), BeamMode::kChopped, 0};
  for (int i = 0; i <= 4000; ++i) {
    upper.time_s.push_back(5.0 * i / 4000);
    upper.volts.push_back(0.0);
  }
  lower.time_s = upper.time_s;
  lower.volts = upper.volts;
  scene.traces = {upper, lower};
  return scene;
}

}  // namespace

TEST_CASE("oscillograph: chopped traces on one beam alternate in dashes") {
  const OscillographScene scene = TwoFlatChoppedTraces();
  RenderOptions options;
  options.width_px = 1200;
  options.chop_dash_div = 0.25;
  options.chop_duty = 0.7;
  const RenderedPhoto photo = RenderOscillograph(scene, options);
  const cv::Mat1f image = BrightTraces(photo, options.style);

  const TraceTruth& a = photo.traces[0];
  const TraceTruth& b = photo.traces[1];
  REQUIRE(a.drawn.size() == b.drawn.size());
  std::size_t a_drawn = 0, b_drawn = 0, both = 0;
  double lit = 0.0, dark = 0.0;
  std::size_t lit_count = 0, dark_count = 0;
  for (std::size_t i = 0; i < a.drawn.size(); ++i) {
    a_drawn += a.drawn[i];
    b_drawn += b.drawn[i];
    both += a.drawn[i] && b.drawn[i];
    // Brightness in the middle of dashes and of gaps (a slot is 0.25 div).
    const double phase = std::fmod(a.screen_div[i].x, 0.5) / 0.25;
    if (std::abs(phase - 0.5) < 0.15) lit += Bilinear(image, a.centre_px[i]), ++lit_count;
    if (std::abs(phase - 1.5) < 0.15) dark += Bilinear(image, a.centre_px[i]), ++dark_count;
  }
  // Each trace is unblanked for 70 % of every other slot, never both at once.
  CHECK(a_drawn == Approx(0.35 * a.drawn.size()).epsilon(0.03));
  CHECK(b_drawn == Approx(0.35 * b.drawn.size()).epsilon(0.03));
  CHECK(both == 0);
  CHECK(lit / lit_count > 0.6);
  CHECK(dark / dark_count < 0.1);
}

TEST_CASE("oscillograph: a fast step writes faintly") {
  OscillographScene scene;
  ScreenTrace contact{"contact", {}, {}, testing::SweepSettings(100e-6, 1.0, -3.2)};
  for (int i = 0; i <= 1000; ++i) {
    const double t = i * 1e-6;
    contact.time_s.push_back(t);
    contact.volts.push_back(t >= 350e-6 && t < 650e-6 ? 2.0 : 0.0);  // 1 us edges
  }
  scene.traces = {contact};
  RenderOptions options;
  options.width_px = 1200;
  const RenderedPhoto photo = RenderOscillograph(scene, options);
  const cv::Mat1f image = BrightTraces(photo, options.style);
  // Off the graticule's lines: the step rises at x = 3.5 from y = -3.2 to -1.2.
  const float top = Bilinear(image, photo.ImageFromScreen({4.5, -1.2}));
  const float edge = Bilinear(image, photo.ImageFromScreen({3.5, -2.2}));
  const float screen = Bilinear(image, photo.ImageFromScreen({3.25, -2.5}));
  INFO("top " << top << ", rising edge " << edge << ", bare screen " << screen);
  CHECK(top > 0.7);
  CHECK(edge < 0.5 * top);
  CHECK(edge > screen);  // faint, not gone
}

TEST_CASE("oscillograph: same seed gives identical bytes, another seed another photo") {
  const OscillographScene scene = TwoSineScene();
  for (const PhotoStyle style : {PhotoStyle::kPolaroid, PhotoStyle::kPhone}) {
    RenderOptions options;
    options.style = style;
    options.width_px = 800;
    const cv::Mat first = RenderOscillograph(scene, options).image;
    const cv::Mat again = RenderOscillograph(scene, options).image;
    options.seed = 2;
    const cv::Mat other = RenderOscillograph(scene, options).image;
    // Rows are developed in parallel; the bytes must not depend on that.
    options.seed = 1;
    const int threads = cv::getNumThreads();
    cv::setNumThreads(1);
    const cv::Mat one_thread = RenderOscillograph(scene, options).image;
    cv::setNumThreads(threads);
    INFO(PhotoStyleName(style));
    CHECK(cv::norm(first, again, cv::NORM_INF) == 0.0);
    CHECK(cv::norm(first, one_thread, cv::NORM_INF) == 0.0);
    CHECK(cv::norm(first, other, cv::NORM_INF) > 0.0);
  }
}

TEST_CASE("oscillograph: sizes and sample types follow the options") {
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.width_px = 1000;
  RenderedPhoto photo = RenderOscillograph(scene, options);
  CHECK(photo.image.type() == CV_8UC3);
  CHECK(photo.image.size() == cv::Size(1000, 750));
  const cv::Point2d small_centre = photo.traces[0].centre_px[1000];

  options.grey = true;
  const cv::Mat grey8 = RenderOscillograph(scene, options).image;
  CHECK(grey8.type() == CV_8UC1);
  options.sixteen_bit = true;
  const cv::Mat grey16 = RenderOscillograph(scene, options).image;
  CHECK(grey16.type() == CV_16UC1);
  cv::Mat grey16_as_8;
  grey16.convertTo(grey16_as_8, CV_8U, 1.0 / 257.0);
  CHECK(cv::norm(grey16_as_8, grey8, cv::NORM_INF) <= 1.0);
  options.grey = false;
  CHECK(RenderOscillograph(scene, options).image.type() == CV_16UC3);
  options.style = PhotoStyle::kLowres;  // JPEG, then widened to 16 bits
  options.width_px = 0;
  const cv::Mat lowres = RenderOscillograph(scene, options).image;
  CHECK(lowres.type() == CV_16UC3);
  CHECK(lowres.cols == 1000);

  options = RenderOptions{};
  options.width_px = 3000;
  photo = RenderOscillograph(scene, options);
  CHECK(photo.image.size() == cv::Size(3000, 2250));
  // The clean photo scales about its centre with the width.
  CHECK(cv::norm((photo.traces[0].centre_px[1000] - cv::Point2d(1499.5, 1124.5)) / 3.0 -
                 (small_centre - cv::Point2d(499.5, 374.5))) < 1e-9);
}

TEST_CASE("oscillograph: options outside their ranges and malformed scenes are refused") {
  std::string error;
  CHECK(RenderOptions{}.Check(&error));
  RenderOptions options;
  options.rotation_deg = 20.0;
  CHECK_FALSE(options.Check(&error));
  CHECK(error.find("rotation_deg") != std::string::npos);
  CHECK_THROWS_AS(RenderOscillograph(OscillographScene{}, options), std::invalid_argument);
  options = RenderOptions{};
  options.width_px = 100;
  CHECK_FALSE(options.Check(&error));

  OscillographScene scene = TwoSineScene();
  scene.traces[0].time_s[5] = 0.0;  // time runs backwards
  CHECK_THROWS_AS(RenderOscillograph(scene, RenderOptions{}), std::invalid_argument);
  scene = TwoSineScene();
  scene.traces[1].volts.pop_back();
  CHECK_THROWS_AS(RenderOscillograph(scene, RenderOptions{}), std::invalid_argument);
}

TEST_CASE("oscillograph: style names round-trip") {
  for (const PhotoStyle style : kAllStyles) {
    CHECK(ParsePhotoStyle(PhotoStyleName(style)) == style);
  }
  CHECK(ParsePhotoStyle("randomised") == PhotoStyle::kRandomised);
  CHECK_FALSE(ParsePhotoStyle("sepia").has_value());
}

namespace {

// A drawn factor of a randomised photo: its number, or its category.
const LookFactor& Factor(const RenderedPhoto& photo, std::string_view name) {
  const auto it = std::find_if(photo.look.begin(), photo.look.end(),
                               [&](const LookFactor& f) { return f.name == name; });
  REQUIRE(it != photo.look.end());
  return *it;
}

}  // namespace

TEST_CASE("oscillograph: the randomised style draws every factor within its range, per seed") {
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.style = PhotoStyle::kRandomised;
  options.width_px = 640;  // the size is drawn too (below); small here to keep the test quick
  std::map<std::string, int> seen;
  for (std::uint64_t seed = 1; seed <= 16; ++seed) {
    options.seed = seed;
    const RenderedPhoto photo = RenderOscillograph(scene, options);
    INFO("seed " << seed);
    CHECK(Factor(photo, "width_px").value == photo.image.cols);
    CHECK(photo.image.cols == 640);
    const double quality = Factor(photo, "jpeg_quality").value;
    CHECK((quality == 0.0 || (quality >= 10.0 && quality <= 95.0)));
    CHECK(photo.jpeg_quality == quality);
    CHECK(Factor(photo, "tilt_deg").value <= 25.0);
    CHECK(Factor(photo, "blur_px").value >= 0.3);
    CHECK(Factor(photo, "blur_px").value <= 2.5);
    CHECK(Factor(photo, "bit_depth").value == (photo.image.depth() == CV_16U ? 16 : 8));
    // A JPEG is 8-bit: 16 bits are drawn only for lossless photos.
    if (quality > 0) CHECK(photo.image.depth() == CV_8U);
    // The look's own marks (up to 4) and the handling's about the traces (up to 4).
    const double trace_marks =
        Factor(photo, "marks_along_traces").value + Factor(photo, "marks_across_traces").value +
        Factor(photo, "rings_on_traces").value + Factor(photo, "arrows_at_traces").value +
        Factor(photo, "labels_by_traces").value;
    CHECK(trace_marks <= 4.0);
    CHECK(Factor(photo, "hand_marks").value <= 8.0);
    CHECK(trace_marks <= Factor(photo, "hand_marks").value);
    if (Factor(photo, "hand_marks").value > 0) {
      CHECK(Factor(photo, "mark_width_px").value >= 2.0 * 640 / 2000 - 1e-9);
      CHECK(Factor(photo, "mark_width_px").value <= 16.0 * 640 / 2000 + 1e-9);
      CHECK(Factor(photo, "mark_colour").category != "none");
    } else {
      CHECK(Factor(photo, "mark_colour").category == "none");
    }
    CHECK(Factor(photo, "tape").value <= 2.0);
    if (Factor(photo, "reproduction").category == "halftone") {
      CHECK(Factor(photo, "halftone_period_px").value >= 2.5);
      CHECK(Factor(photo, "halftone_period_px").value <= 8.0);
      CHECK(Factor(photo, "halftone_angle_deg").value >= 0.0);
      CHECK(Factor(photo, "halftone_angle_deg").value <= 90.0);
      CHECK(Factor(photo, "ink_spread").value <= 0.15);
      CHECK(Factor(photo, "paper_tone").value <= 1.0);
      CHECK(Factor(photo, "scan_blur_px").value >= 0.3);
      CHECK(Factor(photo, "scan_blur_px").value <= 1.5);
      CHECK(std::abs(Factor(photo, "scan_skew_deg").value) <= 3.0);
      CHECK(Factor(photo, "polarity").category == "negative");
      // The camera's roll and the page's skew on the scanner.
      CHECK(std::abs(Factor(photo, "rotation_deg").value) <= 13.0);
      if (quality > 0) CHECK(quality >= 50.0);
    } else {
      CHECK(Factor(photo, "reproduction").category == "photo");
      CHECK(Factor(photo, "halftone_period_px").value == 0.0);
      CHECK(Factor(photo, "scan_skew_deg").value == 0.0);
      CHECK(std::abs(Factor(photo, "rotation_deg").value) <= 10.0);
    }
    ++seen[Factor(photo, "reproduction").category];
    ++seen[Factor(photo, "polarity").category];
    ++seen[Factor(photo, "channels").category];
    ++seen[Factor(photo, "surround").category];
    ++seen[fmt::format("{}-bit", Factor(photo, "bit_depth").value)];
    // The same seed, the same bytes.
    CHECK(cv::norm(photo.image, RenderOscillograph(scene, options).image, cv::NORM_INF) == 0.0);
  }
  // Sixteen seeds show every kind at least once.
  for (const char* kind : {"positive", "negative", "grey", "colour", "hood", "panel", "print",
                           "cropped", "8-bit", "16-bit", "photo", "halftone"}) {
    INFO(kind);
    CHECK(seen[kind] > 0);
  }
  // Without an override the width is drawn in 600..6000 px.
  options.width_px = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    options.seed = seed;
    const int width = RenderOscillograph(scene, options).image.cols;
    CHECK(width >= 600);
    CHECK(width <= 6000);
  }
}

TEST_CASE("oscillograph: the randomised style's traces lie where the truth says") {
  // Scratches, hairs and hand marks may cross a trace and the photo may be a
  // JPEG of quality 10, so single measurements scatter; the median and the
  // bias still follow the truth. Tolerances about 1.5 times the worst of seeds
  // 1..8 at 1600 px. Without the handling (prints, marks beside traces): the
  // photos as the look draws them; the prints are checked below.
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.style = PhotoStyle::kRandomised;
  options.width_px = 1600;
  options.handling = false;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    options.seed = seed;
    const RenderedPhoto photo = RenderOscillograph(scene, options);
    const bool negative = Factor(photo, "polarity").category == "negative";
    const cv::Mat1f image =
        BrightTraces(photo, negative ? PhotoStyle::kNegative : PhotoStyle::kClean);
    for (const TraceTruth& truth : photo.traces) {
      const Disagreement d = MeasureTrace(image, truth, PixelsPerDivision(photo));
      INFO("seed " << seed << " trace " << truth.name << ": median " << d.median_px << " px, bias "
                   << d.mean_px << " px over " << d.count);
      REQUIRE(d.count > 40);
      CHECK(d.median_px <= kRandomisedMedianPx);
      CHECK(std::abs(d.mean_px) <= kRandomisedBiasPx);
    }
  }
}

TEST_CASE("oscillograph: the chopper's phase shifts the dashes, a beam's brightness its light") {
  OscillographScene scene = TwoFlatChoppedTraces();
  RenderOptions options;
  options.width_px = 1200;
  options.chop_dash_div = 0.25;
  options.chop_duty = 0.7;
  const RenderedPhoto unshifted = RenderOscillograph(scene, options);
  // One slot on, the traces swap their dashes; a whole period on, nothing
  // changes. (Samples exactly on a dash's end may round either way.)
  auto differ = [](const std::vector<bool>& a, const std::vector<bool>& b) {
    REQUIRE(a.size() == b.size());
    std::size_t count = 0;
    for (std::size_t i = 0; i < a.size(); ++i) count += a[i] != b[i];
    return count;
  };
  const std::size_t samples = unshifted.traces[0].drawn.size();
  options.chop_phase_div = 0.25;
  const RenderedPhoto swapped = RenderOscillograph(scene, options);
  CHECK(differ(swapped.traces[0].drawn, unshifted.traces[1].drawn) <= samples / 100);
  CHECK(differ(swapped.traces[1].drawn, unshifted.traces[0].drawn) <= samples / 100);
  CHECK(differ(swapped.traces[0].drawn, unshifted.traces[0].drawn) > samples / 2);
  options.chop_phase_div = 0.5;
  CHECK(differ(RenderOscillograph(scene, options).traces[0].drawn, unshifted.traces[0].drawn) <=
        samples / 100);

  options.chop_phase_div = 0.0;
  scene.traces[0].brightness = 0.25;
  const RenderedPhoto dim = RenderOscillograph(scene, options);
  const cv::Mat1f bright_image = BrightTraces(unshifted, PhotoStyle::kClean);
  const cv::Mat1f dim_image = BrightTraces(dim, PhotoStyle::kClean);
  double bright_sum = 0.0, dim_sum = 0.0, other_change = 0.0;
  for (std::size_t i = 0; i < unshifted.traces[0].drawn.size(); ++i) {
    if (!unshifted.traces[0].drawn[i]) continue;
    bright_sum += Bilinear(bright_image, unshifted.traces[0].centre_px[i]);
    dim_sum += Bilinear(dim_image, unshifted.traces[0].centre_px[i]);
  }
  for (std::size_t i = 0; i < unshifted.traces[1].drawn.size(); ++i) {
    other_change += std::abs(Bilinear(bright_image, unshifted.traces[1].centre_px[i]) -
                             Bilinear(dim_image, unshifted.traces[1].centre_px[i]));
  }
  CHECK(dim_sum < 0.7 * bright_sum);
  CHECK(other_change == 0.0);
  scene.traces[0].brightness = 0.0;
  CHECK_THROWS_AS(RenderOscillograph(scene, options), std::invalid_argument);
}

namespace {

// The strongest spatial frequency of `image` other than its mean: cycles per
// pixel along x and y.
cv::Point2d StrongestFrequency(const cv::Mat1f& image) {
  cv::Mat1f centred = image - cv::mean(image)[0];
  cv::Mat spectrum;
  cv::dft(centred, spectrum, cv::DFT_COMPLEX_OUTPUT);
  std::vector<cv::Mat1f> parts;
  cv::split(spectrum, parts);
  cv::Mat1f power = parts[0].mul(parts[0]) + parts[1].mul(parts[1]);
  power(0, 0) = 0.0f;
  cv::Point at;
  cv::minMaxLoc(power, nullptr, nullptr, nullptr, &at);
  const auto signed_index = [](int i, int n) { return i <= n / 2 ? i : i - n; };
  return {static_cast<double>(signed_index(at.x, image.cols)) / image.cols,
          static_cast<double>(signed_index(at.y, image.rows)) / image.rows};
}

// A polyline's distance map: each pixel's distance to the nearest point of it.
cv::Mat1f DistanceTo(const std::vector<cv::Point2d>& line, cv::Size size) {
  cv::Mat1b off(size, 255);
  std::vector<cv::Point> points;
  for (const cv::Point2d& p : line) points.emplace_back(cvRound(p.x * 16), cvRound(p.y * 16));
  cv::polylines(off, points, false, cv::Scalar(0), 1, cv::LINE_8, 4);
  cv::Mat1f distance;
  cv::distanceTransform(off, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance;
}

}  // namespace

TEST_CASE("oscillograph: a halftone screen prints each tone as dots of its area on its lattice") {
  render::PrintLook print;
  print.halftone = true;
  print.period_px = 5.3;
  print.angle_deg = 27.0;
  print.ink_spread = 0.0;
  for (const float tone : {0.1f, 0.3f, 0.5f, 0.8f}) {
    cv::Mat ink(512, 512, CV_32FC1, cv::Scalar(tone));
    render::ScreenHalftone(print, ink);
    INFO("tone " << tone);
    // Amplitude modulation: the dots' area is the tone.
    CHECK(cv::mean(ink)[0] == Approx(tone).margin(0.015));
    // Dots, not a flat tint: most pixels are all paper or all ink.
    const cv::Mat partial = (ink > 0.05f) & (ink < 0.95f);
    CHECK(cv::countNonZero(partial) < static_cast<int>(ink.total() / 2));
    // The spectrum's peak: the screen's ruling, along the screen's angle
    // (or a right angle on: the lattice is square).
    const cv::Point2d f = StrongestFrequency(ink);
    CHECK(std::hypot(f.x, f.y) == Approx(1.0 / print.period_px).margin(1.5 / 512));
    const double angle = std::fmod(std::atan2(f.y, f.x) * 180.0 / std::numbers::pi + 360.0, 90.0);
    CHECK(angle == Approx(print.angle_deg).margin(1.0));
  }
  // The ink spreads: every dot grows.
  cv::Mat thin(256, 256, CV_32FC1, cv::Scalar(0.3f));
  cv::Mat spread = thin.clone();
  render::ScreenHalftone(print, thin);
  print.ink_spread = 0.1;
  render::ScreenHalftone(print, spread);
  CHECK(cv::mean(spread)[0] > cv::mean(thin)[0] + 0.1);
  // Where there is no tone there is no dot, even with the spread.
  cv::Mat blank(64, 64, CV_32FC1, cv::Scalar(0.0f));
  render::ScreenHalftone(print, blank);
  CHECK(cv::countNonZero(blank) == 0);
}

// The mean of `image` at the graticule's lines between their crossings.
double MeanOnGridLines(const cv::Mat1f& image, const RenderedPhoto& photo) {
  double sum = 0.0;
  int count = 0;
  for (int x = 0; x <= 10; ++x) {
    for (double y = -3.75; y < 4.0; y += 0.5) {
      sum += Bilinear(image, photo.ImageFromScreen({static_cast<double>(x), y}));
      ++count;
    }
  }
  for (int y = -4; y <= 4; ++y) {
    for (double x = 0.25; x < 10.0; x += 0.5) {
      sum += Bilinear(image, photo.ImageFromScreen({x, static_cast<double>(y)}));
      ++count;
    }
  }
  return sum / count;
}

TEST_CASE("oscillograph: a randomised print is dark ink on light paper, its grid printed") {
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.style = PhotoStyle::kRandomised;
  options.width_px = 900;
  int halftones = 0;
  for (std::uint64_t seed = 1; seed <= 60 && halftones < 6; ++seed) {
    options.seed = seed;
    const RenderedPhoto photo = RenderOscillograph(scene, options);
    if (Factor(photo, "reproduction").category != "halftone") continue;
    ++halftones;
    INFO("seed " << seed << ", period " << Factor(photo, "halftone_period_px").value);
    const cv::Mat1f image = BrightTraces(photo, PhotoStyle::kClean);
    // The paper: the lightest quarter of the photo is light.
    cv::Mat1f sorted = image.reshape(1, 1).clone();
    cv::sort(sorted, sorted, cv::SORT_ASCENDING);
    const float paper = sorted(0, static_cast<int>(sorted.cols * 0.75));
    CHECK(paper > 0.6f);
    // The grid printed, as every such figure a reader could use shows it
    // (the line's dots average to less than full ink: its mean along it).
    const double grid = MeanOnGridLines(image, photo);
    INFO("grid " << grid << " on paper " << paper);
    CHECK(grid < paper - 0.1);
    // The traces: dark at the truth's centre line, darker than the grid.
    for (const TraceTruth& truth : photo.traces) {
      double sum = 0.0;
      std::size_t count = 0;
      for (std::size_t i = 0; i < truth.centre_px.size(); ++i) {
        if (!truth.drawn[i]) continue;
        sum += Bilinear(image, truth.centre_px[i]);
        ++count;
      }
      REQUIRE(count > 100);
      INFO("trace " << truth.name << ": " << sum / count);
      CHECK(sum / count < paper - 0.15);
    }
    // The same seed, the same bytes.
    CHECK(cv::norm(photo.image, RenderOscillograph(scene, options).image, cv::NORM_INF) == 0.0);
  }
  CHECK(halftones >= 3);
}

TEST_CASE("oscillograph: a randomised print's traces lie where the truth says") {
  // A printed trace is a band of dots: its profile is averaged over a period
  // either side along it; a mark beside it pulls the measured line a little.
  // Tolerances about 1.5 times the worst of the first four prints of seeds
  // 1..60 at 1600 px (seeds 3, 4, 14, 15).
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.style = PhotoStyle::kRandomised;
  options.width_px = 1600;
  int halftones = 0;
  for (std::uint64_t seed = 1; seed <= 60 && halftones < 4; ++seed) {
    options.seed = seed;
    const RenderedPhoto photo = RenderOscillograph(scene, options);
    if (Factor(photo, "reproduction").category != "halftone") continue;
    ++halftones;
    const cv::Mat1f image = BrightTraces(photo, PhotoStyle::kNegative);
    const double along_px = Factor(photo, "halftone_period_px").value;
    for (const TraceTruth& truth : photo.traces) {
      const Disagreement d = MeasureTrace(image, truth, PixelsPerDivision(photo), along_px);
      INFO("seed " << seed << " trace " << truth.name << ": median " << d.median_px << " px, bias "
                   << d.mean_px << " px over " << d.count);
      REQUIRE(d.count > 40);
      CHECK(d.median_px <= kPrintMedianPx);
      CHECK(std::abs(d.mean_px) <= kPrintBiasPx);
    }
  }
  CHECK(halftones == 4);
}

TEST_CASE("oscillograph: without the handling a randomised photo is the same but for it") {
  // The handling draws from a stream of its own: a seed's other factors, its
  // dirt and its noise do not move when it is on.
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.style = PhotoStyle::kRandomised;
  options.width_px = 800;
  int compared = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    options.seed = seed;
    options.handling = true;
    const RenderedPhoto handled = RenderOscillograph(scene, options);
    options.handling = false;
    const RenderedPhoto plain = RenderOscillograph(scene, options);
    INFO("seed " << seed);
    CHECK(Factor(plain, "reproduction").category == "photo");
    CHECK(Factor(plain, "tape").value == 0.0);
    CHECK(Factor(plain, "marks_along_traces").value == 0.0);
    if (Factor(handled, "reproduction").category == "halftone") continue;
    ++compared;
    for (const char* name : {"rotation_deg", "tilt_deg", "blur_px", "grain", "exposure_gain",
                             "dust_specks", "scratches", "hairs", "glare", "jpeg_quality"}) {
      INFO(name);
      CHECK(Factor(handled, name).value == Factor(plain, name).value);
    }
    // Only where marks and tape lie do the pixels differ (a JPEG's blocks
    // spread that a little).
    cv::Mat differs;
    cv::compare(handled.image, plain.image, differs, cv::CMP_NE);
    if (differs.channels() > 1) {
      cv::Mat any = differs.reshape(1, static_cast<int>(differs.total()));
      cv::reduce(any, differs, 1, cv::REDUCE_MAX);
    }
    const double changed = static_cast<double>(cv::countNonZero(differs)) / differs.total();
    if (Factor(handled, "hand_marks").value == 0 && Factor(handled, "tape").value == 0) {
      CHECK(changed == 0.0);
    }
    CHECK(changed < 0.35);
  }
  CHECK(compared >= 6);
}

TEST_CASE("oscillograph: marks along a trace run beside it, clear of it, and across it cross it") {
  const cv::Size size(1600, 1200);
  const double px_per_div = 150.0;
  TraceTruth trace;
  for (int i = 0; i <= 1500; ++i) {
    const double x = 50.0 + i;
    trace.centre_px.push_back({x, 600.0 + 200.0 * std::sin(x / 180.0)});
  }
  const cv::Mat1f distance = DistanceTo(trace.centre_px, size);
  render::HandlingLook handling;
  handling.mark_width_px = 10.0;  // at 2000 px: 8 px here, up to 9.6 px with the jitter
  handling.trace_marks.assign(5, render::TraceMark::kAlong);
  const double half_width_px = 0.5 * 1.2 * 10.0 * size.width / 2000.0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 random(seed);
    const cv::Mat1b mark = render::DrawTraceMarks(handling, size, {trace}, px_per_div, random);
    INFO("seed " << seed);
    double farthest = 0.0, nearest = 1e9;
    int marked = 0;
    for (int row = 0; row < size.height; ++row) {
      for (int col = 0; col < size.width; ++col) {
        if (mark(row, col) < 32) continue;
        ++marked;
        farthest = std::max(farthest, static_cast<double>(distance(row, col)));
        nearest = std::min(nearest, static_cast<double>(distance(row, col)));
      }
    }
    // Five strokes 1..4 divisions long, clear of the trace's centre line by
    // more than the beam's core, no farther than the gap allows.
    CHECK(marked > 5 * px_per_div * 8);
    CHECK(nearest >= 0.03 * px_per_div - 1.0);
    CHECK(farthest <= render::kMarkAlongTraceMaxGapDiv * px_per_div + 0.03 * px_per_div +
                          4 * half_width_px + 3.0);
  }
  // Strokes across it cross it.
  handling.trace_marks.assign(4, render::TraceMark::kAcross);
  std::mt19937_64 random(7);
  const cv::Mat1b across = render::DrawTraceMarks(handling, size, {trace}, px_per_div, random);
  int on_trace = 0;
  for (const cv::Point2d& p : trace.centre_px) on_trace += across(cvRound(p.y), cvRound(p.x)) > 128;
  CHECK(on_trace >= 4 * 4);
  // Rings, arrows and labels lie near the trace.
  handling.trace_marks = {render::TraceMark::kRing, render::TraceMark::kArrow,
                          render::TraceMark::kLabel};
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 again(seed);
    const cv::Mat1b marks = render::DrawTraceMarks(handling, size, {trace}, px_per_div, again);
    cv::Mat1f near_trace;
    cv::threshold(distance, near_trace, 2.0 * px_per_div, 1.0, cv::THRESH_BINARY_INV);
    CHECK(cv::countNonZero(marks) > 0);
    CHECK(cv::countNonZero(marks & (near_trace < 0.5)) == 0);
  }
  // Without a trace, nothing.
  std::mt19937_64 none(7);
  const cv::Mat blank = render::DrawTraceMarks(handling, size, {}, px_per_div, none);
  CHECK((blank.empty() || cv::countNonZero(blank) == 0));
}

TEST_CASE("oscillograph: randomised photos mark traces and tape corners, per seed") {
  const OscillographScene scene = TwoSineScene();
  RenderOptions options;
  options.style = PhotoStyle::kRandomised;
  options.width_px = 800;
  int along = 0, tape = 0;
  std::map<std::string, int> colours;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    options.seed = seed;
    const RenderedPhoto photo = RenderOscillograph(scene, options);
    ++colours[Factor(photo, "mark_colour").category];
    const bool marked = Factor(photo, "marks_along_traces").value > 0;
    const bool taped = Factor(photo, "tape").value > 0;
    if (!marked && !taped) continue;
    along += marked;
    tape += taped;
    INFO("seed " << seed);
    CHECK(cv::norm(photo.image, RenderOscillograph(scene, options).image, cv::NORM_INF) == 0.0);
  }
  CHECK(along >= 3);
  CHECK(tape >= 2);
  // Pencils beyond the look's own five.
  CHECK(colours["green"] + colours["orange"] > 0);
}

}  // namespace impactlab
