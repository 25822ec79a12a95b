// DrawOverlay: what the digitizer found, drawn on the photo so that a person
// can judge it: the fitted graticule (curved where the radial term bends it),
// each trace's band, its centre line (bright where confident, dim where not),
// the contact pulse's edges, and a legend; plus magnified insets of the
// pulse's edges, where a pixel's error matters most.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"

namespace impactlab {

namespace {

// Trace colours (BGR), chosen to stand apart from green phosphor and grey prints.
const cv::Scalar kTraceColours[] = {{60, 60, 255}, {255, 120, 40}, {0, 200, 255}, {255, 60, 255}};
const cv::Scalar kGridColour(255, 255, 0);
const cv::Scalar kEdgeColour(0, 255, 255);

cv::Mat EightBitColour(const cv::Mat& image) {
  cv::Mat out;
  if (image.depth() == CV_16U) {
    image.convertTo(out, CV_8U, 1.0 / 257.0);
  } else {
    out = image.clone();
  }
  if (out.channels() == 1) cv::cvtColor(out, out, cv::COLOR_GRAY2BGR);
  if (out.channels() == 4) cv::cvtColor(out, out, cv::COLOR_BGRA2BGR);
  return out;
}

// cv drawing in fixed point with 4 fractional bits: sub-pixel positions.
constexpr int kShift = 4;
cv::Point Fixed(cv::Point2d p) {
  return {cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift))};
}

void DrawScreenCurve(cv::Mat& image, const GraticuleMapping& mapping, cv::Point2d from,
                     cv::Point2d to, const cv::Scalar& colour, int thickness) {
  constexpr int kSteps = 40;
  std::vector<cv::Point> points;
  for (int i = 0; i <= kSteps; ++i) {
    points.push_back(
        Fixed(mapping.ImageFromScreen(from + (to - from) * (static_cast<double>(i) / kSteps))));
  }
  cv::polylines(image, points, false, colour, thickness, cv::LINE_AA, kShift);
}

void DrawText(cv::Mat& image, const std::string& text, cv::Point at, double scale,
              const cv::Scalar& colour) {
  const int thickness = std::max(1, static_cast<int>(std::lround(scale * 1.5)));
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), thickness + 2,
              cv::LINE_AA);
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, thickness, cv::LINE_AA);
}

// A magnified view of `region` of the photo with the overlay's marks, pasted
// at `at` (top left) in `canvas`.
void Inset(const cv::Mat& photo_with_marks, cv::Rect region, double zoom, cv::Point at,
           cv::Mat& canvas, const std::string& label) {
  region &= cv::Rect(0, 0, photo_with_marks.cols, photo_with_marks.rows);
  if (region.area() == 0) return;
  cv::Mat zoomed;
  cv::resize(photo_with_marks(region), zoomed, cv::Size(), zoom, zoom, cv::INTER_NEAREST);
  cv::Rect target(at, zoomed.size());
  target &= cv::Rect(0, 0, canvas.cols, canvas.rows);
  if (target.area() == 0) return;
  zoomed(cv::Rect(0, 0, target.width, target.height)).copyTo(canvas(target));
  cv::rectangle(canvas, target, cv::Scalar(255, 255, 255), 1);
  DrawText(canvas, label, target.tl() + cv::Point(4, 16), 0.45, cv::Scalar(255, 255, 255));
}

}  // namespace

cv::Mat DrawOverlay(const Photo& photo, const DigitizeResult& result) {
  cv::Mat image = EightBitColour(photo.image);
  // The insets show the photo itself with only the traces' centre lines.
  cv::Mat for_insets = image.clone();
  const GraticuleFit& g = result.graticule;
  const GraticuleMapping& mapping = g.mapping;
  const int nx = g.divisions[0], ny = g.divisions[1];
  const double half = 0.5 * ny;

  // The fitted graticule.
  for (int i = 0; i <= nx; ++i) {
    DrawScreenCurve(image, mapping, {double(i), -half}, {double(i), half}, kGridColour, 1);
  }
  for (int j = 0; j <= ny; ++j) {
    DrawScreenCurve(image, mapping, {0.0, j - half}, {double(nx), j - half}, kGridColour, 1);
  }

  // Bands (dashed) and centre lines.
  for (std::size_t t = 0; t < result.traces.size(); ++t) {
    const DigitizedTrace& trace = result.traces[t];
    const cv::Scalar colour = kTraceColours[t % std::size(kTraceColours)];
    for (const double y : trace.settings.band_div) {
      for (double x = 0.0; x < nx; x += 0.25) {
        DrawScreenCurve(image, mapping, {x, y}, {std::min(x + 0.125, double(nx)), y}, colour, 1);
      }
    }
    // Consecutive samples are joined unless a gap lies between them (a few
    // pixels along the sweep, or a jump such as a step's edge, where no sample
    // was taken): gaps stay gaps.
    const double join_div = 4.0 / g.px_per_div;
    const double join_px = std::max(4.0, 2.0 * trace.width_px);
    for (std::size_t i = 0; i + 1 < trace.centre_px.size(); ++i) {
      const cv::Point2d a = trace.centre_px[i], b = trace.centre_px[i + 1];
      if (trace.screen_div[i + 1].x - trace.screen_div[i].x > join_div) continue;
      if (cv::norm(b - a) > join_px) continue;
      const double confidence = std::min(trace.confidence[i], trace.confidence[i + 1]);
      const cv::Scalar shade = colour * (0.35 + 0.65 * confidence);
      cv::line(image, Fixed(a), Fixed(b), shade, 1, cv::LINE_AA, kShift);
      cv::line(for_insets, Fixed(a), Fixed(b), shade, 1, cv::LINE_AA, kShift);
    }
  }

  // Contact pulses: the edges at half height, and the width.
  std::vector<std::pair<cv::Point2d, std::string>> edges;
  for (std::size_t t = 0; t < result.traces.size(); ++t) {
    if (t >= result.pulses.size() || !result.pulses[t]) continue;
    const ContactPulseFit& pulse = *result.pulses[t];
    const DigitizedTrace& trace = result.traces[t];
    const TraceSettings& s = trace.settings;
    auto y_of = [&](double volts) { return s.zero_div + volts / s.volts_per_div; };
    for (const PulseEdge* edge : {&pulse.rise, &pulse.fall}) {
      const double x = s.t0_div + edge->time_s / s.time_per_div;
      DrawScreenCurve(image, mapping, {x, y_of(pulse.low_volts) - 0.3},
                      {x, y_of(pulse.high_volts) + 0.3}, kEdgeColour, 1);
      cv::circle(image, Fixed(edge->centre_px), 6 << kShift, kEdgeColour, 1, cv::LINE_AA, kShift);
      // In the inset: a short tick each side of the crossing, clear of the stroke.
      const cv::Point2d up =
          mapping.ImageFromScreen({x, y_of(0.5 * (pulse.low_volts + pulse.high_volts))});
      const cv::Point2d side =
          (mapping.ImageFromScreen({x + 0.05, 0.0}) - mapping.ImageFromScreen({x, 0.0}));
      cv::line(for_insets, Fixed(up + side), Fixed(up + side * 0.4), kEdgeColour, 1, cv::LINE_AA,
               kShift);
      cv::line(for_insets, Fixed(up - side), Fixed(up - side * 0.4), kEdgeColour, 1, cv::LINE_AA,
               kShift);
      edges.emplace_back(edge->centre_px, edge == &pulse.rise ? "rise" : "fall");
    }
    // The width, above the pulse's middle.
    const double middle_x =
        s.t0_div + 0.5 * (pulse.rise.time_s + pulse.fall.time_s) / s.time_per_div;
    const std::string text = fmt::format("{}: {:.2f} +- {:.2f} us", trace.name, pulse.width_s * 1e6,
                                         pulse.width_sigma_s * 1e6);
    const double scale = 0.6 * std::max(1.0, image.cols / 1600.0);
    int baseline = 0;
    const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 2, &baseline);
    const cv::Point2d centre = mapping.ImageFromScreen(
        {middle_x, std::max(y_of(pulse.high_volts), y_of(pulse.low_volts)) + 0.2});
    const cv::Point at(std::clamp(static_cast<int>(centre.x) - size.width / 2, 4,
                                  std::max(4, image.cols - size.width - 4)),
                       std::clamp(static_cast<int>(centre.y), size.height + 4, image.rows - 4));
    DrawText(image, text, at, scale, kEdgeColour);
  }

  // Legend.
  const double scale = 0.5 * std::max(1.0, image.cols / 1600.0);
  const int line_height = static_cast<int>(std::lround(28 * scale / 0.5));
  int y = line_height;
  DrawText(image,
           fmt::format("graticule {}x{}: residual {:.3f} px RMS ({} line samples), {:.1f} px/div{}",
                       nx, ny, g.residual_px, g.samples_used, g.px_per_div,
                       g.radial_fitted ? fmt::format(", k1 {:.4f}", mapping.radial_k1) : ""),
           {10, y}, scale, kGridColour);
  for (std::size_t t = 0; t < result.traces.size(); ++t) {
    const DigitizedTrace& trace = result.traces[t];
    y += line_height;
    DrawText(image,
             fmt::format("{}: {} samples, {:.0f} % of the sweep, scatter {:.2f} px, {} outliers",
                         trace.name, trace.trace.time_s.size(), 100.0 * trace.coverage,
                         trace.noise_px, trace.outliers),
             {10, y}, scale, kTraceColours[t % std::size(kTraceColours)]);
  }

  // Insets of the pulse's edges, bottom right, magnified.
  const int inset_size = std::max(40, image.cols / 40);
  const double zoom = std::clamp(image.cols / 8.0 / inset_size, 2.0, 8.0);
  int x = image.cols - 10;
  for (auto it = edges.rbegin(); it != edges.rend(); ++it) {
    const cv::Rect region(static_cast<int>(it->first.x) - inset_size / 2,
                          static_cast<int>(it->first.y) - inset_size / 2, inset_size, inset_size);
    const int side = static_cast<int>(inset_size * zoom);
    x -= side + 10;
    Inset(for_insets, region, zoom, {x, image.rows - side - 10}, image, it->second);
  }
  return image;
}

}  // namespace impactlab
