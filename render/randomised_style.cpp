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
  look.hand_marks = Chance(random, 0.5) ? 0 : UniformInt(random, 1, 4);
  const std::array<cv::Vec3f, 5> pencils = {cv::Vec3f{0.15f, 0.15f, 0.85f},  // red grease pencil
                                            cv::Vec3f{0.95f, 0.95f, 0.95f},  // white
                                            cv::Vec3f{0.2f, 0.85f, 0.95f},   // yellow
                                            cv::Vec3f{0.05f, 0.05f, 0.05f},  // black ink
                                            cv::Vec3f{0.75f, 0.35f, 0.1f}};  // blue ink
  const std::array<const char*, 5> names = {"red", "white", "yellow", "black", "blue"};
  const int pencil = UniformInt(random, 0, 4);
  look.mark_bgr = pencils[pencil];
  look.mark_colour = names[pencil];
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
}

cv::Mat DrawHandMarks(int count, cv::Size size, double width_scale, std::mt19937_64& random) {
  cv::Mat mark = cv::Mat::zeros(size, CV_8UC1);
  const double scale = size.width / 2000.0;
  const std::array<const char*, 10> words = {"X0=.405", "run 3", "R", "L",    "#12",
                                             "2nd",     "ok",    "?", "5/12", "e=.8"};
  const std::array<int, 3> fonts = {cv::FONT_HERSHEY_SCRIPT_SIMPLEX, cv::FONT_HERSHEY_SIMPLEX,
                                    cv::FONT_HERSHEY_PLAIN};
  for (int i = 0; i < count; ++i) {
    const cv::Point at(UniformInt(random, 0, size.width - 1),
                       UniformInt(random, 0, size.height - 1));
    const int thickness =
        std::max(1, static_cast<int>(std::lround(scale * width_scale * Uniform(random, 2.0, 8.0))));
    const int coverage = UniformInt(random, 160, 255);
    switch (UniformInt(random, 0, 3)) {
      case 0:  // a word or a number
        cv::putText(mark, words[UniformInt(random, 0, static_cast<int>(words.size()) - 1)], at,
                    fonts[UniformInt(random, 0, 2)], scale * Uniform(random, 1.5, 4.0),
                    cv::Scalar(coverage), thickness, cv::LINE_AA);
        break;
      case 1: {  // an arrow pointing at something
        const double angle = Uniform(random, 0.0, 2.0 * std::numbers::pi);
        const double length = scale * Uniform(random, 80.0, 400.0);
        const cv::Point to(at.x + static_cast<int>(length * std::cos(angle)),
                           at.y + static_cast<int>(length * std::sin(angle)));
        cv::arrowedLine(mark, at, to, cv::Scalar(coverage), thickness, cv::LINE_AA, 0, 0.2);
        break;
      }
      case 2: {  // a ring round a feature
        const cv::Size axes(static_cast<int>(scale * Uniform(random, 30.0, 200.0)),
                            static_cast<int>(scale * Uniform(random, 20.0, 150.0)));
        cv::ellipse(mark, at, axes, Uniform(random, 0.0, 180.0), 0.0, Uniform(random, 270.0, 360.0),
                    cv::Scalar(coverage), thickness, cv::LINE_AA);
        break;
      }
      default: {  // an underline or a tick across
        const double angle = Uniform(random, -0.5, 0.5) + (Chance(random, 0.3) ? 1.57 : 0.0);
        const double length = scale * Uniform(random, 60.0, 600.0);
        const cv::Point to(at.x + static_cast<int>(length * std::cos(angle)),
                           at.y + static_cast<int>(length * std::sin(angle)));
        cv::line(mark, at, to, cv::Scalar(coverage), thickness, cv::LINE_AA);
        break;
      }
    }
  }
  cv::GaussianBlur(mark, mark, cv::Size(), 0.7);
  return mark;
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
  category("polarity", look.handling.print.halftone ? "negative" : PolarityName(look.development));
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
  // Handling (handling.cpp): every mark, the look's written anywhere and the
  // handling's about a trace, and the pencil they share.
  const HandlingLook& handling = look.handling;
  const auto marks = [&handling](TraceMark kind) {
    return static_cast<double>(
        std::count(handling.trace_marks.begin(), handling.trace_marks.end(), kind));
  };
  const double all_marks = look.hand_marks + static_cast<double>(handling.trace_marks.size());
  number("hand_marks", all_marks);
  number("marks_along_traces", marks(TraceMark::kAlong));
  number("marks_across_traces", marks(TraceMark::kAcross));
  number("rings_on_traces", marks(TraceMark::kRing));
  number("arrows_at_traces", marks(TraceMark::kArrow));
  number("labels_by_traces", marks(TraceMark::kLabel));
  // The pencil's stroke in this photo's pixels, and its colour; 0 and "none" without marks.
  number("mark_width_px", all_marks == 0 ? 0.0 : handling.mark_width_px * image.cols / 2000.0);
  category("mark_colour", all_marks == 0 ? "none" : look.mark_colour);
  number("tape", handling.tape);
  const PrintLook& print = handling.print;
  category("reproduction", print.halftone ? "halftone" : "photo");
  // The print's numbers; 0 for a photo.
  number("halftone_period_px", print.halftone ? print.period_px : 0.0);
  number("halftone_angle_deg", print.halftone ? print.angle_deg : 0.0);
  number("ink_spread", print.halftone ? print.ink_spread : 0.0);
  number("paper_tone", print.halftone ? print.paper_tone : 0.0);
  number("scan_blur_px", print.halftone ? print.scan_blur_px : 0.0);
  number("scan_skew_deg", print.halftone ? print.skew_deg : 0.0);
  return f;
}

}  // namespace impactlab::render
