// The randomised style's handling (docs/rendering.md, "The randomised
// style"): what happened to a photo after it was taken, as a lab's archive
// holds it. An experimenter marked the print about its traces in grease
// pencil or ink (strokes beside and across a trace, rings, arrows, labels),
// taped it down, or the oscillogram survives only as a figure printed in a
// report and scanned. Drawn from a stream of its own, so that a seed's other
// factors, its dirt and its noise are the same with handling or without.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/imgproc.hpp>

#include "render/random_draw.h"
#include "render/styles.h"

namespace impactlab::render {

namespace {

struct Pencil {
  const char* name;
  cv::Vec3f bgr;  // display values
};
// Grease pencils and inks seen on scope prints.
const std::array<Pencil, 7> kPencils = {{{"red", {0.15f, 0.15f, 0.85f}},
                                         {"white", {0.95f, 0.95f, 0.95f}},
                                         {"yellow", {0.2f, 0.85f, 0.95f}},
                                         {"black", {0.05f, 0.05f, 0.05f}},
                                         {"blue", {0.75f, 0.35f, 0.1f}},
                                         {"green", {0.25f, 0.6f, 0.15f}},
                                         {"orange", {0.1f, 0.5f, 0.95f}}}};

// A figure in a printed report: dark ink on white to cream paper, screened
// as round dots, the page scanned a little skew; the figure is the screen
// cropped to the graticule (what lay beyond it and the glare on the glass
// were masked out for the printer), with a margin of page round it.
void DrawPrint(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  PrintLook& print = look.handling.print;
  print.halftone = true;
  print.paper_tone = Uniform(random, 0.0, 1.0);
  const float cream = static_cast<float>(print.paper_tone);
  print.paper_bgr =
      (cv::Vec3f(0.96f, 0.97f, 0.97f) * (1.0f - cream) + cv::Vec3f(0.70f, 0.86f, 0.94f) * cream) *
      static_cast<float>(Uniform(random, 0.9, 1.0));
  const float ink = static_cast<float>(Uniform(random, 0.03, 0.25));
  print.ink_bgr = cv::Vec3f(ink, ink * 1.05f, ink * 1.12f);
  // 65-150 lines per inch scanned at 300-600 dpi.
  print.period_px = LogUniform(random, 2.5, 8.0);
  print.angle_deg = Uniform(random, 0.0, 90.0);
  // The printer made the grid print, or nobody could have read the figure:
  // the ink starts between the ground's tone and the grid's.
  print.floor_of_grid = Uniform(random, 0.2, 0.6);
  print.grid_coverage = Uniform(random, 0.45, 1.0);
  print.ink_spread = Uniform(random, 0.0, 0.15);
  print.paper_mottle = Uniform(random, 0.0, 0.02);
  print.scan_blur_px = Uniform(random, 0.3, 1.5);
  print.scan_noise = LogUniform(random, 0.002, 0.02);
  print.skew_deg = Uniform(random, -3.0, 3.0);
  print.figure_number = UniformInt(random, 2, 60);
  look.pose.rotation_deg += print.skew_deg;
  look.pose.tilt_deg = 0.0;  // a flatbed scanner
  look.pose.barrel_k1 = 0.0;
  const double margin_div = Uniform(random, 0.2, 0.6);
  look.framed_outline_div = Corners(Grow(layout.graticule_div, margin_div, margin_div));
  look.pose.fill = Uniform(random, 0.55, 0.8);       // the page round the figure, the caption below
  look.pose.offset.y = Uniform(random, -0.6, -0.2);  // the figure above its caption
  look.sharpen = 0.0;                                // the scanner's, not a phone's
  look.surround.bezel_bgr = cv::Vec3f::all(0.0f);
  look.surround.bevel_highlight = 0.0;
  look.surround.outside_bgr = cv::Vec3f::all(0.0f);
  look.surround.knobs = false;
  look.print_border = false;
  look.glare = 0.0;
  // Scans are saved as JPEG at a scanner's qualities, when at all.
  if (look.jpeg_quality > 0) look.jpeg_quality = UniformInt(random, 50, 95);
}

}  // namespace

std::mt19937_64 HandlingStream(std::uint64_t seed) {
  // Any fixed odd constant gives a stream unrelated to the look's.
  return std::mt19937_64(seed ^ 0x6A09E667F3BCC909ull);
}

void DrawHandling(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  HandlingLook& handling = look.handling;
  // One person's pencil per photo, for the look's own marks too.
  const Pencil& pencil = kPencils[UniformInt(random, 0, static_cast<int>(kPencils.size()) - 1)];
  look.mark_colour = pencil.name;
  look.mark_bgr = pencil.bgr;
  // At 2000 px: a fine pen (2 px) to a blunt grease pencil (16 px).
  handling.mark_width_px = LogUniform(random, 2.0, 16.0);
  // Marks about the traces in half the photos.
  if (Chance(random, 0.5)) {
    const int marks = UniformInt(random, 1, 4);
    for (int i = 0; i < marks; ++i) {
      handling.trace_marks.push_back(static_cast<TraceMark>(UniformInt(random, 0, 4)));
    }
  }
  // Translucent tape holding the print down or mending a tear.
  handling.tape = Chance(random, 0.15) ? UniformInt(random, 1, 2) : 0;
  handling.tape_opacity = static_cast<float>(Uniform(random, 0.15, 0.5));
  handling.tape_bgr =
      cv::Vec3f(0.84f, 0.93f, 0.96f) * static_cast<float>(Uniform(random, 0.95, 1.05));
  if (Chance(random, 0.25)) DrawPrint(look, layout, random);
}

namespace {

constexpr int kMarkShift = 4;  // cv drawing's sub-pixel bits

cv::Point MarkFixedPoint(cv::Point2d p) {
  return {cvRound(p.x * (1 << kMarkShift)), cvRound(p.y * (1 << kMarkShift))};
}

// A trace to mark, with at least two points; null when there is none.
const TraceTruth* TraceToMark(const std::vector<TraceTruth>& traces, std::mt19937_64& random) {
  std::vector<const TraceTruth*> usable;
  for (const TraceTruth& t : traces) {
    if (t.centre_px.size() >= 2) usable.push_back(&t);
  }
  if (usable.empty()) return nullptr;
  return usable[UniformInt(random, 0, static_cast<int>(usable.size()) - 1)];
}

// The unit normal of a trace's centre line at its point i, in image pixels;
// (0, 0) where its neighbours coincide.
cv::Point2d TraceNormalPx(const std::vector<cv::Point2d>& centre, std::size_t i) {
  const cv::Point2d d = centre[std::min(i + 1, centre.size() - 1)] - centre[i > 0 ? i - 1 : 0];
  const double length = std::hypot(d.x, d.y);
  return length > 1e-9 ? cv::Point2d(-d.y / length, d.x / length) : cv::Point2d(0.0, 0.0);
}

cv::Point2d Turned(cv::Point2d v, double angle) {
  return {v.x * std::cos(angle) - v.y * std::sin(angle),
          v.x * std::sin(angle) + v.y * std::cos(angle)};
}

// A stroke beside a trace, following its course for 1..4 divisions, clear of
// it: a person underlines a trace, they do not draw over it. Its centre runs
// `clear_px` (half its width and the beam's) plus a gap of up to
// kMarkAlongTraceMaxGapDiv from the trace's, wandering a little.
std::vector<cv::Point> StrokeAlongTrace(const TraceTruth& trace, double px_per_div, double clear_px,
                                        std::mt19937_64& random) {
  const std::vector<cv::Point2d>& centre = trace.centre_px;
  const double max_gap_px = kMarkAlongTraceMaxGapDiv * px_per_div;
  const double length_px = Uniform(random, 1.0, 4.0) * px_per_div;
  const double gap_px = Uniform(random, 0.03 * px_per_div, max_gap_px);
  const double side = Chance(random, 0.5) ? 1.0 : -1.0;
  const double wobble_px = Uniform(random, 0.0, 0.03) * px_per_div;
  const double wavelength_px = Uniform(random, 0.5, 2.0) * px_per_div;
  const double phase = Uniform(random, 0.0, 2.0 * std::numbers::pi);
  std::size_t i = UniformInt(random, 0, static_cast<int>(centre.size()) - 2);
  std::vector<cv::Point> stroke;
  double travelled = 0.0, since_point = 1e9;
  for (; i < centre.size() && travelled <= length_px; ++i) {
    if (i > 0) {
      const double step = cv::norm(centre[i] - centre[i - 1]);
      travelled += step;
      since_point += step;
    }
    if (since_point < 2.0 && i + 1 < centre.size()) continue;  // a point every 2 px or so
    const cv::Point2d normal = TraceNormalPx(centre, i);
    if (normal == cv::Point2d(0.0, 0.0)) continue;
    const double wobble =
        wobble_px * std::sin(2.0 * std::numbers::pi * travelled / wavelength_px + phase);
    const double offset = clear_px + std::clamp(gap_px + wobble, 0.0, max_gap_px);
    stroke.push_back(MarkFixedPoint(centre[i] + normal * (side * offset)));
    since_point = 0.0;
  }
  return stroke;
}

}  // namespace

cv::Mat DrawTraceMarks(const HandlingLook& handling, cv::Size size,
                       const std::vector<TraceTruth>& traces, double px_per_div,
                       std::mt19937_64& random) {
  if (handling.trace_marks.empty()) return {};
  cv::Mat mark = cv::Mat::zeros(size, CV_8UC1);
  const double scale = size.width / 2000.0;
  const std::array<const char*, 8> labels = {"X0=.405", ".18 in", "R",  "L",
                                             "1st",     "2nd",    "e?", "ok"};
  for (const TraceMark kind : handling.trace_marks) {
    const TraceTruth* trace = TraceToMark(traces, random);
    if (trace == nullptr) continue;
    const std::vector<cv::Point2d>& centre = trace->centre_px;
    // The pen's width varies a little from mark to mark.
    const double width_px =
        std::max(1.0, scale * handling.mark_width_px * Uniform(random, 0.8, 1.2));
    const int thickness = std::max(1, static_cast<int>(std::lround(width_px)));
    const cv::Scalar coverage(UniformInt(random, 170, 255));
    const std::size_t i = UniformInt(random, 0, static_cast<int>(centre.size()) - 1);
    cv::Point2d normal = TraceNormalPx(centre, i);
    if (normal == cv::Point2d(0.0, 0.0)) normal = {0.0, 1.0};
    const double side = Chance(random, 0.5) ? 1.0 : -1.0;
    switch (kind) {
      case TraceMark::kAlong: {
        // Clear of the trace by half the stroke, the beam's core and a pixel.
        const double clear_px = 0.5 * thickness + 0.03 * px_per_div + 1.0;
        const std::vector<cv::Point> stroke =
            StrokeAlongTrace(*trace, px_per_div, clear_px, random);
        if (stroke.size() >= 2) {
          cv::polylines(mark, stroke, false, coverage, thickness, cv::LINE_AA, kMarkShift);
        }
        break;
      }
      case TraceMark::kAcross: {
        // Through the trace, within 40 degrees of its normal, 0.3..1.2 divisions long.
        const cv::Point2d direction =
            Turned(normal, Uniform(random, -40.0, 40.0) * std::numbers::pi / 180.0);
        const double length_px = Uniform(random, 0.3, 1.2) * px_per_div;
        const double shift = Uniform(random, -0.3, 0.3) * length_px;
        cv::line(mark, MarkFixedPoint(centre[i] + direction * (shift - 0.5 * length_px)),
                 MarkFixedPoint(centre[i] + direction * (shift + 0.5 * length_px)), coverage,
                 thickness, cv::LINE_AA, kMarkShift);
        break;
      }
      case TraceMark::kRing: {
        // Round a point of the trace, nearly closed, 0.25..0.8 division across.
        const double radius_px = Uniform(random, 0.25, 0.8) * px_per_div;
        const cv::Size axes(cvRound(radius_px * Uniform(random, 0.8, 1.25) * (1 << kMarkShift)),
                            cvRound(radius_px * (1 << kMarkShift)));
        const double start = Uniform(random, 0.0, 360.0);
        cv::ellipse(mark, MarkFixedPoint(centre[i]), axes, Uniform(random, 0.0, 180.0), start,
                    start + Uniform(random, 300.0, 370.0), coverage, thickness, cv::LINE_AA,
                    kMarkShift);
        break;
      }
      case TraceMark::kArrow: {
        // From 0.5..1.5 divisions off, its tip 0.1..0.3 division short of the trace.
        const cv::Point2d direction =
            Turned(normal * side, Uniform(random, -50.0, 50.0) * std::numbers::pi / 180.0);
        const cv::Point2d tip = centre[i] + direction * (Uniform(random, 0.1, 0.3) * px_per_div);
        const cv::Point2d tail = tip + direction * (Uniform(random, 0.5, 1.5) * px_per_div);
        cv::arrowedLine(mark, MarkFixedPoint(tail), MarkFixedPoint(tip), coverage, thickness,
                        cv::LINE_AA, kMarkShift, 0.25);
        break;
      }
      case TraceMark::kLabel: {
        // Written 0.3..1 division beside the trace, 0.25..0.5 division high.
        const cv::Point2d at = centre[i] + normal * (side * Uniform(random, 0.3, 1.0) * px_per_div);
        const int font =
            Chance(random, 0.5) ? cv::FONT_HERSHEY_SCRIPT_SIMPLEX : cv::FONT_HERSHEY_SIMPLEX;
        const double height_px = Uniform(random, 0.25, 0.5) * px_per_div;
        const double font_scale = cv::getFontScaleFromHeight(font, cvRound(height_px), thickness);
        cv::putText(mark, labels[UniformInt(random, 0, static_cast<int>(labels.size()) - 1)],
                    cv::Point(cvRound(at.x), cvRound(at.y)), font, font_scale, coverage, thickness,
                    cv::LINE_AA);
        break;
      }
    }
  }
  cv::GaussianBlur(mark, mark, cv::Size(), 0.7);
  return mark;
}

cv::Mat DrawTape(int count, cv::Size size, std::mt19937_64& random) {
  cv::Mat tape = cv::Mat::zeros(size, CV_8UC1);
  const cv::Point2d extent(size.width, size.height);
  for (int i = 0; i < count; ++i) {
    const double width_px = size.width * Uniform(random, 0.035, 0.08);
    const double length_px = size.width * Uniform(random, 0.12, 0.3);
    cv::Point2d centre, along;  // `along`: the unit direction of the tape's length
    const int side = UniformInt(random, 0, 3);
    if (Chance(random, 0.6)) {
      // Over a corner, across its diagonal.
      const cv::Point2d corner(side % 2 == 0 ? 0.0 : extent.x, side < 2 ? 0.0 : extent.y);
      const cv::Point2d inward(side % 2 == 0 ? 1.0 : -1.0, side < 2 ? 1.0 : -1.0);
      centre = corner + inward * (size.width * Uniform(random, 0.02, 0.07));
      along =
          Turned(cv::Point2d(-inward.y, inward.x), Uniform(random, -0.25, 0.25)) / std::sqrt(2.0);
    } else {
      // Over an edge, at right angles to it, half on the photo.
      const double at = Uniform(random, 0.15, 0.85);
      const std::array<cv::Point2d, 4> points = {
          cv::Point2d(at * extent.x, 0.0), cv::Point2d(extent.x, at * extent.y),
          cv::Point2d(at * extent.x, extent.y), cv::Point2d(0.0, at * extent.y)};
      const std::array<cv::Point2d, 4> inward = {cv::Point2d(0, 1), cv::Point2d(-1, 0),
                                                 cv::Point2d(0, -1), cv::Point2d(1, 0)};
      centre = points[side];
      along = Turned(inward[side], Uniform(random, -0.25, 0.25));
    }
    const cv::Point2d across(-along.y, along.x);
    // Straight sides; torn ends: a zigzag across the tape's width.
    std::vector<cv::Point> outline;
    for (int end = 0; end < 2; ++end) {
      const double sign = end == 0 ? 1.0 : -1.0;
      constexpr int kTeeth = 7;
      for (int k = 0; k <= kTeeth; ++k) {
        const double s = sign * (-0.5 + static_cast<double>(k) / kTeeth) * width_px;
        const double tear = Uniform(random, -0.12, 0.12) * width_px;
        outline.push_back(
            MarkFixedPoint(centre + along * (sign * 0.5 * length_px + tear) + across * s));
      }
    }
    cv::fillPoly(tape, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255), cv::LINE_AA,
                 kMarkShift);
  }
  cv::GaussianBlur(tape, tape, cv::Size(), 0.6);
  return tape;
}

}  // namespace impactlab::render
