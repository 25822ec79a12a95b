// Photos as archives keep them: prints marked by hand (a pencil stroke across
// a trace, a ring, a written label) and figures reproduced in print through a
// halftone screen. The traces must be read against the renderer's truth, the
// marks kept from them and said where, and a plain photo found to have
// neither.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "digitize/halftone.h"
#include "digitize/hand_marks.h"
#include "photo_scenes.h"
#include "render/oscillograph.h"

namespace impactlab {
namespace {

RenderedPhoto RunPhoto(const testing::RunScene& run, unsigned seed) {
  return RenderOscillograph(run.scene, testing::CleanOptions(2000, seed, true));
}

// Samples further than 3 px from the trace's true centre line.
std::size_t FarOffTruth(const DigitizedTrace& trace, const RenderedPhoto& photo) {
  const auto truth = std::find_if(photo.traces.begin(), photo.traces.end(),
                                  [&](const TraceTruth& t) { return t.name == trace.name; });
  REQUIRE(truth != photo.traces.end());
  std::size_t hint = 0, far = 0;
  for (const cv::Point2d& p : trace.centre_px) {
    if (testing::DistanceToPolyline(truth->centre_px, p, hint) > 3.0) ++far;
  }
  return far;
}

// The standard run scene drawn on a clean grey photo with its beam chopped
// into dashes `dash_div` long, unblanked over `duty` of each.
RenderedPhoto ChoppedRunPhoto(double dash_div, double duty) {
  RenderOptions options = testing::CleanOptions(2000, 5, true);
  options.chop_dash_div = dash_div;
  options.chop_duty = duty;
  return RenderOscillograph(testing::StandardRunScene().scene, options);
}

cv::Point Pixel(const RenderedPhoto& photo, cv::Point2d screen_div) {
  const cv::Point2d p = photo.ImageFromScreen(screen_div);
  return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))};
}

}  // namespace

TEST_CASE("digitize marks: pencil strokes across a trace and written labels are kept from it") {
  const testing::RunScene run = testing::StandardRunScene();
  const RenderedPhoto clean = RunPhoto(run, 3);
  const DigitizeResult plain = DigitizePhoto({clean.image, "plain.png"}, {10, 8}, run.requests, {});
  // On a clean photo nothing is taken for a mark.
  CHECK(plain.mark_outlines_px.empty());

  // A grease-pencil stroke four times a trace's width across the right
  // trace's first rebounds, a ring, and a label in the left trace's band,
  // as bright as the traces.
  RenderedPhoto marked = clean;
  marked.image = clean.image.clone();
  const cv::Scalar pencil(235);
  cv::line(marked.image, Pixel(clean, {1.2, 3.6}), Pixel(clean, {2.4, 0.4}), pencil, 14,
           cv::LINE_AA);
  cv::ellipse(marked.image, Pixel(clean, {7.0, 1.8}), {90, 60}, 0.0, 0.0, 330.0, pencil, 10,
              cv::LINE_AA);
  cv::putText(marked.image, "X0=.405", Pixel(clean, {5.5, -0.6}), cv::FONT_HERSHEY_SIMPLEX, 2.5,
              pencil, 9, cv::LINE_AA);
  const DigitizeResult result =
      DigitizePhoto({marked.image, "marked.png"}, {10, 8}, run.requests, {});
  CHECK(result.mark_outlines_px.size() >= 3);
  for (std::size_t k = 0; k < 2; ++k) {  // right, left
    const DigitizedTrace& trace = result.traces[k];
    INFO(trace.name << ": " << trace.centre_px.size() << " samples, " << FarOffTruth(trace, marked)
                    << " more than 3 px off the truth");
    CHECK(trace.centre_px.size() > 0.8 * plain.traces[k].centre_px.size());
    CHECK(FarOffTruth(trace, marked) <= trace.centre_px.size() / 100);
  }
  // The stroke crosses the right trace between 1.2 and 2.4 div: its samples
  // there were dropped, and the results say so.
  const DigitizedTrace& right = result.traces[0];
  REQUIRE(!right.mark_stretches_div.empty());
  const bool crossing_said =
      std::any_of(right.mark_stretches_div.begin(), right.mark_stretches_div.end(),
                  [](const std::array<double, 2>& s) { return s[1] > 1.1 && s[0] < 2.5; });
  CHECK(crossing_said);
}

TEST_CASE("digitize marks: what a chopped trace's first reading followed unbroken may be a mark") {
  // Sparse dashes (0.13 division slots, drawn 40 % of each, as on the
  // external annotated-e903) and a pencil arc over the left trace's peak,
  // four times the beam's width. A first reading that took the arc over
  // more than a division unbroken (and so measured its width) did not
  // follow the beam, which draws no unbroken run: the arc is no course of
  // the trace's to keep from the marks (annotated-e903's run 0.314 had kept
  // a ring's arc so, and failed). Had the beam drawn continuously, an
  // unbroken run would be its own course, however thick.
  RenderedPhoto photo = ChoppedRunPhoto(0.13, 0.4);
  const TraceTruth& truth = photo.traces[1];
  REQUIRE(truth.name == "left");
  cv::Point2d peak(0.0, -10.0);
  for (const cv::Point2d& p : truth.screen_div) {
    if (p.x > 4.0 && p.x < 6.0 && p.y > peak.y) peak = p;
  }
  // The arc: the top of an ellipse round the peak, 0.9 x 0.45 division.
  constexpr double kRadiusX = 0.9, kRadiusY = 0.45, kStrokeDiv = 0.08, kHalfSpan = 0.75;
  const double px_per_div = cv::norm(photo.ImageFromScreen({1.0, 0.0}) - photo.ImageFromScreen({}));
  const double half_angle = std::acos(kHalfSpan / kRadiusX) * 180.0 / std::numbers::pi;
  cv::ellipse(photo.image, Pixel(photo, peak),
              {static_cast<int>(kRadiusX * px_per_div), static_cast<int>(kRadiusY * px_per_div)},
              0.0, 180.0 + half_angle, 360.0 - half_angle, cv::Scalar(235),
              static_cast<int>(kStrokeDiv * px_per_div), cv::LINE_AA);
  const PreparedPhoto prepared = PreparePhoto({photo.image, "arc.png"}, {});
  const GraticuleFit graticule = FindGraticule(prepared, {10, 8}, {});

  // The first readings: the trace's samples (its dashes only, or all of
  // them), but along the arc, sampled every 0.01 division, and as wide.
  const auto reading = [&](bool dashes) {
    DigitizedTrace left;
    left.name = "left";
    left.width_px = kStrokeDiv * px_per_div;
    left.height = 0.8;
    const auto add = [&](cv::Point2d screen) {
      left.screen_div.push_back(screen);
      left.centre_px.push_back(photo.ImageFromScreen(screen));
    };
    bool arc_added = false;
    double last_x = -1.0;
    for (std::size_t i = 0; i < truth.screen_div.size(); ++i) {
      const cv::Point2d p = truth.screen_div[i];
      if (std::abs(p.x - peak.x) <= kHalfSpan) {
        for (double x = peak.x - kHalfSpan; !arc_added && x <= peak.x + kHalfSpan; x += 0.01) {
          const double u = (x - peak.x) / kRadiusX;
          add({x, peak.y + kRadiusY * std::sqrt(1.0 - u * u)});
        }
        arc_added = true;
        last_x = peak.x + kHalfSpan;
        continue;
      }
      if (p.x - last_x < 0.01 || (dashes && !truth.drawn[i])) continue;
      add(p);
      last_x = p.x;
    }
    return left;
  };
  const cv::Point2d top = photo.ImageFromScreen({peak.x, peak.y + kRadiusY});
  const DigitizedTrace chopped = reading(true), continuous = reading(false);
  REQUIRE(digitize::ReadInDashes(chopped));
  REQUIRE_FALSE(digitize::ReadInDashes(continuous));
  CHECK(
      digitize::FindHandMarks(prepared, graticule, 0.02 * px_per_div, 0.8, {chopped}).Covers(top));
  CHECK_FALSE(digitize::FindHandMarks(prepared, graticule, 0.02 * px_per_div, 0.8, {continuous})
                  .Covers(top));
}

TEST_CASE("digitize marks: a chopped trace's dash glowing wide at a peak is the trace's own") {
  // Sparse dashes, and the one at the left trace's peak drawn as wide as a
  // pencil stroke: where the beam is slow it glows wider than on the flanks
  // (randomised seed 1018's run 0.713 lost a rebound's peak so, its dash
  // taken for a mark). The first reading measured that dash among the
  // others, each as long as the chopper's slot allows: it is the beam's
  // course, however thick, and no mark is found on it.
  RenderedPhoto photo = ChoppedRunPhoto(0.2, 0.5);
  const TraceTruth& truth = photo.traces[1];
  REQUIRE(truth.name == "left");
  std::size_t peak = 0;
  double highest = -10.0;
  for (std::size_t i = 0; i < truth.screen_div.size(); ++i) {
    const cv::Point2d p = truth.screen_div[i];
    if (truth.drawn[i] && p.x > 4.0 && p.x < 6.0 && p.y > highest) peak = i, highest = p.y;
  }
  REQUIRE(highest > -10.0);
  // The peak's dash: the drawn samples round it.
  std::size_t first = peak, last = peak;
  while (first > 0 && truth.drawn[first - 1]) --first;
  while (last + 1 < truth.screen_div.size() && truth.drawn[last + 1]) ++last;
  const double px_per_div = cv::norm(photo.ImageFromScreen({1.0, 0.0}) - photo.ImageFromScreen({}));
  constexpr double kGlowDiv = 0.08;  // four times the beam's width
  for (std::size_t i = first; i < last; ++i) {
    cv::line(photo.image, Pixel(photo, truth.screen_div[i]), Pixel(photo, truth.screen_div[i + 1]),
             cv::Scalar(235), static_cast<int>(kGlowDiv * px_per_div), cv::LINE_AA);
  }
  const PreparedPhoto prepared = PreparePhoto({photo.image, "glow.png"}, {});
  const GraticuleFit graticule = FindGraticule(prepared, {10, 8}, {});

  // The first reading: the trace's dashes, sampled every 0.01 division.
  DigitizedTrace left;
  left.name = "left";
  left.width_px = 0.02 * px_per_div;
  left.height = 0.8;
  double last_x = -1.0;
  for (std::size_t i = 0; i < truth.screen_div.size(); ++i) {
    const cv::Point2d p = truth.screen_div[i];
    if (!truth.drawn[i] || p.x - last_x < 0.01) continue;
    left.screen_div.push_back(p);
    left.centre_px.push_back(photo.ImageFromScreen(p));
    last_x = p.x;
  }
  REQUIRE(digitize::ReadInDashes(left));
  const cv::Point2d dash = photo.ImageFromScreen(truth.screen_div[peak]);
  // Without the reading, the wide dash is a mark; with it, the trace's own.
  CHECK(digitize::FindHandMarks(prepared, graticule, 0.02 * px_per_div, 0.8, {}).Covers(dash));
  CHECK_FALSE(
      digitize::FindHandMarks(prepared, graticule, 0.02 * px_per_div, 0.8, {left}).Covers(dash));
}

TEST_CASE("digitize marks: a contact trace's levels are its own course, read in pieces or not") {
  // A contact level printed bold (four times the beam's width) half a
  // division above the screen's bottom line, and a first reading of it in
  // twelve pieces a tenth of a division long (broken as at the ticks of an
  // axis it runs along) and then unbroken for 2.5 divisions. A chopped displacement trace's reading
  // so regular would be its dashes, and its long unbroken run something else (a stroke along it).
  // But a contact trace is drawn by a beam of its own, never chopped: all of it is its course
  // (randomised seed 1007's run 0.405 had its bold levels taken for two marks and its pulse lost).
  const testing::RunScene run = testing::StandardRunScene();
  RenderedPhoto photo = RunPhoto(run, 3);
  const double px_per_div = cv::norm(photo.ImageFromScreen({1.0, 0.0}) - photo.ImageFromScreen({}));
  constexpr double kLevelDiv = -3.5, kBoldDiv = 0.08;
  cv::line(photo.image, Pixel(photo, {1.0, kLevelDiv}), Pixel(photo, {6.0, kLevelDiv}),
           cv::Scalar(235), static_cast<int>(kBoldDiv * px_per_div), cv::LINE_AA);
  const PreparedPhoto prepared = PreparePhoto({photo.image, "level.png"}, {});
  const GraticuleFit graticule = FindGraticule(prepared, {10, 8}, {});

  DigitizedTrace level;
  level.width_px = kBoldDiv * px_per_div;
  level.height = 0.8;
  const auto add = [&](double x) {
    level.screen_div.push_back({x, kLevelDiv});
    level.centre_px.push_back(photo.ImageFromScreen({x, kLevelDiv}));
  };
  for (int piece = 0; piece < 12; ++piece) {
    for (int k = 0; k <= 10; ++k) add(1.0 + 0.16 * piece + 0.01 * k);
  }
  for (double x = 3.5; x <= 6.0; x += 0.01) add(x);
  const cv::Point2d unbroken = photo.ImageFromScreen({4.5, kLevelDiv});
  const double beam_px = 0.02 * px_per_div;

  level.name = "left";  // a displacement trace's reading: dashes, and a stroke along them
  REQUIRE(digitize::ReadInDashes(level));
  CHECK(digitize::FindHandMarks(prepared, graticule, beam_px, 0.8, {level}).Covers(unbroken));
  level.name = "contact";
  level.settings.impact = 2;
  CHECK_FALSE(digitize::FindHandMarks(prepared, graticule, beam_px, 0.8, {level}).Covers(unbroken));
}

TEST_CASE("digitize prints: a figure printed through a dot screen is read like the photo") {
  const testing::RunScene run = testing::StandardRunScene();
  const RenderedPhoto photo = RunPhoto(run, 5);
  // The photo printed: ink coverage from its brightness (bright traces
  // print dark), as round dots on a screen of 4.6 px turned 30 degrees whose
  // area follows the coverage, on light paper.
  constexpr double kPeriodPx = 4.6, kAngleDeg = 30.0;
  const double c = std::cos(kAngleDeg * std::numbers::pi / 180.0);
  const double s = std::sin(kAngleDeg * std::numbers::pi / 180.0);
  cv::Mat1f coverage;
  photo.image.convertTo(coverage, CV_32F, 1.0 / 255);
  cv::GaussianBlur(coverage, coverage, cv::Size(), 0.5 * kPeriodPx);
  cv::Mat1b printed(photo.image.size());
  for (int y = 0; y < printed.rows; ++y) {
    for (int x = 0; x < printed.cols; ++x) {
      const double a = (c * x + s * y) / kPeriodPx, b = (-s * x + c * y) / kPeriodPx;
      const double spot = 0.5 * (std::cos(2 * std::numbers::pi * a) +
                                 std::cos(2 * std::numbers::pi * b));        // -1 .. 1
      const double ink = std::clamp(1.6 * coverage(y, x) + 0.08, 0.0, 1.0);  // a light tint
      printed(y, x) = spot > 1.0 - 2.0 * ink ? 40 : 225;
    }
  }
  cv::GaussianBlur(printed, printed, cv::Size(), 0.6);  // the scanner

  const auto screen = digitize::FindHalftoneScreen(printed);
  REQUIRE(screen.has_value());
  CHECK(screen->period_px == Approx(kPeriodPx).epsilon(0.03));
  // Rows run down the image: the lattice drawn along (cos, sin) is turned
  // clockwise on the page, 60 degrees counter-clockwise modulo 90.
  CHECK(std::abs(screen->angle_deg - (90.0 - kAngleDeg)) < 2.0);
  // A photo has no screen.
  CHECK_FALSE(digitize::FindHalftoneScreen(photo.image).has_value());

  const DigitizeResult result = DigitizePhoto({printed, "printed.png"}, {10, 8}, run.requests, {});
  for (std::size_t k = 0; k < 2; ++k) {
    const DigitizedTrace& trace = result.traces[k];
    const testing::TraceScore score =
        testing::ScoreTrace(trace, photo, run.scene.traces[k], {10, 8});
    INFO(trace.name << ": " << trace.centre_px.size() << " samples, coverage " << score.coverage
                    << ", rms " << score.rms_px << " px");
    CHECK(score.coverage > 0.6);
    CHECK(FarOffTruth(trace, photo) <= trace.centre_px.size() / 100);
  }
}

}  // namespace impactlab
