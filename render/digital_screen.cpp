#include "render/digital_screen.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "render/camera.h"
#include "render/random_draw.h"
#include "render/styles.h"

namespace impactlab::render {
namespace {

// The display panel in its own pixels: pixel (i, j) covers [i, i + 1) x
// [j, j + 1). The graticule's lines pass through pixel centres (its origin
// lies at a centre and a division is a whole number of pixels), as a
// scope's firmware draws them.
struct Display {
  cv::Mat bgr;  // CV_32FC3, emitted light, 1 at full drive
  int px_per_div = 50;
  cv::Point2d origin_px;  // screen (0, ny / 2): the graticule's top left corner
  std::array<int, 2> divisions{10, 8};

  cv::Point2d FromScreen(cv::Point2d s) const {
    return {origin_px.x + s.x * px_per_div, origin_px.y + (0.5 * divisions[1] - s.y) * px_per_div};
  }
  cv::Point2d ToScreen(cv::Point2d d) const {
    return {(d.x - origin_px.x) / px_per_div,
            0.5 * divisions[1] - (d.y - origin_px.y) / px_per_div};
  }
};

// Each channel's colour as such scopes draw it (display values, BGR).
cv::Scalar ChannelColour(const std::string& name, bool calibration_in_cyan) {
  const cv::Scalar yellow(0.05, 0.85, 0.95), cyan(0.95, 0.85, 0.15), magenta(0.95, 0.25, 0.95);
  if (name == "left") return cyan;
  if (name == "contact") return magenta;
  if (name == "calibration") return calibration_in_cyan ? cyan : yellow;
  return yellow;
}

void Light(cv::Mat& bgr, int col, int row, const cv::Scalar& colour) {
  if (col < 0 || row < 0 || col >= bgr.cols || row >= bgr.rows) return;
  bgr.at<cv::Vec3f>(row, col) = cv::Vec3f(
      static_cast<float>(colour[0]), static_cast<float>(colour[1]), static_cast<float>(colour[2]));
}

// The dotted graticule: a dot every fifth of a division along each division
// line, the outer frame solid or dotted, and the centre axes' ticks.
void DrawGraticule(Display& d, double grey, bool solid_frame) {
  const cv::Scalar colour(grey, grey, grey);
  const int nx = d.divisions[0], ny = d.divisions[1], step = d.px_per_div / 5;
  const int x0 = static_cast<int>(d.origin_px.x), y0 = static_cast<int>(d.origin_px.y);
  const int x1 = x0 + nx * d.px_per_div, y1 = y0 + ny * d.px_per_div;
  for (int i = 0; i <= nx; ++i) {
    const int x = x0 + i * d.px_per_div;
    const bool frame = i == 0 || i == nx;
    for (int y = y0; y <= y1; y += frame && solid_frame ? 1 : step) Light(d.bgr, x, y, colour);
  }
  for (int j = 0; j <= ny; ++j) {
    const int y = y0 + j * d.px_per_div;
    const bool frame = j == 0 || j == ny;
    for (int x = x0; x <= x1; x += frame && solid_frame ? 1 : step) Light(d.bgr, x, y, colour);
  }
  const int xc = x0 + nx * d.px_per_div / 2, yc = y0 + ny * d.px_per_div / 2;
  for (int x = x0; x <= x1; x += step) {
    for (int k = -2; k <= 2; ++k) Light(d.bgr, x, yc + k, colour);
  }
  for (int y = y0; y <= y1; y += step) {
    for (int k = -2; k <= 2; ++k) Light(d.bgr, xc + k, y, colour);
  }
}

// A channel's waveform as the firmware draws it: in each display column of
// the graticule a vertical run of pixels from the lowest to the highest
// point of the polyline over the column, `thickness` pixels wide.
void DrawWaveform(Display& d, const ScreenTrace& trace, const cv::Scalar& colour, int thickness) {
  const TraceSettings& s = trace.settings;
  std::vector<cv::Point2d> points;
  for (std::size_t i = 0; i < trace.time_s.size(); ++i) {
    points.push_back(d.FromScreen({s.t0_div + trace.time_s[i] / s.time_per_div,
                                   s.zero_div + trace.volts[i] / s.volts_per_div}));
  }
  if (points.size() < 2) return;
  const int x0 = static_cast<int>(d.origin_px.x), x1 = x0 + d.divisions[0] * d.px_per_div;
  const double top = d.origin_px.y, bottom = top + d.divisions[1] * d.px_per_div;
  // y of the polyline at display x (points' x is non-decreasing).
  std::size_t k = 0;
  const auto y_at = [&](double x) {
    while (k + 1 < points.size() && points[k + 1].x < x) ++k;
    if (k + 1 >= points.size()) return points.back().y;
    const cv::Point2d &a = points[k], &b = points[k + 1];
    return b.x > a.x ? a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x) : b.y;
  };
  const int first = std::max(x0, static_cast<int>(std::ceil(points.front().x - 0.5)));
  const int last = std::min(x1, static_cast<int>(std::floor(points.back().x - 0.5)));
  std::size_t sample = 0;
  for (int col = first; col <= last; ++col) {
    double lo = y_at(col), hi = lo;
    const double end = y_at(col + 1.0);
    lo = std::min(lo, end);
    hi = std::max(hi, end);
    while (sample < points.size() && points[sample].x < col) ++sample;
    for (; sample < points.size() && points[sample].x < col + 1.0; ++sample) {
      lo = std::min(lo, points[sample].y);
      hi = std::max(hi, points[sample].y);
    }
    // A line `thickness` pixels wide centred on the values: its rows' centres
    // average the values' (half a pixel up and down for two).
    const double half = 0.5 * (thickness - 1);
    const int row_lo = static_cast<int>(std::floor(std::clamp(lo - half, top, bottom)));
    const int row_hi = static_cast<int>(std::floor(std::clamp(hi + half, top, bottom)));
    for (int row = row_lo; row <= row_hi; ++row) Light(d.bgr, col, row, colour);
  }
}

void Text(Display& d, const std::string& text, cv::Point2d at, const cv::Scalar& colour,
          double scale) {
  cv::putText(d.bgr, text, cv::Point(static_cast<int>(at.x), static_cast<int>(at.y)),
              cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// What a scope shows besides the waveforms: the channels' scales and the
// time base above the graticule, a menu beside it where there is room, each
// channel's ground marker at the graticule's left edge, the trigger level's
// at its right, and sometimes a measurement readout inside the graticule.
void DrawAnnotations(Display& d, const OscillographScene& scene, bool calibration_in_cyan,
                     std::mt19937_64& random) {
  const cv::Scalar grey(0.75, 0.75, 0.75), dim(0.3, 0.3, 0.3);
  const double left = d.origin_px.x, top = d.origin_px.y;
  const double right = left + d.divisions[0] * d.px_per_div;
  const double bottom = top + d.divisions[1] * d.px_per_div;
  std::string scales;
  for (std::size_t i = 0; i < scene.traces.size(); ++i) {
    scales += fmt::format("CH{} {:g}V  ", i + 1, scene.traces[i].settings.volts_per_div);
  }
  if (!scene.traces.empty())
    scales += fmt::format("M {:g}s", scene.traces.front().settings.time_per_div);
  Text(d, scales, {left, top - 8.0}, grey, 0.42);
  Text(d, Chance(random, 0.5) ? "Stop" : "Trig'd", {right - 60.0, top - 8.0},
       cv::Scalar(0.3, 0.8, 0.3), 0.42);
  if (d.bgr.cols - right > 90.0) {
    const char* items[] = {"Trigger", "Edge", "Source CH1", "Slope Rising", "Mode Auto"};
    const double box = (bottom - top) / 5.0;
    for (int k = 0; k < 5; ++k) {
      const double y = top + k * box;
      cv::rectangle(d.bgr, cv::Point(static_cast<int>(right) + 12, static_cast<int>(y) + 2),
                    cv::Point(d.bgr.cols - 6, static_cast<int>(y + box) - 4), dim, 1);
      Text(d, items[k], {right + 18.0, y + 0.55 * box}, grey, 0.42);
    }
  }
  Text(d, fmt::format("{:.1f}V {:.0f}mV", Uniform(random, 1.0, 40.0), Uniform(random, 1.0, 900.0)),
       {left + 4.0, bottom + 18.0}, grey, 0.42);
  for (const ScreenTrace& trace : scene.traces) {
    const double zero = d.FromScreen({0.0, trace.settings.zero_div}).y;
    if (zero < top + 4.0 || zero > bottom - 4.0) continue;
    const cv::Scalar colour = ChannelColour(trace.name, calibration_in_cyan);
    const cv::Point marker[] = {cv::Point(static_cast<int>(left) + 1, static_cast<int>(zero) - 5),
                                cv::Point(static_cast<int>(left) + 10, static_cast<int>(zero)),
                                cv::Point(static_cast<int>(left) + 1, static_cast<int>(zero) + 5)};
    cv::fillConvexPoly(d.bgr, marker, 3, colour);
  }
  const double trigger = Uniform(random, top + 10.0, bottom - 10.0);
  Text(d, "T", {right - 12.0, trigger}, cv::Scalar(0.0, 0.6, 1.0), 0.4);
  if (Chance(random, 0.6) && !scene.traces.empty()) {
    const cv::Scalar colour = ChannelColour(scene.traces.front().name, calibration_in_cyan);
    Text(d, fmt::format("CH1 Max {:.3g}V", Uniform(random, 0.1, 9.0)),
         {left + 0.2 * d.px_per_div, top + 0.45 * d.px_per_div}, colour, 0.42);
  }
}

// The light the camera sees at display position `p` (display pixels): the
// panel's stripes, red, green and blue a third of a pixel wide each and
// 85 % of its height (centred), each three times its channel's share, so that a pixel
// seen whole shows its colour; the black matrix between.
cv::Vec3f PanelLight(const cv::Mat& bgr, cv::Point2d p) {
  // Clamped: a point on the panel's far edge may round onto it.
  const int col = std::clamp(static_cast<int>(std::floor(p.x)), 0, bgr.cols - 1);
  const int row = std::clamp(static_cast<int>(std::floor(p.y)), 0, bgr.rows - 1);
  const double fx = p.x - col, fy = p.y - row;
  constexpr double kLit = 0.85;  // centred in the pixel, the black matrix above and below
  if (std::abs(fy - 0.5) > 0.5 * kLit) return {0.0f, 0.0f, 0.0f};
  const cv::Vec3f& colour = bgr.at<cv::Vec3f>(row, col);
  const int stripe = std::min(2, static_cast<int>(3.0 * fx));  // 0 red, 1 green, 2 blue
  cv::Vec3f out(0.0f, 0.0f, 0.0f);
  const int channel = 2 - stripe;  // BGR
  out[channel] = static_cast<float>(colour[channel] * 3.0 / kLit);
  return out;
}

}  // namespace

RenderedPhoto RenderDigitalScreen(const OscillographScene& scene, const RenderOptions& options) {
  std::mt19937_64 random(options.seed);
  Display display;
  display.divisions = scene.divisions;
  display.px_per_div = 5 * UniformInt(random, 8, 12);  // dots every fifth of a division
  const int margin_left = UniformInt(random, 8, 30), margin_top = UniformInt(random, 26, 44);
  const int menu = Chance(random, 0.7) ? UniformInt(random, 110, 200) : UniformInt(random, 8, 30);
  const int width = margin_left + scene.divisions[0] * display.px_per_div + menu;
  const int height =
      margin_top + scene.divisions[1] * display.px_per_div + UniformInt(random, 26, 40);
  display.origin_px = {margin_left + 0.5, margin_top + 0.5};
  const float background = static_cast<float>(Uniform(random, 0.0, 0.06));
  display.bgr =
      cv::Mat(height, width, CV_32FC3, cv::Scalar(background, background, background * 1.3));
  const bool calibration_in_cyan = Chance(random, 0.5);
  DrawGraticule(display, Uniform(random, 0.25, 0.6), Chance(random, 0.6));
  DrawAnnotations(display, scene, calibration_in_cyan, random);
  const int thickness = UniformInt(random, 1, 2);
  for (const ScreenTrace& trace : scene.traces) {
    DrawWaveform(display, trace, ChannelColour(trace.name, calibration_in_cyan), thickness);
  }

  // The scope's body around the panel, and the phone framing it.
  const cv::Point2d panel_lo = display.ToScreen({0.0, static_cast<double>(height)});
  const cv::Point2d panel_hi = display.ToScreen({static_cast<double>(width), 0.0});
  const double bezel_div = Uniform(random, 0.4, 1.2), body_div = Uniform(random, 1.0, 3.0);
  const cv::Rect2d panel(panel_lo.x, panel_lo.y, panel_hi.x - panel_lo.x, panel_hi.y - panel_lo.y);
  const cv::Rect2d bezel(panel.x - bezel_div, panel.y - bezel_div, panel.width + 2 * bezel_div,
                         panel.height + 2 * bezel_div);
  const cv::Rect2d body(bezel.x - body_div, bezel.y - body_div, bezel.width + 2 * body_div,
                        bezel.height + 2 * body_div);
  CameraPose pose;
  pose.rotation_deg = options.rotation_deg.value_or(Uniform(random, -10.0, 10.0));
  pose.tilt_deg = options.tilt_deg.value_or(Uniform(random, 0.0, 25.0));
  pose.tilt_azimuth_deg = Uniform(random, 0.0, 360.0);
  pose.barrel_k1 = options.barrel_k1.value_or(Uniform(random, -0.05, 0.02));
  pose.fill = Uniform(random, 0.75, 0.95);
  pose.offset = {Uniform(random, -1.0, 1.0), Uniform(random, -1.0, 1.0)};
  const int photo_width = options.width_px > 0 ? options.width_px : UniformInt(random, 1600, 3000);
  const cv::Size size(photo_width, photo_width * 3 / 4);
  const std::vector<cv::Point2d> outline = {{bezel.x, bezel.y},
                                            {bezel.br().x, bezel.y},
                                            {bezel.br().x, bezel.br().y},
                                            {bezel.x, bezel.br().y}};
  RenderedPhoto photo;
  photo.mapping =
      FrameCamera(pose, outline, {panel.x + 0.5 * panel.width, panel.y + 0.5 * panel.height}, size);

  // Each photo pixel the mean of four looks into the scene through the
  // exact mapping: the panel's stripes alias as a phone's sensor aliases them.
  const ScreenFromPixel screen_of(photo.mapping);
  const cv::Vec3f bezel_bgr(0.03f, 0.03f, 0.035f);
  const float body_grey = static_cast<float>(Uniform(random, 0.08, 0.3));
  const cv::Vec3f body_bgr(body_grey, body_grey, body_grey * 1.05f);
  const float desk = static_cast<float>(Uniform(random, 0.2, 0.6));
  const cv::Vec3f desk_bgr(desk * 0.9f, desk, desk * 1.1f);
  cv::Mat light(size, CV_32FC3);
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row) {
      auto* out = light.ptr<cv::Vec3f>(row);
      for (int col = 0; col < size.width; ++col) {
        cv::Vec3f sum(0.0f, 0.0f, 0.0f);
        for (const auto& [dx, dy] :
             {std::pair{-0.25, -0.25}, {0.25, -0.25}, {-0.25, 0.25}, {0.25, 0.25}}) {
          const cv::Point2d s = screen_of(col + dx, row + dy);
          if (panel.contains(s)) {
            sum += PanelLight(display.bgr, display.FromScreen(s));
          } else if (bezel.contains(s)) {
            sum += bezel_bgr;
          } else if (body.contains(s)) {
            sum += body_bgr;
          } else {
            sum += desk_bgr;
          }
        }
        out[col] = 0.25f * sum;
      }
    }
  });
  // Glare on the glass, the lens's blur, the sensor's noise and tone curve.
  const cv::Point2d glare_at(Uniform(random, 0.2, 0.8) * size.width,
                             Uniform(random, 0.2, 0.8) * size.height);
  const double glare = Uniform(random, 0.0, 0.25),
               glare_sigma = Uniform(random, 0.08, 0.2) * size.width;
  const double gain = Uniform(random, 1.2, 2.0), noise = Uniform(random, 0.004, 0.015);
  const double blur = options.blur_px.value_or(Uniform(random, 0.5, 1.3));
  cv::GaussianBlur(light, light, cv::Size(), blur);
  std::normal_distribution<float> sensor(0.0f, static_cast<float>(noise));
  photo.image = cv::Mat(size, CV_8UC3);
  for (int row = 0; row < size.height; ++row) {
    const auto* in = light.ptr<cv::Vec3f>(row);
    auto* out = photo.image.ptr<cv::Vec3b>(row);
    for (int col = 0; col < size.width; ++col) {
      const double dx = col - glare_at.x, dy = row - glare_at.y;
      const float shine = static_cast<float>(
          glare * std::exp(-(dx * dx + dy * dy) / (2.0 * glare_sigma * glare_sigma)));
      for (int c = 0; c < 3; ++c) {
        const double e = std::max(0.0, gain * in[col][c] + shine + sensor(random));
        out[col][c] = cv::saturate_cast<uchar>(255.0 * std::pow(std::min(e, 1.0), 1.0 / 2.2));
      }
    }
  }
  StyleLook finish;
  finish.jpeg_quality = options.jpeg_quality.value_or(UniformInt(random, 70, 92));
  FinishPhoto(finish, photo.image);
  photo.jpeg_quality = finish.jpeg_quality;

  // The truth: every sample on the graticule, as the other styles give it.
  const cv::Rect2d graticule(0.0, -0.5 * scene.divisions[1], scene.divisions[0],
                             scene.divisions[1]);
  for (const ScreenTrace& trace : scene.traces) {
    TraceTruth truth;
    truth.name = trace.name;
    const TraceSettings& s = trace.settings;
    for (std::size_t i = 0; i < trace.time_s.size(); ++i) {
      const cv::Point2d p(s.t0_div + trace.time_s[i] / s.time_per_div,
                          s.zero_div + trace.volts[i] / s.volts_per_div);
      if (p.x < graticule.x || p.x > graticule.br().x || p.y < graticule.y ||
          p.y > graticule.br().y)
        continue;
      truth.time_s.push_back(trace.time_s[i]);
      truth.screen_div.push_back(p);
      truth.centre_px.push_back(photo.mapping.ImageFromScreen(p));
      truth.drawn.push_back(true);
    }
    photo.traces.push_back(std::move(truth));
  }
  return photo;
}

}  // namespace impactlab::render
