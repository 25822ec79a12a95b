// RenderOscillograph: lays out the beams, draws the flat screen, photographs
// it through the style's camera and develops the photo.
#include "render/oscillograph.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "render/beam.h"
#include "render/camera.h"
#include "render/digital_screen.h"
#include "render/photo.h"
#include "render/screen.h"
#include "render/styles.h"

namespace impactlab {

namespace {

constexpr std::array<std::pair<PhotoStyle, std::string_view>, 7> kStyleNames = {{
    {PhotoStyle::kClean, "clean"},
    {PhotoStyle::kPolaroid, "polaroid"},
    {PhotoStyle::kPhone, "phone"},
    {PhotoStyle::kNegative, "negative"},
    {PhotoStyle::kLowres, "lowres"},
    {PhotoStyle::kRandomised, "randomised"},
    {PhotoStyle::kDigital, "digital"},
}};

bool Fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

void CheckScene(const OscillographScene& scene) {
  auto fail = [](const std::string& message) {
    throw std::invalid_argument("oscillograph scene: " + message);
  };
  for (const int d : scene.divisions) {
    if (d < 1 || d > 100) fail(fmt::format("divisions must be 1..100, got {}", d));
  }
  for (const ScreenTrace& trace : scene.traces) {
    const TraceSettings& s = trace.settings;
    if (trace.time_s.size() != trace.volts.size()) {
      fail(fmt::format("trace '{}' has {} times but {} voltages", trace.name, trace.time_s.size(),
                       trace.volts.size()));
    }
    if (!(s.time_per_div > 0.0) || !std::isfinite(s.time_per_div)) {
      fail(fmt::format("trace '{}': time_per_div must be positive, got {}", trace.name,
                       s.time_per_div));
    }
    if (s.volts_per_div == 0.0 || !std::isfinite(s.volts_per_div) || !std::isfinite(s.zero_div) ||
        !std::isfinite(s.t0_div)) {
      fail(fmt::format("trace '{}': volts_per_div must be non-zero and the settings finite",
                       trace.name));
    }
    if (!(trace.brightness > 0.0 && trace.brightness <= 100.0)) {
      fail(fmt::format("trace '{}': brightness must lie in (0, 100], got {}", trace.name,
                       trace.brightness));
    }
    for (std::size_t i = 0; i < trace.time_s.size(); ++i) {
      if (!std::isfinite(trace.time_s[i]) || !std::isfinite(trace.volts[i])) {
        fail(fmt::format("trace '{}': sample {} is not finite", trace.name, i));
      }
      if (i > 0 && trace.time_s[i] < trace.time_s[i - 1]) {
        fail(fmt::format("trace '{}': time decreases at sample {} ({} s after {} s)", trace.name, i,
                         trace.time_s[i], trace.time_s[i - 1]));
      }
    }
  }
}

}  // namespace

std::string_view PhotoStyleName(PhotoStyle style) {
  for (const auto& [value, name] : kStyleNames) {
    if (value == style) return name;
  }
  return "unknown";
}

std::optional<PhotoStyle> ParsePhotoStyle(std::string_view name) {
  for (const auto& [value, style_name] : kStyleNames) {
    if (style_name == name) return value;
  }
  return std::nullopt;
}

bool RenderOptions::Check(std::string* error) const {
  if (width_px != 0 && (width_px < 200 || width_px > 8000)) {
    return Fail(error, fmt::format("width_px must be 0 or 200..8000, got {}", width_px));
  }
  if (rotation_deg && !(std::abs(*rotation_deg) <= 15.0)) {
    return Fail(error, fmt::format("rotation_deg must lie in [-15, 15], got {}", *rotation_deg));
  }
  if (tilt_deg && !(*tilt_deg >= 0.0 && *tilt_deg <= 35.0)) {
    return Fail(error, fmt::format("tilt_deg must lie in [0, 35], got {}", *tilt_deg));
  }
  if (barrel_k1 && !(std::abs(*barrel_k1) <= 0.3)) {
    return Fail(error, fmt::format("barrel_k1 must lie in [-0.3, 0.3], got {}", *barrel_k1));
  }
  if (blur_px && !(*blur_px >= 0.0 && *blur_px <= 20.0)) {
    return Fail(error, fmt::format("blur_px must lie in [0, 20], got {}", *blur_px));
  }
  if (jpeg_quality && (*jpeg_quality < 0 || *jpeg_quality > 100)) {
    return Fail(error, fmt::format("jpeg_quality must lie in [0, 100], got {}", *jpeg_quality));
  }
  if (!(beam_fwhm_div > 0.0 && beam_fwhm_div <= 0.5)) {
    return Fail(error, fmt::format("beam_fwhm_div must lie in (0, 0.5], got {}", beam_fwhm_div));
  }
  if (!(chop_dash_div > 0.0 && chop_dash_div <= 10.0)) {
    return Fail(error, fmt::format("chop_dash_div must lie in (0, 10], got {}", chop_dash_div));
  }
  if (!(chop_duty > 0.0 && chop_duty <= 1.0)) {
    return Fail(error, fmt::format("chop_duty must lie in (0, 1], got {}", chop_duty));
  }
  if (!std::isfinite(chop_phase_div)) {
    return Fail(error, fmt::format("chop_phase_div must be finite, got {}", chop_phase_div));
  }
  return true;
}

namespace {

// Tape and the handling's trace marks, from the handling's own stream, laid
// with the look's dirt: the marks in the same pencil as the look's own.
void AddHandling(const render::StyleLook& look, cv::Size size,
                 const std::vector<TraceTruth>& traces, double px_per_div, std::mt19937_64& random,
                 render::Dirt& dirt) {
  const render::HandlingLook& handling = look.handling;
  if (handling.tape > 0) dirt.tape = render::DrawTape(handling.tape, size, random);
  const cv::Mat marks = render::DrawTraceMarks(handling, size, traces, px_per_div, random);
  if (marks.empty()) return;
  if (dirt.mark.empty()) {
    dirt.mark = marks;
  } else {
    cv::max(dirt.mark, marks, dirt.mark);
  }
}

// Points on the graticule's lines, between their crossings, in the photo:
// where a print's tones are set from.
std::vector<cv::Point2d> GridLinePoints(const CameraMapping& mapping, const cv::Rect2d& g) {
  std::vector<cv::Point2d> points;
  for (int i = 0; i <= static_cast<int>(std::lround(g.width)); ++i) {
    for (double y = g.y + 0.25; y < g.br().y; y += 0.5) {
      points.push_back(mapping.ImageFromScreen({g.x + i, y}));
    }
  }
  for (int j = 0; j <= static_cast<int>(std::lround(g.height)); ++j) {
    for (double x = g.x + 0.25; x < g.br().x; x += 0.5) {
      points.push_back(mapping.ImageFromScreen({x, g.y + j}));
    }
  }
  return points;
}

}  // namespace

RenderedPhoto RenderOscillograph(const OscillographScene& scene, const RenderOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("render options: " + error);
  }
  CheckScene(scene);
  if (options.style == PhotoStyle::kDigital) return render::RenderDigitalScreen(scene, options);

  std::mt19937_64 random(options.seed);
  std::mt19937_64 handling_random = render::HandlingStream(options.seed);
  const render::ScreenLayout layout = render::LayOutScreen(scene.divisions);
  const render::StyleLook look = render::DrawStyleLook(options, layout, random, handling_random);
  const cv::Size size = render::PhotoSize(look);

  RenderedPhoto photo;
  photo.mapping = render::FrameCamera(look.pose, look.framed_outline_div, layout.centre_div, size);

  std::vector<render::TraceBeam> beams =
      render::LayOutBeams(scene, {options.chop_dash_div, options.chop_duty, options.chop_phase_div},
                          layout.graticule_div, layout.face_div);
  for (render::TraceBeam& beam : beams) {
    for (const cv::Point2d& p : beam.truth.screen_div) {
      beam.truth.centre_px.push_back(photo.mapping.ImageFromScreen(p));
    }
    photo.traces.push_back(std::move(beam.truth));
  }

  // The flat screen at the photo's finest scale, so that looking it up from
  // the photo only ever shrinks it; the camera's blur goes with it.
  const double canvas_px_per_div = render::MaxPixelsPerDivision(photo.mapping, layout.face_div);
  const double canvas_blur_px = look.blur_px * canvas_px_per_div /
                                render::PixelsPerDivisionAt(photo.mapping, layout.centre_div);
  const render::PhosphorCanvas phosphor =
      render::RenderPhosphor(layout, beams, look.screen, canvas_px_per_div, canvas_blur_px);
  render::Dirt dirt = render::DrawDirt(look, size, random);
  const double px_per_div = render::PixelsPerDivisionAt(photo.mapping, layout.centre_div);
  AddHandling(look, size, photo.traces, px_per_div, handling_random, dirt);
  if (look.handling.print.halftone) {
    // The photograph as the report's printer had it (grey, 8 bits, without
    // what was later laid on the printed page), then printed and scanned.
    render::StyleLook original = look;
    original.grey = true;
    original.sixteen_bit = false;
    original.jpeg_quality = 0;
    render::Dirt on_photo = dirt;
    on_photo.tape = cv::Mat();
    on_photo.mark = cv::Mat();
    const cv::Mat developed =
        render::Photograph(phosphor, layout, original, photo.mapping, on_photo, random);
    // The caption 0.8 division under the graticule, along its bottom line.
    const cv::Rect2d& g = layout.graticule_div;
    const cv::Point2d caption_div(g.x + 0.5 * g.width, g.y - 0.8);
    const cv::Point2d caption_px = photo.ImageFromScreen(caption_div);
    photo.image = render::ReproduceInPrint(
        look, developed, GridLinePoints(photo.mapping, g), caption_px,
        photo.ImageFromScreen(caption_div + cv::Point2d(1.0, 0.0)) - caption_px, 0.3 * px_per_div,
        dirt, handling_random);
  } else {
    photo.image = render::Photograph(phosphor, layout, look, photo.mapping, dirt, random);
  }
  render::FinishPhoto(look, photo.image);
  photo.jpeg_quality = look.jpeg_quality;
  if (options.style == PhotoStyle::kRandomised)
    photo.look = render::DescribeLook(look, photo.image);
  return photo;
}

}  // namespace impactlab
