// Manual hints (docs/manifest.md): the graticule's corners given where the
// lattice search fails, and points a trace passes through where the tracking
// strays. Measured against the renderer's truth.
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "io/errors.h"
#include "photo_scenes.h"
#include "render/oscillograph.h"

namespace impactlab {
namespace {

// A rendered photo turned further than the lattice search looks (a camera
// held askew): the rendered image rotated about its centre by an affine map,
// and the true mapping with it.
struct TurnedPhoto {
  cv::Mat image;
  CameraMapping rendered;
  cv::Matx23d affine;

  cv::Point2d ImageFromScreen(cv::Point2d screen_div) const {
    const cv::Point2d p = rendered.ImageFromScreen(screen_div);
    return {affine(0, 0) * p.x + affine(0, 1) * p.y + affine(0, 2),
            affine(1, 0) * p.x + affine(1, 1) * p.y + affine(1, 2)};
  }
};

TurnedPhoto Turn(const RenderedPhoto& photo, double degrees) {
  TurnedPhoto turned;
  turned.rendered = photo.mapping;
  const cv::Point2f centre(0.5f * (photo.image.cols - 1), 0.5f * (photo.image.rows - 1));
  // Shrunk a little so that the whole screen stays in the frame.
  const cv::Mat m = cv::getRotationMatrix2D(centre, degrees, 0.7);
  m.convertTo(turned.affine, CV_64F);
  cv::warpAffine(photo.image, turned.image, m, photo.image.size(), cv::INTER_LINEAR,
                 cv::BORDER_REPLICATE);
  return turned;
}

// A digitized trace's centres against the true centre line, in the turned photo.
testing::TraceScore ScoreTurned(const DigitizedTrace& trace, const RenderedPhoto& rendered,
                                const TurnedPhoto& turned) {
  testing::TraceScore score;
  std::vector<cv::Point2d> truth;
  for (const TraceTruth& t : rendered.traces) {
    if (t.name != trace.name) continue;
    for (const cv::Point2d& p : t.screen_div) truth.push_back(turned.ImageFromScreen(p));
  }
  if (truth.size() < 2) return score;
  double sum2 = 0.0;
  std::size_t hint = 0;
  for (const cv::Point2d& p : trace.centre_px) {
    const double d = testing::DistanceToPolyline(truth, p, hint);
    sum2 += d * d;
    score.far_samples += d > 3.0;
    ++score.samples;
  }
  if (score.samples > 0) score.rms_px = std::sqrt(sum2 / score.samples);
  return score;
}

// The message of the InputError `f` throws (empty when none is thrown).
template <typename F>
std::string InputErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The screen's corners in the photo as a user would click them: the truth
// moved by up to `click_px` in varied directions.
template <typename Truth>
GraticuleCorners ClickedCorners(const Truth& truth, double click_px) {
  const cv::Point2d screen[4] = {{0.0, 4.0}, {10.0, 4.0}, {10.0, -4.0}, {0.0, -4.0}};
  const cv::Point2d slip[4] = {{1.0, -0.6}, {-0.8, 1.0}, {0.5, 0.9}, {-1.0, -0.7}};
  GraticuleCorners corners{};
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d p = truth.ImageFromScreen(screen[i]) + slip[i] * click_px;
    corners[i] = {p.x, p.y};
  }
  return corners;
}

}  // namespace

TEST_CASE("digitize hints: the corners hint reads a photo turned beyond the lattice search") {
  const testing::RunScene run = testing::StandardRunScene();
  RenderOptions options;
  options.style = PhotoStyle::kClean;
  options.width_px = 2000;
  options.seed = 3;
  const RenderedPhoto rendered = RenderOscillograph(run.scene, options);
  for (const double degrees : {40.0, -42.0}) {
    CAPTURE(degrees);
    const TurnedPhoto turned = Turn(rendered, degrees);
    const PreparedPhoto prepared = PreparePhoto({turned.image, "turned.png"}, {});

    // The search looks up to 20 degrees: not found, and the message names the hint.
    const std::string message = InputErrorOf([&] {
      FindGraticule(prepared, {10, 8}, GraticuleOptions{});
    });
    CHECK_THAT(message, Catch::Contains("graticule of 10 x 8 divisions not found"));
    CHECK_THAT(message, Catch::Contains("graticule_corners = [[x, y] x 4]"));

    // With the corners clicked to within 1.5 px, the fit finds the true
    // mapping to within a pixel everywhere on the screen.
    GraticuleOptions hinted;
    hinted.corners_px = ClickedCorners(turned, 1.5);
    const GraticuleFit fit = FindGraticule(prepared, {10, 8}, hinted);
    CHECK(fit.from_corners_hint);
    CHECK(testing::WorstMappingError(fit, turned) < /*max_mapping_error_px=*/0.25);
    CHECK(fit.residual_px < 0.5);

    // And the traces are read from it: the whole photo with the hint.
    DigitizeOptions all;
    all.graticule = hinted;
    const DigitizeResult result =
        DigitizePhoto({turned.image, "turned.png"}, {10, 8}, run.requests, all);
    REQUIRE(result.traces.size() == 3);
    for (std::size_t k = 0; k < 2; ++k) {  // right, left: against the true centre lines
      const DigitizedTrace& trace = result.traces[k];
      const testing::TraceScore score = ScoreTurned(trace, rendered, turned);
      CAPTURE(trace.name, score.rms_px, score.far_samples, score.samples);
      CHECK(score.samples > 300);
      CHECK(score.rms_px < 0.5);
      CHECK(score.far_samples <= score.samples / 50);
    }
    CHECK(HintsUsed(result) == "graticule_corners");
  }
}

TEST_CASE("digitize hints: a corner outside the photo is refused naming the key") {
  const RenderedPhoto rendered = RenderOscillograph(testing::StandardRunScene().scene, {});
  const PreparedPhoto prepared = PreparePhoto({rendered.image, "p.png"}, {});
  GraticuleOptions hinted;
  hinted.corners_px = ClickedCorners(rendered, 0.0);
  (*hinted.corners_px)[2] = {rendered.image.cols + 10.0, 100.0};
  const std::string message = InputErrorOf([&] { FindGraticule(prepared, {10, 8}, hinted); });
  CHECK_THAT(message, Catch::Contains("graticule_corners[2]"));
  CHECK_THAT(message, Catch::Contains("outside the photo"));
}

}  // namespace impactlab
