// Manual hints (docs/manifest.md): the graticule's corners given where the
// lattice search fails, and points a trace passes through where the tracking
// strays. Measured against the renderer's truth.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "io/errors.h"
#include "photo_scenes.h"
#include "render/oscillograph.h"
#include "tests/support/input_error.h"

namespace impactlab {
namespace {

// Where the scratch leaves the left trace, and how long it runs, divisions.
constexpr double kScratchFromDiv = 3.0;
constexpr double kScratchLengthDiv = 3.0;

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

using testing::InputErrorOf;

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

// The true centre line's screen point of trace `name` nearest screen x.
cv::Point2d TruthAt(const RenderedPhoto& photo, const std::string& name, double x_div) {
  for (const TraceTruth& t : photo.traces) {
    if (t.name != name) continue;
    cv::Point2d best(1e9, 1e9);
    for (const cv::Point2d& p : t.screen_div) {
      if (std::abs(p.x - x_div) < std::abs(best.x - x_div)) best = p;
    }
    return best;
  }
  return {};
}

// A scratch as wide as the trace and brighter, from screen `from` to `to`.
void BrightScratch(cv::Mat& image, const RenderedPhoto& photo, cv::Point2d from_div,
                   cv::Point2d to_div, int width_px) {
  const cv::Point2d a = photo.ImageFromScreen(from_div), b = photo.ImageFromScreen(to_div);
  const double full = image.depth() == CV_16U ? 65535.0 : 255.0;
  cv::line(image, cv::Point(cvRound(a.x * 16), cvRound(a.y * 16)),
           cv::Point(cvRound(b.x * 16), cvRound(b.y * 16)), cv::Scalar::all(full), width_px,
           cv::LINE_AA, 4);
}

}  // namespace

TEST_CASE("digitize hints: the corners hint reads a photo turned beyond the lattice search") {
  const testing::RunScene run = testing::StandardRunScene();
  const RenderedPhoto rendered = RenderOscillograph(run.scene, testing::CleanOptions(2000, 3));
  for (const double degrees : {40.0, -42.0}) {
    CAPTURE(degrees);
    const TurnedPhoto turned = Turn(rendered, degrees);
    const PreparedPhoto prepared = PreparePhoto({turned.image, "turned.png"}, {});

    // The search looks up to 20 degrees: not found, and the message names
    // the hint. Its Hough lines reach 35 degrees beyond, and since the two
    // families' directions are taken together above the noise floor it
    // finds these turned photos now: then it must have found them right.
    std::optional<GraticuleFit> searched;
    const std::string message = InputErrorOf([&] {
      searched = FindGraticule(prepared, {10, 8}, GraticuleOptions{});
    });
    if (searched) {
      CHECK(testing::WorstMappingError(*searched, turned) < /*max_mapping_error_px=*/0.25);
    } else {
      CHECK_THAT(message, Catch::Contains("graticule of 10 x 8 divisions not found"));
      CHECK_THAT(message, Catch::Contains("graticule_corners = [[x, y] x 4]"));
    }

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

TEST_CASE("digitize hints: points on a trace keep its tracking off a bright scratch along it") {
  // Unchopped traces: a chopped trace's course tells a continuous line from
  // its dashes (digitize/trace_track.cpp), a continuous trace's cannot.
  testing::RunScene run = testing::StandardRunScene();
  for (ScreenTrace& trace : run.scene.traces) trace.mode = BeamMode::kContinuous;
  RenderedPhoto photo = RenderOscillograph(run.scene, testing::CleanOptions(2000, 5));
  // A scratch leaving the left trace where it falls towards an impact and
  // running on straight, brighter than the trace: the tracking takes the
  // brighter, straighter line.
  const cv::Point2d start = TruthAt(photo, "left", kScratchFromDiv);
  const cv::Point2d next = TruthAt(photo, "left", kScratchFromDiv + 0.1);
  const cv::Point2d direction = (next - start) * (1.0 / cv::norm(next - start));
  BrightScratch(photo.image, photo, start, start + direction * kScratchLengthDiv, 5);

  const std::size_t left = 1;
  const auto far_samples = [&](const DigitizeResult& result) {
    const testing::TraceScore score =
        testing::ScoreTrace(result.traces[left], photo, run.scene.traces[left], {10, 8});
    return score;
  };
  DigitizeOptions no_marks;
  no_marks.traces.hand_marks = false;
  const DigitizeResult lost =
      DigitizePhoto({photo.image, "scratched.png"}, {10, 8}, run.requests, no_marks);
  const testing::TraceScore before = far_samples(lost);
  CAPTURE(before.far_samples, before.samples, before.rms_px);
  // The tracking follows the scratch without the hint, where nothing else
  // keeps it off: a scratch this wide is a hand mark to the mark search
  // (marks_and_prints_test.cpp), which is off here.
  REQUIRE(before.far_samples > 20);

  // Points on the trace every 0.3 division along the scratch, clicked to a
  // pixel: close enough to fence the tracking in between.
  std::vector<TraceRequest> requests = run.requests;
  for (double x = kScratchFromDiv + 0.3; x < kScratchFromDiv + kScratchLengthDiv + 0.2; x += 0.3) {
    const cv::Point2d p = photo.ImageFromScreen(TruthAt(photo, "left", x)) + cv::Point2d(0.7, -0.7);
    requests[left].settings.points_px.push_back({p.x, p.y});
  }
  const DigitizeResult hinted =
      DigitizePhoto({photo.image, "scratched.png"}, {10, 8}, requests, no_marks);
  const testing::TraceScore after = far_samples(hinted);
  CAPTURE(after.far_samples, after.samples, after.rms_px, after.coverage);
  CHECK(hinted.traces[left].from_points_hint);
  CHECK(HintsUsed(hinted) == "left.points");
  CHECK(after.far_samples <= after.samples / 100);
  CHECK(after.rms_px < 0.3);
  CHECK(after.coverage > 0.7);  // the chopper draws 75 % of the sweep
}

TEST_CASE(
    "digitize hints: a trace not found names the points hint; a point off its band is refused") {
  const testing::RunScene run = testing::StandardRunScene();
  const RenderedPhoto photo = RenderOscillograph(run.scene, {});
  // The left trace looked for where nothing is drawn.
  std::vector<TraceRequest> requests = {run.requests[1]};
  requests[0].settings.band_div = {3.0, 3.9};
  requests[0].settings.zero_div = 3.5;
  std::string message = DigitizePhoto({photo.image, "p.png"}, {10, 8}, requests, {}).Failure();
  CHECK_THAT(message, Catch::Contains("trace 'left' not found"));
  CHECK_THAT(message, Catch::Contains("points = [[x, y], ...]"));

  // A hinted point outside the band: a slip, named by its key.
  requests = {run.requests[1]};
  const cv::Point2d off = photo.ImageFromScreen({5.0, 2.0});
  const cv::Point2d on = photo.ImageFromScreen(TruthAt(photo, "left", 5.0));
  requests[0].settings.points_px = {{on.x, on.y}, {off.x, off.y}};
  message = DigitizePhoto({photo.image, "p.png"}, {10, 8}, requests, {}).Failure();
  CHECK_THAT(message, Catch::Contains("traces.left.points[1]"));
  CHECK_THAT(message, Catch::Contains("outside its band [-2.4, 0] div"));
}

}  // namespace impactlab
