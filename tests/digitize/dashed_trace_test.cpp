// Sparse dashes: displacement traces chopped into short dashes with gaps one
// and a half to four times as long, on a graticule lit almost as brightly as
// the traces (a print, a 16-bit negative) or with faint scratches crossing
// them. Each trace must be found and measured against the renderer's truth.
#include <algorithm>
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

#include "digitize/digitize.h"
#include "io/errors.h"
#include "photo_scenes.h"
#include "render/oscillograph.h"

namespace impactlab {
namespace {

// Each sample's distance (photo pixels) from the true centre line.
std::vector<double> Misses(const DigitizedTrace& trace, const RenderedPhoto& photo) {
  const TraceTruth* truth = nullptr;
  for (const TraceTruth& t : photo.traces) {
    if (t.name == trace.name) truth = &t;
  }
  std::vector<double> misses;
  if (truth == nullptr) return misses;
  std::size_t hint = 0;
  for (const cv::Point2d& p : trace.centre_px) {
    misses.push_back(testing::DistanceToPolyline(truth->centre_px, p, hint));
  }
  return misses;
}

// A 2000 px photo of the standard run scene's settings with a chopper
// drawing dashes `duty` of each `dash_div` slot, the beam `beam_fwhm_div` wide.
RenderOptions DashedOptions(PhotoStyle style, unsigned seed, double dash_div, double duty,
                            double beam_fwhm_div) {
  RenderOptions options;
  options.style = style;
  options.width_px = 2000;
  options.seed = seed;
  options.chop_dash_div = dash_div;
  options.chop_duty = duty;
  options.beam_fwhm_div = beam_fwhm_div;
  return options;
}

// How many samples lie more than 3 px off the true centre line.
std::size_t FarOff(const std::vector<double>& misses) {
  return static_cast<std::size_t>(
      std::count_if(misses.begin(), misses.end(), [](double d) { return d > 3.0; }));
}

struct Case {
  PhotoStyle style;
  double dash_div;  // one chopper slot along the sweep
  double duty;      // the share of its slot a trace is drawn
  bool sixteen_bit;
  double scratch;  // the scratches' level (of full scale); 0: none
  double grid;     // the graticule redrawn at this level; 0: as rendered
};

}  // namespace

TEST_CASE("digitize dashed: sparse dashes on a bright graticule or across scratches are measured") {
  const testing::RunScene run = testing::StandardRunScene();
  // Dashes of 0.02-0.04 division (4-6 px at 2000 px) with gaps one and a
  // half to four times as long (the two traces alternate on the chopper). On
  // the print and the negative the graticule is redrawn so bright that the
  // traces stand only 1.4-2 times higher than its lines (as on the external
  // prints); the clean photo has scratches half as bright as its traces.
  const Case cases[] = {{PhotoStyle::kPolaroid, 0.05, 0.4, false, 0.0, 0.5},
                        {PhotoStyle::kNegative, 0.06, 0.35, true, 0.0, 0.45},
                        {PhotoStyle::kClean, 0.1, 0.2, false, 0.3, 0.0}};
  for (const Case& c : cases) {
    RenderOptions options = DashedOptions(c.style, 7, c.dash_div, c.duty, 0.012);
    options.sixteen_bit = c.sixteen_bit;
    RenderedPhoto photo = RenderOscillograph(run.scene, options);
    if (c.grid > 0.0) testing::BrightenGraticule(photo.image, photo, c.grid);
    if (c.scratch > 0.0) {
      testing::Scratch(photo.image, photo, {0.3, 3.8}, {9.7, -2.3}, c.scratch);
      testing::Scratch(photo.image, photo, {1.0, -2.2}, {8.5, 3.5}, c.scratch);
      testing::Scratch(photo.image, photo, {6.3, 3.9}, {6.6, -2.3}, c.scratch);
    }

    const DigitizeResult result =
        DigitizePhoto({photo.image, "dashed.png"}, {10, 8}, run.requests, {});
    for (std::size_t k = 0; k < 2; ++k) {  // right, left
      const DigitizedTrace& trace = result.traces[k];
      const testing::TraceScore score =
          testing::ScoreTrace(trace, photo, run.scene.traces[k], {10, 8});
      const std::vector<double> misses = Misses(trace, photo);
      std::size_t far = 0;
      double sum2 = 0.0;
      for (const double d : misses) {
        if (d > 3.0) {
          ++far;
        } else {
          sum2 += d * d;
        }
      }
      const double rms_near = misses.size() > far ? std::sqrt(sum2 / (misses.size() - far)) : 0.0;
      INFO(PhotoStyleName(c.style)
           << " dash " << c.dash_div << " div, duty " << c.duty << ", " << trace.name << ": "
           << misses.size() << " samples, coverage " << score.coverage << ", rms " << rms_near
           << " px within 3 px, " << far << " further");
      // Found and measured: all but a few samples on the true centre line to a
      // few tenths of a pixel; nothing invented far off.
      CHECK(misses.size() > 100);
      CHECK(rms_near < 0.4);
      CHECK(far <= misses.size() / 50);
      CHECK(score.max_px < 30.0);
      // Of the drawn stretches (less the dash ends and cusps dropped), most
      // are measured.
      CHECK(score.coverage > 0.65);
    }
  }
}

}  // namespace impactlab

namespace impactlab {
namespace {

TEST_CASE("digitize dashed: a continuous scratch across sparse dots does not take their course") {
  // Dots a fifth of a 0.12-division slot long: a scratch crossing the band
  // steeply holds a peak in every column it crosses, the trace in one of
  // four or five, so column by column the scratch earns more than the dots
  // even where it is fainter, and where it crosses the trace's own flank it
  // continues the trace's course.
  const testing::RunScene run = testing::StandardRunScene();
  for (const auto& [level, thickness] :
       {std::pair{0.5, 1}, std::pair{0.8, 1}, std::pair{0.4, 5}, std::pair{0.6, 5}}) {
    RenderedPhoto photo =
        RenderOscillograph(run.scene, DashedOptions(PhotoStyle::kClean, 5, 0.12, 0.22, 0.025));
    // Across the right trace's band, steeply, and across the left's.
    testing::Scratch(photo.image, photo, {5.3, -0.2}, {6.4, 4.0}, level, thickness);
    testing::Scratch(photo.image, photo, {2.2, 0.2}, {3.1, -2.6}, level, thickness);
    const DigitizeResult result =
        DigitizePhoto({photo.image, "dots-and-scratch.png"}, {10, 8}, run.requests, {});
    for (std::size_t k = 0; k < 2; ++k) {
      const std::vector<double> misses = Misses(result.traces[k], photo);
      const std::size_t far = FarOff(misses);
      INFO("scratch " << thickness << " px at " << level << " of full scale, "
                      << result.traces[k].name << ": " << misses.size() << " samples, " << far
                      << " off the line");
      // Followed along the dots: what lies off them is the crossing itself,
      // where the scratch's light pulls the centre (a tenth of a division
      // of the sweep for the thick bright scratch). Taking the scratch's
      // course put 29-38 % of the right trace's samples off it.
      CHECK(misses.size() > 100);
      CHECK(far <= misses.size() / 10);
    }
  }
}

TEST_CASE("digitize dashed: traces as bright as the grid are read where they leave its lines") {
  // The graticule redrawn as bright as the traces: nothing in brightness
  // tells a trace from a grid line, but a grid line lies on the graticule's
  // lattice and the traces swing across it.
  const testing::RunScene run = testing::StandardRunScene();
  RenderedPhoto photo =
      RenderOscillograph(run.scene, DashedOptions(PhotoStyle::kPolaroid, 7, 0.05, 0.4, 0.012));
  testing::BrightenGraticule(photo.image, photo, 1.0);
  const DigitizeResult result =
      DigitizePhoto({photo.image, "bright-grid.png"}, {10, 8}, run.requests, {});
  for (std::size_t k = 0; k < 2; ++k) {
    const std::vector<double> misses = Misses(result.traces[k], photo);
    const std::size_t far = FarOff(misses);
    INFO(result.traces[k].name << ": " << misses.size() << " samples, " << far << " off the line");
    CHECK(misses.size() > 100);
    CHECK(far <= misses.size() / 50);
  }
}

TEST_CASE("digitize dashed: a band holding only bright grid lines is refused, saying so") {
  // The left trace is not drawn, its band crossed only by grid lines as
  // bright as the traces: what is followed there lies on the lattice.
  testing::RunScene run = testing::StandardRunScene();
  run.scene.traces.erase(run.scene.traces.begin() + 1);
  RenderOptions options;
  options.style = PhotoStyle::kPolaroid;
  options.width_px = 2000;
  options.seed = 7;
  RenderedPhoto photo = RenderOscillograph(run.scene, options);
  testing::BrightenGraticule(photo.image, photo, 1.0);
  const DigitizeResult result =
      DigitizePhoto({photo.image, "no-left.png"}, {10, 8}, run.requests, {});
  INFO(result.Failure());
  CHECK_FALSE(result.ok);  // else a grid line was taken for the missing trace
  CHECK_THAT(result.Failure(), Catch::Contains("trace 'left' not found"));
}

}  // namespace
}  // namespace impactlab

namespace impactlab {
namespace {

TEST_CASE(
    "digitize dashed: fine dots shorter than the outlier reach are judged by their neighbours") {
  // A small photo (about 70 px a division) of a finely chopped, sub-pixel
  // beam: dots 2-3 px long every 7-10 px (0.07-0.09 division slots, a third
  // drawn), as randomised seed 1014's run 0.713. Most samples have fewer than
  // three neighbours within the outlier fit's tenth of a division; judged
  // against the neighbouring dots they are kept where they lie on the line.
  const testing::RunScene run = testing::StandardRunScene();
  for (const auto& [dash_div, duty] : {std::pair{0.07, 0.32}, std::pair{0.09, 0.3}}) {
    RenderOptions options = DashedOptions(PhotoStyle::kClean, 11, dash_div, duty, 0.01);
    options.width_px = 900;
    const RenderedPhoto photo = RenderOscillograph(run.scene, options);
    const DigitizeResult result =
        DigitizePhoto({photo.image, "fine-dots.png"}, {10, 8}, run.requests, {});
    INFO("slot " << dash_div << " div, duty " << duty << ": " << result.Failure());
    REQUIRE(result.ok);
    for (std::size_t k = 0; k < 2; ++k) {
      const DigitizedTrace& trace = result.traces[k];
      const std::vector<double> misses = Misses(trace, photo);
      const std::size_t far = FarOff(misses);
      INFO(trace.name << ": " << misses.size() << " samples, coverage " << trace.coverage << ", "
                      << far << " off the line");
      CHECK(trace.coverage > 0.1);
      CHECK(far <= misses.size() / 20);
    }
  }
}

}  // namespace
}  // namespace impactlab
