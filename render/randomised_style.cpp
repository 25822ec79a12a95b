// The randomised style (docs/rendering.md, "The randomised style"): domain
// randomisation of the photo's look. Every factor is drawn per seed from a
// range wider than any one of the fixed styles covers, so that a digitizer
// tuned on this generator has seen more than one kind of photo. The ranges
// are plausible for scope photos a person can still read, not calibrated.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "render/random_draw.h"
#include "render/styles.h"

namespace impactlab::render {

namespace {

// Uniform in log: for scale factors whose small values matter as much as
// their large ones (size, blur, noise, brightness).
double LogUniform(std::mt19937_64& random, double lo, double hi) {
  return std::exp(Uniform(random, std::log(lo), std::log(hi)));
}

bool Chance(std::mt19937_64& random, double p) { return Uniform(random, 0.0, 1.0) < p; }

// Phosphors a scope of the time might have: P31 (green, most), P11 (blue,
// for photography), P7 (bluish white).
const std::array<cv::Vec3f, 3> kPhosphorBgr = {
    cv::Vec3f{0.30f, 1.0f, 0.42f}, cv::Vec3f{1.0f, 0.45f, 0.15f}, cv::Vec3f{1.0f, 0.9f, 0.7f}};
constexpr std::array<const char*, 3> kPhosphorNames = {"P31", "P11", "P7"};

// Where the camera sits and what it frames: the bezel under a hood, the bezel
// and the lit front panel, a print on a scanner, or a tight crop.
void DrawSurround(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  const int kind = UniformInt(random, 0, 3);
  look.surround.bezel_bgr = cv::Vec3f::all(static_cast<float>(LogUniform(random, 0.001, 0.03)));
  look.surround.bevel_highlight = Uniform(random, 0.0, 2.5);
  look.framed_outline_div = Corners(layout.bezel_div);
  look.pose.fill = Uniform(random, 0.75, 0.97);
  if (kind == 0) {
    look.surround_kind = "hood";
  } else if (kind == 1) {
    look.surround_kind = "panel";
    const std::array<cv::Vec3f, 3> panels = {cv::Vec3f{0.105f, 0.095f, 0.085f},  // blue-grey
                                             cv::Vec3f{0.07f, 0.09f, 0.10f},     // beige
                                             cv::Vec3f{0.08f, 0.08f, 0.08f}};    // grey
    look.surround.outside_bgr =
        panels[UniformInt(random, 0, 2)] * static_cast<float>(LogUniform(random, 0.3, 2.5));
    look.surround.knobs = Chance(random, 0.7);
    look.surround.knob_bgr = cv::Vec3f::all(static_cast<float>(Uniform(random, 0.005, 0.03)));
    look.pose.fill = Uniform(random, 0.6, 0.9);  // the panel shows around the bezel
  } else if (kind == 2) {
    look.surround_kind = "print";
    look.print_border = true;
    look.print_image_div =
        Grow(layout.graticule_div, Uniform(random, 0.3, 1.5), Uniform(random, 0.2, 1.0));
    look.print_border_div = Uniform(random, 0.1, 0.7);
    look.framed_outline_div =
        Corners(Grow(look.print_image_div, look.print_border_div, look.print_border_div));
  } else {
    // Cropped to about the graticule: the face's edge and the bezel partly out
    // of the frame.
    look.surround_kind = "cropped";
    const double margin_div = Uniform(random, 0.1, 0.7);
    look.framed_outline_div = Corners(Grow(layout.graticule_div, margin_div, margin_div));
    look.pose.fill = Uniform(random, 0.85, 0.95);
  }
}

// The graticule: brightness from barely lit to nearly as bright as a trace,
// the line's width, the centre axes' ticks, worn-off stretches of line.
void DrawGraticuleLook(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  const std::array<cv::Vec3f, 3> lamps = {cv::Vec3f{0.75f, 0.95f, 1.0f},   // warm lamp
                                          cv::Vec3f{0.95f, 0.95f, 0.95f},  // white
                                          cv::Vec3f{0.55f, 1.0f, 0.7f}};   // greenish
  look.screen.graticule_bgr =
      lamps[UniformInt(random, 0, 2)] * static_cast<float>(LogUniform(random, 0.01, 0.3));
  look.graticule_fwhm_div = LogUniform(random, 0.008, 0.05);
  look.screen.graticule_ticks = Chance(random, 0.75);
  if (Chance(random, 0.5)) {
    const cv::Rect2d& g = layout.graticule_div;
    const int gaps = UniformInt(random, 1, 8);
    for (int i = 0; i < gaps; ++i) {
      const double length_div = Uniform(random, 0.2, 3.0);
      constexpr double kHalfWidthDiv = 0.12;  // wider than any line drawn
      if (Chance(random, 0.5)) {
        const double x = g.x + UniformInt(random, 0, static_cast<int>(std::lround(g.width)));
        const double y = Uniform(random, g.y, g.y + g.height - length_div);
        look.screen.graticule_missing_div.push_back(
            {x - kHalfWidthDiv, y, 2 * kHalfWidthDiv, length_div});
      } else {
        const double y = g.y + UniformInt(random, 0, static_cast<int>(std::lround(g.height)));
        const double x = Uniform(random, g.x, g.x + g.width - length_div);
        look.screen.graticule_missing_div.push_back(
            {x, y - kHalfWidthDiv, length_div, 2 * kHalfWidthDiv});
      }
    }
  }
}

// The camera: roll, perspective, lens distortion, focus.
void DrawCamera(StyleLook& look, std::mt19937_64& random) {
  look.pose.rotation_deg = Uniform(random, -10.0, 10.0);
  // Half are square on (a scope camera or a copy stand), half hand-held.
  look.pose.tilt_deg = Chance(random, 0.5) ? 0.0 : Uniform(random, 0.0, 25.0);
  look.pose.tilt_azimuth_deg = Uniform(random, 0.0, 360.0);
  look.pose.camera_distance_div = Uniform(random, 18.0, 40.0);
  // Mostly barrel, some pincushion; half have none worth modelling.
  look.pose.barrel_k1 = Chance(random, 0.5) ? 0.0 : Uniform(random, -0.08, 0.02);
  look.pose.offset = {Uniform(random, -0.8, 0.8), Uniform(random, -0.8, 0.8)};
  look.blur_px = LogUniform(random, 0.3, 2.5);
}

// Room light, falloff and glare on the glass.
void DrawLight(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  look.vignetting = Uniform(random, 0.0, 0.5);
  look.light_gradient = Uniform(random, 0.0, 0.3);
  look.light_angle_rad = Uniform(random, 0.0, 2.0 * std::numbers::pi);
  look.light_unevenness = Uniform(random, 0.0, 0.12);
  look.screen.face_bgr =
      cv::Vec3f(0.6f, 1.0f, 0.8f) * static_cast<float>(LogUniform(random, 0.001, 0.02));
  if (Chance(random, 0.4)) {
    look.glare = Uniform(random, 0.02, 0.15);
    const cv::Rect2d& g = layout.graticule_div;
    look.glare_centre_div = {Uniform(random, g.x, g.br().x), Uniform(random, g.y, g.br().y)};
    look.glare_radius_div = Uniform(random, 0.8, 2.5);
  }
}

// Film or sensor, development and the file.
void DrawFilm(StyleLook& look, std::mt19937_64& random) {
  const int phosphor = Chance(random, 0.75) ? 0 : UniformInt(random, 1, 2);
  look.screen.phosphor_bgr = kPhosphorBgr[phosphor];
  look.screen.glow_fraction = Uniform(random, 0.05, 0.3);
  look.screen.glow_sigma_div = Uniform(random, 0.025, 0.07);
  look.exposure_gain = LogUniform(random, 1.5, 6.0);
  look.tone_gamma = Uniform(random, 0.45, 0.9);
  const double development = Uniform(random, 0.0, 1.0);
  if (development < 0.45) {
    look.development = Development::kColour;
    look.sensor_noise = LogUniform(random, 0.002, 0.05);
    look.chroma_noise = Uniform(random, 0.0, 0.015);
    if (Chance(random, 0.4)) look.sharpen = Uniform(random, 0.2, 0.8);
    look.grey = Chance(random, 0.3);
  } else {
    look.development = development < 0.75 ? Development::kMonochrome : Development::kNegative;
    const bool sepia = Chance(random, 0.3);
    look.paper_bgr = sepia ? cv::Vec3f(0.76f, 0.87f, 0.95f)
                           : cv::Vec3f::all(static_cast<float>(Uniform(random, 0.85, 0.97)));
    look.black_level = static_cast<float>(Uniform(random, 0.02, 0.15));
    look.grain = LogUniform(random, 0.005, 0.045);
    // A scanner's own noise on top of the film's grain.
    if (Chance(random, 0.5)) look.sensor_noise = LogUniform(random, 0.002, 0.01);
    look.grey = Chance(random, 0.6);
  }
  look.width_px = static_cast<int>(std::lround(LogUniform(random, 600.0, 6000.0)));
  look.jpeg_quality = Chance(random, 0.7) ? UniformInt(random, 10, 95) : 0;
  look.sixteen_bit = look.jpeg_quality == 0 && Chance(random, 0.4);
}

// Dust, scratches, hairs and hand marks, from none to a lot.
void DrawDirtLook(StyleLook& look, std::mt19937_64& random) {
  const double scale = look.width_px / 2000.0;
  look.dust_specks = Chance(random, 0.2) ? 0 : static_cast<int>(LogUniform(random, 1.0, 250.0));
  look.scratches = UniformInt(random, 0, 8);
  look.scratch_width_px =
      std::max(1, static_cast<int>(std::lround(scale * Uniform(random, 0.6, 2.0))));
  look.hairs = UniformInt(random, 0, 5);
  look.hair_width_px =
      std::max(1, static_cast<int>(std::lround(scale * Uniform(random, 0.8, 3.0))));
  look.hair_length_lo = 0.05;
  look.hair_length_hi = 0.4;
  // Hand marks: none in half the photos, else 1..6, a quarter of them
  // following a trace and a sixth crossing one.
  const int marks = Chance(random, 0.5) ? 0 : UniformInt(random, 1, 6);
  for (int i = 0; i < marks; ++i) {
    const double kind = Uniform(random, 0.0, 1.0);
    look.hand_marks.push_back(kind < 0.25   ? HandMark::kAlongTrace
                              : kind < 0.42 ? HandMark::kAcrossTrace
                                            : static_cast<HandMark>(UniformInt(random, 0, 3)));
  }
  look.mark_width_px = LogUniform(random, 2.0, 14.0);  // at 2000 px: fine pen to grease pencil
  const std::array<cv::Vec3f, 7> pencils = {cv::Vec3f{0.15f, 0.15f, 0.85f},  // red grease pencil
                                            cv::Vec3f{0.95f, 0.95f, 0.95f},  // white
                                            cv::Vec3f{0.2f, 0.85f, 0.95f},   // yellow
                                            cv::Vec3f{0.05f, 0.05f, 0.05f},  // black ink
                                            cv::Vec3f{0.75f, 0.35f, 0.1f},   // blue ink
                                            cv::Vec3f{0.25f, 0.6f, 0.15f},   // green
                                            cv::Vec3f{0.1f, 0.5f, 0.95f}};   // orange
  look.mark_bgr = pencils[UniformInt(random, 0, static_cast<int>(pencils.size()) - 1)];
  // Translucent tape holding the print down or mending a tear.
  look.tape = Chance(random, 0.15) ? UniformInt(random, 1, 2) : 0;
  look.tape_opacity = static_cast<float>(Uniform(random, 0.15, 0.5));
  look.tape_bgr = cv::Vec3f(0.84f, 0.93f, 0.96f) * static_cast<float>(Uniform(random, 0.95, 1.05));
}

// A quarter of the photos are figures reproduced in a printed report and
// scanned: dark ink on white to cream paper, screened as round dots.
void DrawReproduction(StyleLook& look, std::mt19937_64& random) {
  if (!Chance(random, 0.25)) return;
  PrintLook& print = look.print;
  print.halftone = true;
  const float cream = static_cast<float>(Uniform(random, 0.0, 1.0));
  print.paper_bgr =
      (cv::Vec3f(0.96f, 0.97f, 0.97f) * (1.0f - cream) + cv::Vec3f(0.70f, 0.86f, 0.94f) * cream) *
      static_cast<float>(Uniform(random, 0.9, 1.0));
  const float ink = static_cast<float>(Uniform(random, 0.03, 0.25));
  print.ink_bgr = cv::Vec3f(ink, ink * 1.05f, ink * 1.12f);
  print.period_px = LogUniform(random, 2.5, 8.0);
  print.angle_deg = Uniform(random, 0.0, 90.0);
  print.ink_floor = Uniform(random, 0.03, 0.2);
  print.ink_gain = Uniform(random, 1.0, 1.8);
  print.ink_spread = Uniform(random, 0.0, 0.15);
  print.paper_mottle = Uniform(random, 0.0, 0.02);
  print.scan_blur_px = Uniform(random, 0.3, 1.5);
  print.scan_noise = LogUniform(random, 0.002, 0.02);
  look.sharpen = 0.0;  // the scanner's, not a phone's
  // The figure shows the screen: what lies beyond it, and the glare on the
  // glass, were masked out for the printer (the framing stays as drawn).
  look.surround.bezel_bgr = cv::Vec3f::all(0.0f);
  look.surround.bevel_highlight = 0.0;
  look.surround.outside_bgr = cv::Vec3f::all(0.0f);
  look.surround.knobs = false;
  look.print_border = false;
  look.glare = 0.0;
}

std::string PolarityName(Development development) {
  return development == Development::kNegative ? "negative" : "positive";
}

std::string DevelopmentName(Development development) {
  switch (development) {
    case Development::kColour:
      return "colour";
    case Development::kMonochrome:
      return "print";
    case Development::kNegative:
      return "negative";
  }
  return "unknown";
}

}  // namespace

void DrawRandomised(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  DrawSurround(look, layout, random);
  DrawGraticuleLook(look, layout, random);
  DrawCamera(look, random);
  DrawLight(look, layout, random);
  DrawFilm(look, random);
  DrawDirtLook(look, random);
  DrawReproduction(look, random);
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

// A grease-pencil stroke along a trace's course, 1..4 divisions of it, at an
// offset of up to kMarkAlongTraceMaxOffsetDiv that wanders a little.
std::vector<cv::Point> StrokeAlongTrace(const TraceTruth& trace, double px_per_div,
                                        std::mt19937_64& random) {
  const std::vector<cv::Point2d>& centre = trace.centre_px;
  const double max_offset_px = kMarkAlongTraceMaxOffsetDiv * px_per_div;
  const double length_px = Uniform(random, 1.0, 4.0) * px_per_div;
  const double offset_px = Uniform(random, 0.0, max_offset_px) * (Chance(random, 0.5) ? 1 : -1);
  const double wobble_px = Uniform(random, 0.0, 0.05) * px_per_div;
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
    const double offset = std::clamp(
        offset_px +
            wobble_px * std::sin(2.0 * std::numbers::pi * travelled / wavelength_px + phase),
        -max_offset_px, max_offset_px);
    stroke.push_back(MarkFixedPoint(centre[i] + normal * offset));
    since_point = 0.0;
  }
  return stroke;
}

// A stroke across a trace: through one of its points, within 40 degrees of
// its normal, 0.3..1.5 divisions long.
std::vector<cv::Point> StrokeAcrossTrace(const TraceTruth& trace, double px_per_div,
                                         std::mt19937_64& random) {
  const std::vector<cv::Point2d>& centre = trace.centre_px;
  const std::size_t i = UniformInt(random, 0, static_cast<int>(centre.size()) - 1);
  cv::Point2d normal = TraceNormalPx(centre, i);
  if (normal == cv::Point2d(0.0, 0.0)) normal = {0.0, 1.0};
  const double turn = Uniform(random, -40.0, 40.0) * std::numbers::pi / 180.0;
  const cv::Point2d direction(normal.x * std::cos(turn) - normal.y * std::sin(turn),
                              normal.x * std::sin(turn) + normal.y * std::cos(turn));
  const double length_px = Uniform(random, 0.3, 1.5) * px_per_div;
  const double shift = Uniform(random, -0.3, 0.3) * length_px;
  return {MarkFixedPoint(centre[i] + direction * (shift - 0.5 * length_px)),
          MarkFixedPoint(centre[i] + direction * (shift + 0.5 * length_px))};
}

}  // namespace

cv::Mat DrawHandMarks(const StyleLook& look, cv::Size size, const std::vector<TraceTruth>& traces,
                      double px_per_div, std::mt19937_64& random) {
  cv::Mat mark = cv::Mat::zeros(size, CV_8UC1);
  const double scale = size.width / 2000.0;
  const std::array<const char*, 10> words = {"X0=.405", "run 3", "R", "L",    "#12",
                                             "2nd",     "ok",    "?", "5/12", "e=.8"};
  const std::array<int, 3> fonts = {cv::FONT_HERSHEY_SCRIPT_SIMPLEX, cv::FONT_HERSHEY_SIMPLEX,
                                    cv::FONT_HERSHEY_PLAIN};
  for (HandMark kind : look.hand_marks) {
    const cv::Point at(UniformInt(random, 0, size.width - 1),
                       UniformInt(random, 0, size.height - 1));
    // The pen's width varies a little from mark to mark.
    const int thickness = std::max(
        1, static_cast<int>(std::lround(scale * look.mark_width_px * Uniform(random, 0.8, 1.2))));
    const int coverage = UniformInt(random, 160, 255);
    const TraceTruth* trace = nullptr;
    if (kind == HandMark::kAlongTrace || kind == HandMark::kAcrossTrace) {
      trace = TraceToMark(traces, random);
      if (trace == nullptr) kind = HandMark::kUnderline;
    }
    switch (kind) {
      case HandMark::kWord:
        cv::putText(mark, words[UniformInt(random, 0, static_cast<int>(words.size()) - 1)], at,
                    fonts[UniformInt(random, 0, 2)], scale * Uniform(random, 1.5, 4.0),
                    cv::Scalar(coverage), thickness, cv::LINE_AA);
        break;
      case HandMark::kArrow: {
        const double angle = Uniform(random, 0.0, 2.0 * std::numbers::pi);
        const double length = scale * Uniform(random, 80.0, 400.0);
        const cv::Point to(at.x + static_cast<int>(length * std::cos(angle)),
                           at.y + static_cast<int>(length * std::sin(angle)));
        cv::arrowedLine(mark, at, to, cv::Scalar(coverage), thickness, cv::LINE_AA, 0, 0.2);
        break;
      }
      case HandMark::kRing: {
        const cv::Size axes(static_cast<int>(scale * Uniform(random, 30.0, 200.0)),
                            static_cast<int>(scale * Uniform(random, 20.0, 150.0)));
        cv::ellipse(mark, at, axes, Uniform(random, 0.0, 180.0), 0.0, Uniform(random, 270.0, 360.0),
                    cv::Scalar(coverage), thickness, cv::LINE_AA);
        break;
      }
      case HandMark::kUnderline: {  // an underline or a tick, anywhere
        const double angle = Uniform(random, -0.5, 0.5) + (Chance(random, 0.3) ? 1.57 : 0.0);
        const double length = scale * Uniform(random, 60.0, 600.0);
        const cv::Point to(at.x + static_cast<int>(length * std::cos(angle)),
                           at.y + static_cast<int>(length * std::sin(angle)));
        cv::line(mark, at, to, cv::Scalar(coverage), thickness, cv::LINE_AA);
        break;
      }
      case HandMark::kAlongTrace:
      case HandMark::kAcrossTrace: {
        const std::vector<cv::Point> stroke = kind == HandMark::kAlongTrace
                                                  ? StrokeAlongTrace(*trace, px_per_div, random)
                                                  : StrokeAcrossTrace(*trace, px_per_div, random);
        if (stroke.size() >= 2) {
          cv::polylines(mark, stroke, false, cv::Scalar(coverage), thickness, cv::LINE_AA,
                        kMarkShift);
        }
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
    cv::Point2d centre, across;  // `across`: the unit direction of the tape's length
    const int side = UniformInt(random, 0, 3);
    if (Chance(random, 0.6)) {
      // Over a corner, across its diagonal.
      const cv::Point2d corner(side % 2 == 0 ? 0.0 : extent.x, side < 2 ? 0.0 : extent.y);
      const cv::Point2d inward(side % 2 == 0 ? 1.0 : -1.0, side < 2 ? 1.0 : -1.0);
      centre = corner + inward * (size.width * Uniform(random, 0.02, 0.07));
      const double turn = Uniform(random, -0.25, 0.25);
      const cv::Point2d a(-inward.y, inward.x);
      across = cv::Point2d(a.x * std::cos(turn) - a.y * std::sin(turn),
                           a.x * std::sin(turn) + a.y * std::cos(turn)) /
               std::sqrt(2.0);
    } else {
      // Over an edge, at right angles to it, half on the photo.
      const double along = Uniform(random, 0.15, 0.85);
      const std::array<cv::Point2d, 4> points = {
          cv::Point2d(along * extent.x, 0.0), cv::Point2d(extent.x, along * extent.y),
          cv::Point2d(along * extent.x, extent.y), cv::Point2d(0.0, along * extent.y)};
      const std::array<cv::Point2d, 4> inward = {cv::Point2d(0, 1), cv::Point2d(-1, 0),
                                                 cv::Point2d(0, -1), cv::Point2d(1, 0)};
      centre = points[side];
      const double turn = Uniform(random, -0.25, 0.25);
      across = {inward[side].x * std::cos(turn) - inward[side].y * std::sin(turn),
                inward[side].x * std::sin(turn) + inward[side].y * std::cos(turn)};
    }
    const cv::Point2d side_dir(-across.y, across.x);
    // Straight sides; torn ends: a zigzag across the tape's width.
    std::vector<cv::Point> outline;
    for (int end = 0; end < 2; ++end) {
      const double sign = end == 0 ? 1.0 : -1.0;
      constexpr int kTeeth = 7;
      for (int k = 0; k <= kTeeth; ++k) {
        const double s = sign * (-0.5 + static_cast<double>(k) / kTeeth) * width_px;
        const double tear = Uniform(random, -0.12, 0.12) * width_px;
        outline.push_back(
            MarkFixedPoint(centre + across * (sign * 0.5 * length_px + tear) + side_dir * s));
      }
    }
    cv::fillPoly(tape, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255), cv::LINE_AA,
                 kMarkShift);
  }
  cv::GaussianBlur(tape, tape, cv::Size(), 0.6);
  return tape;
}

std::vector<LookFactor> DescribeLook(const StyleLook& look, const cv::Mat& image) {
  std::vector<LookFactor> f;
  auto number = [&f](std::string name, double value) { f.push_back({std::move(name), value, ""}); };
  auto category = [&f](std::string name, std::string value) {
    f.push_back({std::move(name), 0.0, std::move(value)});
  };
  number("width_px", image.cols);
  number("bit_depth", image.depth() == CV_16U ? 16 : 8);
  category("channels", image.channels() == 1 ? "grey" : "colour");
  // A figure reproduced in print is dark ink on light paper, whatever the photo was.
  category("polarity", look.print.halftone ? "negative" : PolarityName(look.development));
  category("development", DevelopmentName(look.development));
  number("jpeg_quality", look.jpeg_quality);  // 0: lossless
  category("surround", look.surround_kind);
  number("fill", look.pose.fill);
  number("rotation_deg", look.pose.rotation_deg);
  number("tilt_deg", look.pose.tilt_deg);
  number("barrel_k1", look.pose.barrel_k1);
  number("blur_px", look.blur_px);
  number("sensor_noise", look.sensor_noise);
  number("grain", look.grain);
  number("sharpen", look.sharpen);
  number("exposure_gain", look.exposure_gain);
  number("tone_gamma", look.tone_gamma);
  number("vignetting", look.vignetting);
  number("light_unevenness", look.light_unevenness);
  number("glare", look.glare);
  std::string phosphor = "other";
  for (std::size_t i = 0; i < kPhosphorBgr.size(); ++i) {
    if (look.screen.phosphor_bgr == kPhosphorBgr[i]) phosphor = kPhosphorNames[i];
  }
  category("phosphor", phosphor);
  number("glow_fraction", look.screen.glow_fraction);
  // The graticule's brightness relative to a slow trace's core (both before the tone curve).
  number("graticule_brightness",
         cv::norm(look.screen.graticule_bgr) / cv::norm(look.screen.phosphor_bgr));
  number("graticule_fwhm_div", look.screen.graticule_sigma_div * 2.354820045);
  category("graticule_ticks", look.screen.graticule_ticks ? "on" : "off");
  number("graticule_missing", static_cast<double>(look.screen.graticule_missing_div.size()));
  number("dust_specks", look.dust_specks);
  number("scratches", look.scratches);
  number("hairs", look.hairs);
  number("hand_marks", static_cast<double>(look.hand_marks.size()));
  number("marks_along_traces",
         static_cast<double>(
             std::count(look.hand_marks.begin(), look.hand_marks.end(), HandMark::kAlongTrace)));
  number("marks_across_traces",
         static_cast<double>(
             std::count(look.hand_marks.begin(), look.hand_marks.end(), HandMark::kAcrossTrace)));
  // The strokes' width in this photo's pixels; 0 without marks.
  number("mark_width_px", look.hand_marks.empty() ? 0.0 : look.mark_width_px * image.cols / 2000.0);
  number("tape", look.tape);
  const PrintLook& print = look.print;
  category("reproduction", print.halftone ? "halftone" : "photo");
  // The print's numbers; 0 for a photo.
  number("halftone_period_px", print.halftone ? print.period_px : 0.0);
  number("halftone_angle_deg", print.halftone ? print.angle_deg : 0.0);
  number("ink_spread", print.halftone ? print.ink_spread : 0.0);
  number("scan_blur_px", print.halftone ? print.scan_blur_px : 0.0);
  return f;
}

}  // namespace impactlab::render
