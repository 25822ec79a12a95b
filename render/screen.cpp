#include "render/screen.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "render/rectangles.h"

namespace impactlab::render {

namespace {

constexpr double kFaceMarginDiv = 0.3;   // visible phosphor beyond the graticule
constexpr double kBezelWidthDiv = 0.75;  // the bezel's width around the face

double EdgeCoverage(double signed_distance, double edge) {
  return std::clamp(0.5 - signed_distance / edge, 0.0, 1.0);
}

// The phosphor's glow: the beam blurred wide. Blurred at a quarter of the
// resolution, which a glow tens of pixels wide does not notice; the beam's
// sides must be multiples of kGlowShrink.
constexpr int kGlowShrink = 4;

void AddGlow(cv::Mat& beam, double fraction, double sigma_px) {
  CV_Assert(beam.cols % kGlowShrink == 0 && beam.rows % kGlowShrink == 0);
  cv::Mat small, glow;
  cv::resize(beam, small, cv::Size(beam.cols / kGlowShrink, beam.rows / kGlowShrink), 0.0, 0.0,
             cv::INTER_AREA);
  cv::GaussianBlur(small, small, cv::Size(), std::max(0.5, sigma_px / kGlowShrink));
  cv::resize(small, glow, beam.size(), 0.0, 0.0, cv::INTER_LINEAR);
  cv::scaleAdd(glow, fraction, beam, beam);
}

}  // namespace

ScreenLayout LayOutScreen(const std::array<int, 2>& divisions) {
  ScreenLayout layout;
  const double nx = divisions[0], ny = divisions[1];
  layout.graticule_div = {0.0, -ny / 2.0, nx, ny};
  layout.face_div = Grow(layout.graticule_div, kFaceMarginDiv);
  layout.face_corner_div = 0.6;
  layout.bezel_div = Grow(layout.face_div, kBezelWidthDiv);
  layout.bezel_corner_div = layout.face_corner_div + 0.4;
  layout.centre_div = {nx / 2.0, 0.0};
  return layout;
}

Graticule::Graticule(const cv::Rect2d& g, bool ticks)
    : x0_(g.x),
      x1_(g.x + g.width),
      y0_(g.y),
      y1_(g.y + g.height),
      xc_(g.x + g.width / 2),
      yc_(g.y + g.height / 2),
      nx_(static_cast<int>(std::lround(g.width))),
      ny_(static_cast<int>(std::lround(g.height))),
      x_ticks_(static_cast<int>(std::lround(g.width / kTickDiv))),
      y_ticks_(static_cast<int>(std::lround(g.height / kTickDiv))),
      ticks_(ticks) {}

float PhosphorCanvas::Sample(cv::Point2d p) const {
  const cv::Matx23d& m = canvas_from_screen;
  const double x = m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2);
  const double y = m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2);
  if (!(x >= 0.0 && y >= 0.0 && x < exposure.cols - 1 && y < exposure.rows - 1)) return 0.0f;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const float* top = exposure.ptr<float>(y0) + x0;
  const float* bottom = exposure.ptr<float>(y0 + 1) + x0;
  return (top[0] * (1.0f - fx) + top[1] * fx) * (1.0f - fy) +
         (bottom[0] * (1.0f - fx) + bottom[1] * fx) * fy;
}

PhosphorCanvas RenderPhosphor(const ScreenLayout& layout, const std::vector<TraceBeam>& beams,
                              const ScreenLook& look, double px_per_div, double blur_px) {
  // The canvas covers the face and a few pixels more, so that sampling it
  // never runs off its edge inside the face.
  // Its sides are a multiple of the glow's shrink factor, so that shrinking
  // and growing back keeps the glow centred on the beam.
  const double pad_div = 3.0 / px_per_div;
  const cv::Rect2d face = Grow(layout.face_div, pad_div);
  auto multiple_of_shrink = [](double length_px) {
    return kGlowShrink * static_cast<int>(std::ceil(length_px / kGlowShrink));
  };
  const cv::Size size(multiple_of_shrink(face.width * px_per_div + 1.0),
                      multiple_of_shrink(face.height * px_per_div + 1.0));
  const cv::Rect2d area(face.x, face.y + face.height - (size.height - 1) / px_per_div,
                        (size.width - 1) / px_per_div, (size.height - 1) / px_per_div);
  PhosphorCanvas canvas;
  // Canvas x grows with screen x; canvas y grows downwards, screen y upwards.
  canvas.canvas_from_screen = cv::Matx23d(px_per_div, 0.0, -area.x * px_per_div,  //
                                          0.0, -px_per_div, (area.y + area.height) * px_per_div);
  // Traces write with the maximum of their segments, and of each other where
  // they cross: the photo's shoulder saturates a crossing anyway.
  canvas.exposure = cv::Mat::zeros(size, CV_32FC1);
  for (const TraceBeam& trace : beams) {
    DrawBeam(trace.segments, canvas.canvas_from_screen, look.beam_sigma_div * px_per_div,
             canvas.exposure);
  }
  AddGlow(canvas.exposure, look.glow_fraction, look.glow_sigma_div * px_per_div);
  if (blur_px > 0.05) cv::GaussianBlur(canvas.exposure, canvas.exposure, cv::Size(), blur_px);
  return canvas;
}

cv::Vec3f SurroundExposure(cv::Point2d p, const ScreenLayout& layout, const SurroundLook& look,
                           double edge_div) {
  const double bezel_d = RoundedRectDistance(p, layout.bezel_div, layout.bezel_corner_div);
  const float bezel_alpha = static_cast<float>(EdgeCoverage(bezel_d, edge_div));
  cv::Vec3f exposure(0.0f, 0.0f, 0.0f);
  if (bezel_alpha > 0.0f) {
    // The bezel's inner lip catches the room light, more so at the bottom,
    // which faces up.
    const double face_d = RoundedRectDistance(p, layout.face_div, layout.face_corner_div);
    constexpr double kLipWidthDiv = 0.06;
    double lip = 0.0;
    if (face_d < 10.0 * kLipWidthDiv) {
      const double half_height_div = layout.graticule_div.height / 2;
      const double facing_up = std::clamp(0.5 - 0.5 * p.y / half_height_div, 0.0, 1.0);
      lip = look.bevel_highlight * std::exp(-std::max(face_d, 0.0) / kLipWidthDiv) *
            (0.3 + 0.7 * facing_up);
    }
    exposure = look.bezel_bgr * static_cast<float>(bezel_alpha * (1.0 + lip));
  }
  if (bezel_alpha >= 1.0f) return exposure;

  cv::Vec3f outside = look.outside_bgr;
  if (look.knobs) {
    // Three knobs on the front panel, right of the bezel: dark, with a lit rim
    // at the top.
    const double knob_x_div = layout.bezel_div.x + layout.bezel_div.width + 1.4;
    constexpr double kKnobRadiusDiv = 0.65;
    for (const double knob_y_div : {2.6, 0.0, -2.6}) {
      const cv::Point2d d(p.x - knob_x_div, p.y - knob_y_div);
      if (std::max(std::abs(d.x), std::abs(d.y)) > kKnobRadiusDiv + edge_div) continue;
      const double r = std::sqrt(d.dot(d));
      const double alpha = EdgeCoverage(r - kKnobRadiusDiv, edge_div);
      const double rim = std::exp(-std::abs(r - 0.8 * kKnobRadiusDiv) / 0.04) *
                         std::clamp(d.y / kKnobRadiusDiv, 0.0, 1.0);
      const cv::Vec3f knob = look.knob_bgr * static_cast<float>(1.0 + 3.0 * rim);
      outside = outside * static_cast<float>(1.0 - alpha) + knob * static_cast<float>(alpha);
    }
  }
  return exposure + outside * (1.0f - bezel_alpha);
}

}  // namespace impactlab::render
