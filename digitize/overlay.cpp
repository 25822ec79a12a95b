// DrawOverlay: what the digitizer found, drawn on the photo so that a person
// can judge it: the fitted graticule (curved where the radial term bends it),
// each trace's band, its centre line (bright where confident, dim where not),
// the contact pulse's edges, and a legend; plus magnified insets of the
// pulse's edges, where a pixel's error matters most.
//
// A report shows the overlay far smaller than the photo, so it is drawn
// directly at its output size, every mark placed and sized for it: copying
// the full photo twice to draw on it, then shrinking it, cost about as much
// as the digitizing itself. The insets are cut from the photo itself and keep
// its own pixels at any output size.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "digitize/grey_ink.h"

namespace impactlab {

namespace {

// Trace colours (BGR), chosen to stand apart from green phosphor and grey prints.
const cv::Scalar kTraceColours[] = {{60, 60, 255}, {255, 120, 40}, {0, 200, 255}, {255, 60, 255}};
const cv::Scalar kGridColour(255, 255, 0);
const cv::Scalar kEdgeColour(0, 255, 255);
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kFailureColour(80, 80, 255);
constexpr std::size_t kFailureLineChars = 90;

// `text` broken at spaces into lines of at most `width` characters (a longer
// word stands alone).
std::vector<std::string> WrappedWords(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t space = text.find(' ', at);
    const std::string word = text.substr(at, space == std::string::npos ? space : space - at);
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    if (space == std::string::npos) break;
    at = space + 1;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

// The 8-bit BGR pixels of `image` in a Mat of their own: they are drawn on,
// and must never be the photo's.
cv::Mat EightBitColour(const cv::Mat& image) {
  cv::Mat eight = image;
  if (image.depth() == CV_16U) image.convertTo(eight, CV_8U, 1.0 / 257.0);
  cv::Mat out;
  if (eight.channels() == 1) {
    cv::cvtColor(eight, out, cv::COLOR_GRAY2BGR);
  } else if (eight.channels() == 4) {
    cv::cvtColor(eight, out, cv::COLOR_BGRA2BGR);
  } else {
    out = eight.data == image.data ? image.clone() : eight;
  }
  return out;
}

// The photo shrunk by the whole factor `f`, 8-bit BGR. A whole factor is a
// plain block average (15x cheaper than a fractional shrink of a colour
// photo, and the working copy's own shrink: half OpenCV's time), and only
// the small result is converted. The last f - 1 columns and rows at most
// are left out.
cv::Mat ScaledBackground(const cv::Mat& photo, int f) {
  if (f == 1) return EightBitColour(photo);
  const cv::Mat small = digitize::ShrunkByArea(photo, f);
  return small.type() == CV_8UC3 ? small : EightBitColour(small);
}

// An image drawn on, and where the photo's points fall in it: the overlay
// (the photo scaled) or an inset's crop (the photo's own pixels, shifted).
struct Canvas {
  cv::Mat image;
  double scale_x = 1.0, scale_y = 1.0;  // canvas pixels per photo pixel
  cv::Point2d origin;                   // photo point at the canvas's (0, 0) when unscaled

  // Pixel centres lie at whole coordinates in both, as area resampling has them.
  cv::Point2d FromPhoto(cv::Point2d p) const {
    return {(p.x - origin.x + 0.5) * scale_x - 0.5, (p.y - origin.y + 0.5) * scale_y - 0.5};
  }
  // A length given in photo pixels (a margin, an offset), at least a pixel.
  int Px(double photo_px) const {
    return std::max(1, static_cast<int>(std::lround(photo_px * scale_x)));
  }
};

// The smallest whole shrink factor that brings the photo within
// `max_width_px` (0: none).
Canvas OverlayCanvas(const cv::Mat& photo, int max_width_px) {
  const int f = max_width_px > 0 ? std::max(1, (photo.cols + max_width_px - 1) / max_width_px) : 1;
  Canvas canvas;
  canvas.image = ScaledBackground(photo, f);
  canvas.scale_x = canvas.scale_y = 1.0 / f;
  return canvas;
}

// cv drawing in fixed point with 4 fractional bits: sub-pixel positions.
constexpr int kShift = 4;
cv::Point Fixed(cv::Point2d p) {
  return {cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift))};
}

void DrawScreenCurve(Canvas& canvas, const GraticuleMapping& mapping, cv::Point2d from,
                     cv::Point2d to, const cv::Scalar& colour) {
  constexpr int kSteps = 40;
  std::vector<cv::Point> points;
  for (int i = 0; i <= kSteps; ++i) {
    const cv::Point2d screen = from + (to - from) * (static_cast<double>(i) / kSteps);
    points.push_back(Fixed(canvas.FromPhoto(mapping.ImageFromScreen(screen))));
  }
  cv::polylines(canvas.image, points, false, colour, 1, cv::LINE_AA, kShift);
}

// A straight mark between two photo points: drawn on the overlay and again,
// at the photo's own resolution, in the insets.
struct Mark {
  cv::Point2d from, to;
  cv::Scalar colour;
};

void DrawMarks(Canvas& canvas, const std::vector<Mark>& marks) {
  for (const Mark& m : marks) {
    cv::line(canvas.image, Fixed(canvas.FromPhoto(m.from)), Fixed(canvas.FromPhoto(m.to)), m.colour,
             1, cv::LINE_AA, kShift);
  }
}

// `font_scale` is the canvas's own; the dark halo that keeps text legible on
// any photo shrinks with the canvas, as it would were the photo drawn on. The
// halo is drawn without anti-aliasing: its edges lie on dark, where no one
// sees them, and thick anti-aliased strokes cost 3x the rest of the text.
void DrawText(Canvas& canvas, const std::string& text, cv::Point at, double font_scale,
              const cv::Scalar& colour) {
  const int thickness = std::max(1, static_cast<int>(std::lround(font_scale * 1.5)));
  const int halo = canvas.Px(2.0);
  cv::putText(canvas.image, text, at, cv::FONT_HERSHEY_SIMPLEX, font_scale, cv::Scalar(0, 0, 0),
              thickness + halo, cv::LINE_8);
  cv::putText(canvas.image, text, at, cv::FONT_HERSHEY_SIMPLEX, font_scale, colour, thickness,
              cv::LINE_AA);
}

void DrawGraticule(Canvas& canvas, const GraticuleFit& g) {
  const int nx = g.divisions[0], ny = g.divisions[1];
  const double half = 0.5 * ny;
  for (int i = 0; i <= nx; ++i) {
    DrawScreenCurve(canvas, g.mapping, {double(i), -half}, {double(i), half}, kGridColour);
  }
  for (int j = 0; j <= ny; ++j) {
    DrawScreenCurve(canvas, g.mapping, {0.0, j - half}, {double(nx), j - half}, kGridColour);
  }
}

// The band's edges, dashed.
void DrawBand(Canvas& canvas, const GraticuleFit& g, const DigitizedTrace& trace,
              const cv::Scalar& colour) {
  const double nx = g.divisions[0];
  for (const double y : trace.settings.band_div) {
    for (double x = 0.0; x < nx; x += 0.25) {
      DrawScreenCurve(canvas, g.mapping, {x, y}, {std::min(x + 0.125, nx), y}, colour);
    }
  }
}

// Consecutive samples are joined unless a gap lies between them (a few pixels
// along the sweep, or a jump such as a step's edge, where no sample was
// taken): gaps stay gaps.
std::vector<Mark> CentreLine(const GraticuleFit& g, const DigitizedTrace& trace,
                             const cv::Scalar& colour) {
  const double join_div = 4.0 / g.px_per_div;
  const double join_px = std::max(4.0, 2.0 * trace.width_px);
  std::vector<Mark> marks;
  for (std::size_t i = 0; i + 1 < trace.centre_px.size(); ++i) {
    const cv::Point2d a = trace.centre_px[i], b = trace.centre_px[i + 1];
    if (trace.screen_div[i + 1].x - trace.screen_div[i].x > join_div) continue;
    if (cv::norm(b - a) > join_px) continue;
    const double confidence = std::min(trace.confidence[i], trace.confidence[i + 1]);
    marks.push_back({a, b, colour * (0.35 + 0.65 * confidence)});
  }
  return marks;
}

// A pulse edge's crossing, shown magnified in an inset.
struct LabelledPoint {
  cv::Point2d photo_px;
  std::string label;
};

// The pulse's edges at half height (a line across each and a circle at the
// crossing) and its width above its middle. The crossings go to `edges`; the
// ticks beside them, clear of the stroke, to `inset_marks`.
void DrawPulse(Canvas& canvas, const GraticuleMapping& mapping, const DigitizedTrace& trace,
               const ContactPulseFit& fit, double text_scale, std::vector<Mark>& inset_marks,
               std::vector<LabelledPoint>& edges) {
  const ContactPulse& pulse = fit.pulse;
  const TraceSettings& s = trace.settings;
  auto y_of = [&](double volts) { return s.zero_div + volts / s.volts_per_div; };
  const std::pair<const PulseEdgeInPhoto*, double> both[] = {{&fit.rise, pulse.rise_s.value},
                                                             {&fit.fall, pulse.fall_s.value}};
  for (const auto& [edge, time_s] : both) {
    const double x = s.t0_div + time_s / s.time_per_div;
    DrawScreenCurve(canvas, mapping, {x, y_of(pulse.low_volts) - 0.3},
                    {x, y_of(pulse.high_volts) + 0.3}, kEdgeColour);
    cv::circle(canvas.image, Fixed(canvas.FromPhoto(edge->centre_px)),
               cvRound(6.0 * canvas.scale_x * (1 << kShift)), kEdgeColour, 1, cv::LINE_AA, kShift);
    const cv::Point2d up =
        mapping.ImageFromScreen({x, y_of(0.5 * (pulse.low_volts + pulse.high_volts))});
    const cv::Point2d side =
        mapping.ImageFromScreen({x + 0.05, 0.0}) - mapping.ImageFromScreen({x, 0.0});
    inset_marks.push_back({up + side, up + side * 0.4, kEdgeColour});
    inset_marks.push_back({up - side, up - side * 0.4, kEdgeColour});
    edges.push_back({edge->centre_px, edge == &fit.rise ? "rise" : "fall"});
  }
  const double middle_x =
      s.t0_div + 0.5 * (pulse.rise_s.value + pulse.fall_s.value) / s.time_per_div;
  const std::string text = fmt::format("{}: {:.2f} +- {:.2f} us", trace.name,
                                       pulse.width_s.value * 1e6, pulse.width_s.sigma * 1e6);
  const double scale = 0.6 * text_scale;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 2, &baseline);
  const cv::Point2d centre = canvas.FromPhoto(mapping.ImageFromScreen(
      {middle_x, std::max(y_of(pulse.high_volts), y_of(pulse.low_volts)) + 0.2}));
  const int margin = canvas.Px(4.0);
  const cv::Point at(
      std::clamp(static_cast<int>(centre.x) - size.width / 2, margin,
                 std::max(margin, canvas.image.cols - size.width - margin)),
      std::clamp(static_cast<int>(centre.y), size.height + margin, canvas.image.rows - margin));
  DrawText(canvas, text, at, scale, kEdgeColour);
}

// The status lines, top left, on a dark panel of their own: on a print's
// light border or a bright screen coloured text would not read.
void DrawLegend(Canvas& canvas, const DigitizeResult& result, double text_scale) {
  const GraticuleFit& g = result.graticule;
  const double scale = 0.5 * text_scale;
  std::vector<std::pair<std::string, cv::Scalar>> lines;
  if (result.graticule_found) {
    lines.emplace_back(
        fmt::format("graticule {}x{}: residual {:.3f} px RMS ({} line samples), {:.1f} px/div{}",
                    g.divisions[0], g.divisions[1], g.residual_px, g.samples_used, g.px_per_div,
                    g.radial_fitted ? fmt::format(", k1 {:.4f}", g.mapping.radial_k1) : ""),
        kGridColour);
  }
  if (!result.ok) {
    // Why the photo was not read, in lines a photo's width can hold.
    for (const std::string& line : WrappedWords("not read: " + result.reason, kFailureLineChars)) {
      lines.emplace_back(line, kFailureColour);
    }
  }
  for (std::size_t t = 0; t < result.traces.size(); ++t) {
    const DigitizedTrace& trace = result.traces[t];
    lines.emplace_back(
        fmt::format("{}: {} samples, {:.0f} % of the sweep, scatter {:.2f} px, {} outliers",
                    trace.name, trace.trace.time_s.size(), 100.0 * trace.coverage, trace.noise_px,
                    trace.outliers),
        kTraceColours[t % std::size(kTraceColours)]);
  }
  const int thickness = std::max(1, static_cast<int>(std::lround(scale * 1.5)));
  int baseline = 0, widest = 0;
  const int text_height =
      cv::getTextSize("Ag", cv::FONT_HERSHEY_SIMPLEX, scale, thickness, &baseline).height;
  for (const auto& [text, colour] : lines) {
    widest = std::max(
        widest, cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, thickness, &baseline).width);
  }
  const int pad = std::max(3, text_height / 2);
  const int line_height = text_height + baseline + pad;
  const cv::Rect panel =
      cv::Rect(0, 0, widest + 2 * pad, static_cast<int>(lines.size()) * line_height + pad) &
      cv::Rect(0, 0, canvas.image.cols, canvas.image.rows);
  // Darkened, not blacked out: the photo's corner still shows through.
  canvas.image(panel) *= 0.2;
  int y = pad + text_height;
  for (const auto& [text, colour] : lines) {
    // Light tints of the marks' colours: the same hue, readable on dark.
    const cv::Scalar tint = 0.5 * colour + cv::Scalar(127, 127, 127);
    cv::putText(canvas.image, text, {pad, y}, cv::FONT_HERSHEY_SIMPLEX, scale, tint, thickness,
                cv::LINE_AA);
    y += line_height;
  }
}

// `region` of the photo itself, with only `marks` drawn in (at the photo's
// resolution), magnified `zoom` times and pasted at `at` (top left) in `canvas`.
void Inset(const cv::Mat& photo, cv::Rect region, double zoom, const std::vector<Mark>& marks,
           cv::Point at, Canvas& canvas, const std::string& label) {
  region &= cv::Rect(0, 0, photo.cols, photo.rows);
  if (region.area() == 0) return;
  Canvas crop;
  crop.image = EightBitColour(photo(region));
  crop.origin = region.tl();
  DrawMarks(crop, marks);
  cv::Mat zoomed;
  cv::resize(crop.image, zoomed, cv::Size(), zoom, zoom, cv::INTER_NEAREST);
  cv::Rect target(at, zoomed.size());
  target &= cv::Rect(0, 0, canvas.image.cols, canvas.image.rows);
  if (target.area() == 0) return;
  zoomed(cv::Rect(0, 0, target.width, target.height)).copyTo(canvas.image(target));
  cv::rectangle(canvas.image, target, kWhite, 1);
  DrawText(canvas, label, target.tl() + cv::Point(canvas.Px(4.0), canvas.Px(16.0)),
           0.45 * canvas.scale_x, kWhite);
}

// The insets, bottom right, laid out as on the full-size photo and scaled
// with the canvas; but an inset always magnifies at least twice, showing
// less around the edge on a small canvas rather than losing the photo's pixels.
void DrawInsets(Canvas& canvas, const cv::Mat& photo, const std::vector<LabelledPoint>& edges,
                const std::vector<Mark>& marks) {
  const int inset_px = std::max(40, photo.cols / 40);
  const double full_size_zoom = std::clamp(photo.cols / 8.0 / inset_px, 2.0, 8.0);
  const double zoom = std::max(2.0, full_size_zoom * canvas.scale_x);
  const int crop_px =
      std::max(1, static_cast<int>(std::lround(inset_px * full_size_zoom * canvas.scale_x / zoom)));
  const int side = static_cast<int>(crop_px * zoom);
  const int margin = canvas.Px(10.0);
  int x = canvas.image.cols - margin;
  for (auto it = edges.rbegin(); it != edges.rend(); ++it) {
    const cv::Rect region(static_cast<int>(it->photo_px.x) - crop_px / 2,
                          static_cast<int>(it->photo_px.y) - crop_px / 2, crop_px, crop_px);
    x -= side + margin;
    Inset(photo, region, zoom, marks, {x, canvas.image.rows - side - margin}, canvas, it->label);
  }
}

// What was taken for hand marks, outlined in magenta (a colour no trace is
// drawn in), so that a person sees what the traces were kept from.
void DrawHandMarkOutlines(Canvas& canvas, const std::vector<std::vector<cv::Point>>& outlines) {
  const cv::Scalar magenta(255, 0, 255);
  for (const std::vector<cv::Point>& outline : outlines) {
    std::vector<cv::Point> points;
    for (const cv::Point& p : outline) points.push_back(Fixed(canvas.FromPhoto(p)));
    cv::polylines(canvas.image, points, true, magenta, 1, cv::LINE_AA, kShift);
  }
}

}  // namespace

bool OverlayOptions::Check(std::string* error) const {
  if (max_width_px < 0) {
    if (error) *error = fmt::format("max_width_px must be 0 or positive, got {}", max_width_px);
    return false;
  }
  return true;
}

cv::Mat DrawOverlay(const Photo& photo, const DigitizeResult& result,
                    const OverlayOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("overlay options: " + error);
  }
  Canvas canvas = OverlayCanvas(photo.image, options.max_width_px);
  // Text is sized for the photo (larger on a large one), then shrunk with it.
  const double text_scale = std::max(1.0, photo.image.cols / 1600.0) * canvas.scale_x;
  const GraticuleFit& g = result.graticule;
  if (result.graticule_found) DrawGraticule(canvas, g);

  // The insets show the photo itself with only the centre lines and the
  // pulse edges' ticks.
  std::vector<Mark> inset_marks;
  for (std::size_t t = 0; t < result.traces.size(); ++t) {
    const cv::Scalar colour = kTraceColours[t % std::size(kTraceColours)];
    DrawBand(canvas, g, result.traces[t], colour);
    const std::vector<Mark> centre = CentreLine(g, result.traces[t], colour);
    DrawMarks(canvas, centre);
    inset_marks.insert(inset_marks.end(), centre.begin(), centre.end());
  }

  std::vector<LabelledPoint> edges;
  for (std::size_t t = 0; t < result.traces.size() && t < result.pulses.size(); ++t) {
    if (!result.pulses[t]) continue;
    DrawPulse(canvas, g.mapping, result.traces[t], *result.pulses[t], text_scale, inset_marks,
              edges);
  }
  DrawHandMarkOutlines(canvas, result.mark_outlines_px);
  DrawLegend(canvas, result, text_scale);
  DrawInsets(canvas, photo.image, edges, inset_marks);
  return canvas.image;
}

}  // namespace impactlab
