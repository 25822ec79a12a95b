// The digitizer against the renderer's truth, in every photo style: the
// graticule's mapping, each trace's centre line (pixels and % of full scale),
// the contact pulse's width, and that no sample lies off the true trace.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "render/oscillograph.h"
#include "tests/digitize/photo_scenes.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

using testing::ScoreTrace;
using testing::StandardRunScene;
using testing::TraceScore;
using testing::WorstMappingError;

// Per style, about 1.5 times the worst seen over seeds 1..5 at these widths
// (bench/digitize_bench.cpp measures them; docs/digitizing.md has the table).
struct Tolerance {
  int width_px;          // the photo (lowres at its own 1000 px)
  double mapping_px;     // worst |fitted - true| image position of a graticule point
  double centre_rms_px;  // a trace's centre line against the truth
  double pulse_percent;  // contact pulse width error
};

const std::map<PhotoStyle, Tolerance> kTolerance = {
    {PhotoStyle::kClean, {1600, 0.05, 0.15, 0.5}}, {PhotoStyle::kPolaroid, {1600, 0.15, 0.35, 0.5}},
    {PhotoStyle::kPhone, {1600, 0.15, 0.3, 0.5}},  {PhotoStyle::kNegative, {1600, 0.15, 0.35, 0.5}},
    {PhotoStyle::kLowres, {1000, 0.45, 0.5, 1.0}},
};

}  // namespace

TEST_CASE("digitize: every style gives the true traces, graticule and contact pulse") {
  cv::setNumThreads(1);
  const testing::RunScene run = StandardRunScene();
  for (const auto& [style, tolerance] : kTolerance) {
    RenderOptions options;
    options.style = style;
    options.seed = 3;
    options.width_px = tolerance.width_px;
    const RenderedPhoto photo = RenderOscillograph(run.scene, options);
    const DigitizeResult result =
        DigitizePhoto({photo.image, "synthetic.png"}, {10, 8}, run.requests, DigitizeOptions{});
    INFO(PhotoStyleName(style));

    CHECK(result.graticule.residual_px < 0.5);
    CHECK(WorstMappingError(result.graticule, photo) < tolerance.mapping_px);
    // Barrel distortion is fitted where the photo has much of it (phone), and
    // where it is fitted it is the photo's; a photo without any gets none.
    const double true_k1 = photo.mapping.radial_k1;
    if (std::abs(true_k1) > 0.03) CHECK(result.graticule.radial_fitted);
    if (true_k1 == 0.0) CHECK_FALSE(result.graticule.radial_fitted);
    if (result.graticule.radial_fitted) {
      CHECK(result.graticule.mapping.radial_k1 == Approx(true_k1).margin(0.01));
    }

    REQUIRE(result.traces.size() == run.requests.size());
    for (std::size_t t = 0; t < result.traces.size(); ++t) {
      const DigitizedTrace& trace = result.traces[t];
      const TraceScore score = ScoreTrace(trace, photo, run.scene.traces[t], {10, 8});
      INFO(trace.name << ": rms " << score.rms_px << " px (" << score.rms_percent_fs
                      << " % FS), max " << score.max_px << " px over " << score.samples
                      << ", coverage " << score.coverage);
      CHECK(trace.name == run.requests[t].name);
      CHECK(score.rms_px < tolerance.centre_rms_px);
      CHECK(score.far_samples == 0);  // nothing made up
      CHECK(score.coverage > 0.7);    // most of what was drawn is found
      // Samples come with increasing time, an uncertainty and a confidence.
      REQUIRE(trace.trace.time_s.size() == trace.trace.volts.size());
      REQUIRE(trace.trace.sigma_volts.size() == trace.trace.volts.size());
      REQUIRE(trace.confidence.size() == trace.trace.volts.size());
      for (std::size_t i = 1; i < trace.trace.time_s.size(); ++i) {
        REQUIRE(trace.trace.time_s[i] > trace.trace.time_s[i - 1]);
      }
      for (std::size_t i = 0; i < trace.confidence.size(); ++i) {
        REQUIRE((trace.confidence[i] > 0.0 && trace.confidence[i] <= 1.0));
        REQUIRE(trace.trace.sigma_volts[i] > 0.0);
      }
    }
    // The contact trace (the only one with `impact`) has its pulse measured.
    REQUIRE(result.pulses.size() == 3);
    CHECK(!result.pulses[0]);
    CHECK(!result.pulses[1]);
    REQUIRE(result.pulses[2]);
    const ContactPulseFit& pulse = *result.pulses[2];
    const double truth = testing::kPulseFallS - testing::kPulseRiseS;
    INFO("pulse " << pulse.pulse.width_s.value * 1e6 << " +- " << pulse.pulse.width_s.sigma * 1e6
                  << " us");
    CHECK(std::abs(pulse.pulse.width_s.value - truth) < tolerance.pulse_percent / 100.0 * truth);
    CHECK(pulse.pulse.width_s.sigma > 0.0);
    CHECK(pulse.pulse.rise_s.value == Approx(testing::kPulseRiseS).margin(0.01 * truth));
    CHECK(pulse.pulse.low_volts == Approx(0.0).margin(0.05));
    CHECK(pulse.pulse.high_volts == Approx(1.0).margin(0.05));
  }
}

// The mean signed error (photo pixels, up the screen) of a trace's samples
// within `window_s` of the source's smooth maxima.
double MeanErrorAtMaxima(const DigitizedTrace& trace, const ScreenTrace& source, double px_per_div,
                         double window_s) {
  std::vector<double> peaks;
  for (std::size_t k = 1; k + 1 < source.volts.size(); ++k) {
    if (source.volts[k] > source.volts[k - 1] && source.volts[k] >= source.volts[k + 1])
      peaks.push_back(source.time_s[k]);
  }
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < trace.trace.time_s.size(); ++i) {
    const double t = trace.trace.time_s[i];
    const bool near = std::any_of(peaks.begin(), peaks.end(),
                                  [&](double peak) { return std::abs(t - peak) < window_s; });
    const auto it = std::lower_bound(source.time_s.begin(), source.time_s.end(), t);
    if (!near || it == source.time_s.begin() || it == source.time_s.end()) continue;
    const std::size_t k = static_cast<std::size_t>(it - source.time_s.begin());
    const double f = (t - source.time_s[k - 1]) / (source.time_s[k] - source.time_s[k - 1]);
    const double truth = source.volts[k - 1] + f * (source.volts[k] - source.volts[k - 1]);
    sum += (trace.trace.volts[i] - truth) / trace.settings.volts_per_div * px_per_div;
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

TEST_CASE("digitize: a slow sweep's maxima are not pulled inside their curve by the blur") {
  // At 1000 px the right trace's maxima curve with a radius of about 8 px:
  // a blur of 1.5 px pulls their centre 0.3 px inside (more than the first
  // order's s^2 kappa / 2 = 0.2 px), and undoing that pull leaves 0.17 px.
  cv::setNumThreads(1);
  const testing::RunScene run = StandardRunScene();
  RenderOptions options;
  options.style = PhotoStyle::kLowres;
  options.seed = 3;
  options.blur_px = 1.5;
  const RenderedPhoto photo = RenderOscillograph(run.scene, options);
  const DigitizeResult result =
      DigitizePhoto({photo.image, "synthetic.png"}, {10, 8}, run.requests, DigitizeOptions{});
  REQUIRE(result.traces.size() == 3);
  const DigitizedTrace& right = result.traces[0];
  const double error_px =
      MeanErrorAtMaxima(right, run.scene.traces[0], result.graticule.px_per_div, 0.05);
  INFO("spread " << right.spread_px2 << " px^2, mean error at the maxima " << error_px << " px");
  // The blur's own 2.25 px^2 and the beam's; the tone hides most of it from the width.
  CHECK(right.spread_px2 > 1.5);
  CHECK(right.spread_px2 < 3.5);
  CHECK(error_px > -0.2);
  CHECK(error_px < 0.05);
}

TEST_CASE("digitize: grey and 16-bit photos give the same traces as 8-bit colour") {
  const testing::RunScene run = StandardRunScene();
  RenderOptions options;
  options.width_px = 1200;
  const RenderedPhoto colour = RenderOscillograph(run.scene, options);
  options.grey = true;
  options.sixteen_bit = true;
  const RenderedPhoto grey16 = RenderOscillograph(run.scene, options);
  REQUIRE(grey16.image.type() == CV_16UC1);
  const DigitizeResult a = DigitizePhoto({colour.image, "c.png"}, {10, 8}, run.requests, {});
  const DigitizeResult b = DigitizePhoto({grey16.image, "g.png"}, {10, 8}, run.requests, {});
  for (std::size_t t = 0; t < run.requests.size(); ++t) {
    const TraceScore sa = ScoreTrace(a.traces[t], colour, run.scene.traces[t], {10, 8});
    const TraceScore sb = ScoreTrace(b.traces[t], grey16, run.scene.traces[t], {10, 8});
    INFO(run.requests[t].name << ": colour " << sa.rms_px << " px, grey16 " << sb.rms_px << " px");
    CHECK(sb.rms_px < 0.2);
    CHECK(std::abs(sa.rms_px - sb.rms_px) < 0.05);
  }
}

TEST_CASE("digitize: a colour JPEG is decoded to its luma, the grey the digitizer reads") {
  const testing::TempDir dir;
  RenderOptions options;
  options.width_px = 800;
  const cv::Mat colour = RenderOscillograph(StandardRunScene().scene, options).image;
  REQUIRE(colour.type() == CV_8UC3);
  std::vector<uchar> jpeg;
  cv::imencode(".jpg", colour, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
  const auto path = dir.path() / "photo.jpg";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size()));

  const Photo photo = LoadPhoto(path);
  REQUIRE(photo.image.type() == CV_8UC1);
  // The same luma as the colour decode's BT.601 grey, but for rounding in the
  // colour round trip.
  cv::Mat grey;
  cv::cvtColor(cv::imdecode(jpeg, cv::IMREAD_COLOR), grey, cv::COLOR_BGR2GRAY);
  cv::Mat difference;
  cv::absdiff(photo.image, grey, difference);
  double largest = 0.0;
  cv::minMaxLoc(difference, nullptr, &largest);
  CHECK(largest <= 3.0);
  CHECK(cv::mean(difference)[0] < 0.6);
}

TEST_CASE("digitize: a negative is recognised and read as such") {
  const testing::RunScene run = StandardRunScene();
  RenderOptions options;
  options.style = PhotoStyle::kNegative;
  options.width_px = 1000;
  const RenderedPhoto photo = RenderOscillograph(run.scene, options);
  const PreparedPhoto prepared = PreparePhoto({photo.image, "n.png"}, {});
  CHECK(prepared.dark_traces);
  GraticuleOptions forced;
  forced.polarity = Polarity::kBrightTraces;  // told wrong: the grid is dark, not found
  CHECK_THROWS(FindGraticule(PreparePhoto({photo.image, "n.png"}, forced), {10, 8}, forced));
  CHECK_FALSE(PreparePhoto({RenderOscillograph(run.scene, RenderOptions{}).image, "c.png"}, {})
                  .dark_traces);
}

TEST_CASE("digitize: the mapping's inverse undoes it") {
  GraticuleMapping mapping;
  mapping.homography = cv::Matx33d(150.0, 8.0, 200.0, -6.0, -148.0, 700.0, 1e-3, 2e-4, 1.0);
  mapping.radial_k1 = -0.06;
  mapping.distortion_centre_px = {999.5, 749.5};
  mapping.distortion_radius_px = 1250.0;
  for (double x = 0.0; x <= 10.0; x += 2.5) {
    for (double y = -4.0; y <= 4.0; y += 2.0) {
      const cv::Point2d back = mapping.ScreenFromImage(mapping.ImageFromScreen({x, y}));
      CHECK(cv::norm(back - cv::Point2d(x, y)) < 1e-9);
    }
  }
  CHECK(mapping.PixelsPerDivisionAt({5.0, 0.0}) > 100.0);
}

// The standard run scene as a grey 1000 px photo, digitized.
struct DigitizedScene {
  RenderedPhoto photo;
  Photo input;
  DigitizeResult result;
};

DigitizedScene DigitizeGreyScene() {
  const testing::RunScene run = StandardRunScene();
  RenderOptions options;
  options.width_px = 1000;
  options.grey = true;
  DigitizedScene out{RenderOscillograph(run.scene, options), {}, {}};
  out.input = Photo{out.photo.image, "p.png"};
  out.result = DigitizePhoto(out.input, {10, 8}, run.requests, {});
  return out;
}

TEST_CASE("digitize: the overlay is the photo with the findings drawn on it") {
  const auto [photo, input, result] = DigitizeGreyScene();
  const cv::Mat overlay = DrawOverlay(input, result);
  CHECK(overlay.type() == CV_8UC3);
  CHECK(overlay.size() == photo.image.size());
  cv::Mat grey;
  cv::cvtColor(overlay, grey, cv::COLOR_BGR2GRAY);
  CHECK(cv::countNonZero(grey != photo.image) > 1000);  // lines, labels, insets
}

TEST_CASE("digitize: the overlay's status lines sit on a dark panel, in light text") {
  const auto [photo, input, result] = DigitizeGreyScene();
  // The photo's top left a print's light border, where coloured text alone
  // could not be read.
  const cv::Rect band(0, 0, std::min(300, photo.image.cols), std::min(24, photo.image.rows));
  Photo light = input;
  light.image = input.image.clone();
  light.image(band).setTo(220);
  const cv::Mat overlay = DrawOverlay(light, result);
  cv::Mat grey;
  cv::cvtColor(overlay, grey, cv::COLOR_BGR2GRAY);
  // The first status line's band: darkened to a fifth, with light letters on it.
  const cv::Mat region = grey(band), original = light.image(band);
  CHECK(cv::mean(region)[0] < 0.5 * cv::mean(original)[0] + 20.0);
  CHECK(cv::countNonZero(region > 150) > 100);
  // Dark where there are no letters: the panel covers the band.
  cv::Mat sorted;
  cv::sort(region.clone().reshape(1, 1), sorted, cv::SORT_ASCENDING);
  CHECK(sorted.at<unsigned char>(0, sorted.cols / 2) < 0.35 * cv::mean(original)[0] + 10.0);
}

TEST_CASE(
    "digitize: an overlay drawn smaller shrinks by a whole factor and keeps the trace's place") {
  const auto [photo, input, result] = DigitizeGreyScene();
  const int factor = 3;
  const int max_width = photo.image.cols / factor + 1;  // 2 is too little, 3 fits
  const cv::Mat overlay = DrawOverlay(input, result, {.max_width_px = max_width});
  REQUIRE(overlay.type() == CV_8UC3);
  CHECK(overlay.cols == photo.image.cols / factor);
  CHECK(overlay.rows == photo.image.rows / factor);

  // The first trace's centre line is drawn red (BGR 60, 60, 255, dimmed by
  // confidence) on a grey photo: nothing else there is that red.
  std::vector<cv::Mat1b> bgr;
  cv::split(overlay, bgr);
  cv::Mat1b red = (bgr[2] > bgr[1] + 80) & (bgr[2] > bgr[0] + 80);
  CHECK(cv::countNonZero(red) < 0.02 * overlay.total());
  cv::Mat1f distance;
  cv::distanceTransform(~red, distance, cv::DIST_L2, 3);
  const double scale = 1.0 / factor;
  const DigitizedTrace& trace = result.traces[0];
  std::vector<float> distances;
  for (std::size_t i = 0; i < trace.centre_px.size(); ++i) {
    if (trace.screen_div[i].x < 1.0 || trace.screen_div[i].x > 9.0) continue;  // clear of labels
    // Pixel centres at whole coordinates in both images.
    const cv::Point2d at =
        (trace.centre_px[i] + cv::Point2d(0.5, 0.5)) * scale - cv::Point2d(0.5, 0.5);
    distances.push_back(distance(cv::Point(at)));
  }
  REQUIRE(distances.size() > 100);
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  CHECK(distances[distances.size() / 2] < 1.0);

  CHECK(DrawOverlay(input, result, {.max_width_px = 5000}).size() == photo.image.size());
  CHECK_THROWS_AS(DrawOverlay(input, result, {.max_width_px = -1}), std::invalid_argument);
}

TEST_CASE("digitize: options outside their ranges are refused before any work") {
  std::string error;
  CHECK(GraticuleOptions{}.Check(&error));
  CHECK(TraceOptions{}.Check(&error));
  CHECK(DigitizeOptions{}.Check(&error));
  DigitizeOptions options;
  options.traces.samples_per_px = 0.0;
  CHECK_FALSE(options.Check(&error));
  CHECK(error.find("samples_per_px") != std::string::npos);
  options = {};
  options.graticule.detect_width_px = 50;
  CHECK_FALSE(options.Check(&error));
  CHECK(error.find("detect_width_px") != std::string::npos);
  options = {};
  options.traces.centroid_level = 1.5;
  CHECK_THROWS_AS(
      DigitizePhoto({cv::Mat(300, 400, CV_8UC1, cv::Scalar(0)), "x.png"}, {10, 8}, {}, options),
      std::invalid_argument);
}

}  // namespace impactlab
