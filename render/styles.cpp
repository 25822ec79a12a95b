#include "render/styles.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/imgproc.hpp>

#include "imagefile/image_file.h"
#include "render/random_draw.h"

namespace impactlab::render {

namespace {

// P31 phosphor (peak near 520 nm): a yellowish green whose saturated core
// turns whitish in a photo, because the red and blue channels catch up.
const cv::Vec3f kP31Bgr{0.30f, 1.0f, 0.42f};
// The scale illumination's lamp light, warm.
const cv::Vec3f kLampBgr{0.75f, 0.95f, 1.0f};

void DrawClean(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  look.pose.fill = 0.97;
  look.framed_outline_div = Corners(layout.bezel_div);
  look.screen.graticule_bgr = kLampBgr * 0.05f;
  look.surround.bezel_bgr = {0.006f, 0.006f, 0.006f};
  look.surround.bevel_highlight = 1.5;
  look.blur_px = 0.4;
  look.exposure_gain = Uniform(random, 2.8, 3.2);
  look.sensor_noise = 0.006;
}

void DrawPolaroid(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  // A scope camera photographs the graticule square on; the print then lies
  // on the scanner at an angle.
  look.pose.rotation_deg = Uniform(random, -8.0, 8.0);
  look.pose.fill = Uniform(random, 0.88, 0.95);
  look.pose.offset = {Uniform(random, -0.8, 0.8), Uniform(random, -0.8, 0.8)};
  // Pack-film image area (about 1.3:1) around the graticule, thin white border.
  look.print_border = true;
  look.print_image_div = Grow(layout.graticule_div, 1.25, 0.8);
  look.print_border_div = Uniform(random, 0.3, 0.45);
  look.framed_outline_div =
      Corners(Grow(look.print_image_div, look.print_border_div, look.print_border_div));
  look.screen.graticule_bgr = kLampBgr * static_cast<float>(Uniform(random, 0.04, 0.07));
  look.screen.glow_fraction = 0.2;  // fast film overexposes the trace: a brighter glow
  // The camera's hood keeps the room light out: the bezel is barely lit.
  look.surround.bezel_bgr = {0.0015f, 0.0015f, 0.0015f};
  look.surround.bevel_highlight = 0.5;
  look.light_unevenness = Uniform(random, 0.03, 0.08);
  look.vignetting = Uniform(random, 0.15, 0.35);
  look.light_gradient = Uniform(random, 0.0, 0.15);
  look.light_angle_rad = Uniform(random, 0.0, 2.0 * std::numbers::pi);
  look.blur_px = Uniform(random, 0.8, 1.3);
  look.exposure_gain = Uniform(random, 3.0, 4.5);
  look.development = Development::kMonochrome;
  const bool sepia = Uniform(random, 0.0, 1.0) < 0.5;
  look.paper_bgr = sepia ? cv::Vec3f(0.76f, 0.87f, 0.95f) : cv::Vec3f(0.92f, 0.93f, 0.93f);
  look.black_level = static_cast<float>(Uniform(random, 0.05, 0.10));
  look.grain = Uniform(random, 0.02, 0.035);
  look.dust_specks = UniformInt(random, 30, 90);
  look.scratches = UniformInt(random, 1, 4);
  look.hairs = UniformInt(random, 0, 2);
}

void DrawPhone(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  look.pose.rotation_deg = Uniform(random, -6.0, 6.0);
  look.pose.tilt_deg = Uniform(random, 8.0, 22.0);
  look.pose.tilt_azimuth_deg = Uniform(random, 0.0, 360.0);
  look.pose.camera_distance_div = Uniform(random, 22.0, 35.0);
  look.pose.barrel_k1 = Uniform(random, -0.07, -0.03);
  look.pose.fill = Uniform(random, 0.78, 0.9);
  look.pose.offset = {Uniform(random, -0.6, 0.6), Uniform(random, -0.6, 0.6)};
  look.framed_outline_div = Corners(layout.bezel_div);
  // Room light: the face is not black, the panel is lit.
  look.screen.graticule_bgr = kLampBgr * static_cast<float>(Uniform(random, 0.03, 0.05));
  look.screen.face_bgr = {0.006f, 0.009f, 0.008f};
  look.surround.bezel_bgr = {0.014f, 0.014f, 0.015f};
  look.surround.bevel_highlight = 2.0;
  look.surround.outside_bgr = cv::Vec3f(0.105f, 0.095f, 0.085f) *
                              static_cast<float>(Uniform(random, 0.7, 1.2));  // blue-grey panel
  look.surround.knobs = true;
  look.surround.knob_bgr = {0.01f, 0.01f, 0.011f};
  look.vignetting = Uniform(random, 0.25, 0.45);
  look.light_gradient = Uniform(random, 0.1, 0.3);
  look.light_unevenness = Uniform(random, 0.05, 0.12);
  look.light_angle_rad = Uniform(random, 0.0, 2.0 * std::numbers::pi);
  look.glare = Uniform(random, 0.03, 0.1);
  look.glare_centre_div = {Uniform(random, layout.graticule_div.x, layout.graticule_div.br().x),
                           Uniform(random, layout.graticule_div.y, layout.graticule_div.br().y)};
  look.glare_radius_div = Uniform(random, 0.8, 2.0);
  look.blur_px = Uniform(random, 0.6, 1.0);
  look.exposure_gain = Uniform(random, 2.5, 3.5);
  look.sensor_noise = Uniform(random, 0.012, 0.025);
  look.chroma_noise = Uniform(random, 0.004, 0.01);
  look.sharpen = Uniform(random, 0.3, 0.6);
  look.jpeg_quality = UniformInt(random, 72, 88);
}

void DrawNegative(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  look.pose.rotation_deg = Uniform(random, -4.0, 4.0);
  look.pose.fill = Uniform(random, 0.9, 0.97);
  look.pose.offset = {Uniform(random, -0.5, 0.5), Uniform(random, -0.5, 0.5)};
  look.print_image_div = Grow(layout.graticule_div, 1.25, 0.8);
  look.framed_outline_div = Corners(look.print_image_div);
  look.screen.graticule_bgr = kLampBgr * static_cast<float>(Uniform(random, 0.04, 0.07));
  look.surround.bezel_bgr = {0.0015f, 0.0015f, 0.0015f};
  look.surround.bevel_highlight = 0.5;
  look.light_unevenness = Uniform(random, 0.03, 0.06);
  look.vignetting = Uniform(random, 0.1, 0.25);
  look.light_gradient = Uniform(random, 0.0, 0.15);
  look.light_angle_rad = Uniform(random, 0.0, 2.0 * std::numbers::pi);
  look.blur_px = Uniform(random, 0.6, 1.0);
  look.exposure_gain = Uniform(random, 3.0, 4.0);
  look.development = Development::kNegative;
  look.paper_bgr = cv::Vec3f(0.90f, 0.91f, 0.89f) * static_cast<float>(Uniform(random, 0.95, 1.05));
  look.black_level = static_cast<float>(Uniform(random, 0.08, 0.14));
  look.grain = Uniform(random, 0.015, 0.03);
  look.dust_specks = UniformInt(random, 10, 40);
  look.scratches = UniformInt(random, 0, 2);
}

void DrawLowres(StyleLook& look, const ScreenLayout& layout, std::mt19937_64& random) {
  look.width_px = 1000;
  look.pose.rotation_deg = Uniform(random, -5.0, 5.0);
  look.pose.tilt_deg = Uniform(random, 0.0, 8.0);
  look.pose.tilt_azimuth_deg = Uniform(random, 0.0, 360.0);
  look.pose.barrel_k1 = Uniform(random, -0.03, 0.0);
  look.pose.fill = Uniform(random, 0.85, 0.95);
  look.pose.offset = {Uniform(random, -0.5, 0.5), Uniform(random, -0.5, 0.5)};
  look.framed_outline_div = Corners(layout.bezel_div);
  look.screen.graticule_bgr = kLampBgr * static_cast<float>(Uniform(random, 0.04, 0.06));
  look.screen.face_bgr = {0.004f, 0.006f, 0.005f};
  look.surround.bezel_bgr = {0.01f, 0.01f, 0.01f};
  look.vignetting = Uniform(random, 0.1, 0.25);
  look.light_unevenness = Uniform(random, 0.03, 0.08);
  look.light_gradient = Uniform(random, 0.0, 0.2);
  look.light_angle_rad = Uniform(random, 0.0, 2.0 * std::numbers::pi);
  look.blur_px = Uniform(random, 1.0, 1.5);
  look.exposure_gain = Uniform(random, 2.5, 3.5);
  look.sensor_noise = Uniform(random, 0.01, 0.02);
  look.jpeg_quality = UniformInt(random, 18, 30);
}

// A smooth random curve across the image, for scratches and hairs, in cv
// drawing's fixed point with 4 fractional bits.
std::vector<cv::Point> RandomCurve(cv::Size size, double length_px, double curl,
                                   std::mt19937_64& random) {
  constexpr int kShift = 4;
  cv::Point2d p(Uniform(random, 0, size.width), Uniform(random, 0, size.height));
  double heading = Uniform(random, 0.0, 2.0 * std::numbers::pi);
  double turn = 0.0;
  std::vector<cv::Point> points;
  constexpr double kStepPx = 4.0;
  for (double travelled = 0.0; travelled < length_px; travelled += kStepPx) {
    points.emplace_back(cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift)));
    turn = 0.9 * turn + curl * Uniform(random, -1.0, 1.0);
    heading += turn;
    p += cv::Point2d(std::cos(heading), std::sin(heading)) * kStepPx;
  }
  return points;
}

}  // namespace

StyleLook DrawStyleLook(const RenderOptions& options, const ScreenLayout& layout,
                        std::mt19937_64& random, std::mt19937_64& handling_random) {
  StyleLook look;
  look.screen.phosphor_bgr = kP31Bgr;
  switch (options.style) {
    case PhotoStyle::kClean:
      DrawClean(look, layout, random);
      break;
    case PhotoStyle::kPolaroid:
      DrawPolaroid(look, layout, random);
      break;
    case PhotoStyle::kPhone:
      DrawPhone(look, layout, random);
      break;
    case PhotoStyle::kNegative:
      DrawNegative(look, layout, random);
      break;
    case PhotoStyle::kLowres:
      DrawLowres(look, layout, random);
      break;
    case PhotoStyle::kRandomised:
      DrawRandomised(look, layout, random);
      if (options.handling) DrawHandling(look, layout, handling_random);
      break;
    case PhotoStyle::kDigital:  // drawn by RenderDigitalScreen, not through a look
      break;
  }
  // The randomised style draws its file format; an option asking for grey or
  // 16 bits still gets them.
  look.grey = look.grey || options.grey;
  look.sixteen_bit = look.sixteen_bit || options.sixteen_bit;
  // Overrides replace drawn values after all draws, so that overriding one
  // leaves the others as the seed made them.
  if (options.width_px > 0) look.width_px = options.width_px;
  if (options.rotation_deg) look.pose.rotation_deg = *options.rotation_deg;
  if (options.tilt_deg) look.pose.tilt_deg = *options.tilt_deg;
  if (options.barrel_k1) look.pose.barrel_k1 = *options.barrel_k1;
  if (options.blur_px) look.blur_px = *options.blur_px;
  if (options.jpeg_quality) look.jpeg_quality = *options.jpeg_quality;
  constexpr double kFwhmPerSigma = 2.354820045;
  look.screen.beam_sigma_div = options.beam_fwhm_div / kFwhmPerSigma;
  look.screen.graticule_sigma_div = look.graticule_fwhm_div
                                        ? *look.graticule_fwhm_div / kFwhmPerSigma
                                        : 0.75 * look.screen.beam_sigma_div;
  return look;
}

Dirt DrawDirt(const StyleLook& look, cv::Size size, std::mt19937_64& random) {
  Dirt dirt;
  if (look.dust_specks + look.scratches + look.hairs + look.hand_marks == 0) return dirt;
  constexpr int kShift = 4;  // cv drawing's sub-pixel bits
  dirt.dark = cv::Mat::zeros(size, CV_8UC1);
  dirt.light = cv::Mat::zeros(size, CV_8UC1);
  const double scale = size.width / 2000.0;
  for (int i = 0; i < look.dust_specks; ++i) {
    const cv::Point centre(cvRound(Uniform(random, 0, size.width) * (1 << kShift)),
                           cvRound(Uniform(random, 0, size.height) * (1 << kShift)));
    // Mostly small specks, a few large ones.
    const double radius_px = scale * (0.6 + 3.0 * std::pow(Uniform(random, 0.0, 1.0), 3.0));
    const int coverage = UniformInt(random, 90, 255);
    cv::Mat& target = Uniform(random, 0.0, 1.0) < 0.6 ? dirt.dark : dirt.light;
    cv::circle(target, centre, cvRound(radius_px * (1 << kShift)), cv::Scalar(coverage), cv::FILLED,
               cv::LINE_AA, kShift);
  }
  for (int i = 0; i < look.scratches; ++i) {
    const auto curve = RandomCurve(size, Uniform(random, 0.2, 0.8) * size.width, 0.002, random);
    cv::polylines(dirt.light, curve, false, cv::Scalar(UniformInt(random, 60, 150)),
                  look.scratch_width_px, cv::LINE_AA, kShift);
  }
  for (int i = 0; i < look.hairs; ++i) {
    const auto curve = RandomCurve(
        size, Uniform(random, look.hair_length_lo, look.hair_length_hi) * size.width, 0.03, random);
    cv::polylines(dirt.dark, curve, false, cv::Scalar(UniformInt(random, 150, 230)),
                  look.hair_width_px, cv::LINE_AA, kShift);
  }
  cv::GaussianBlur(dirt.dark, dirt.dark, cv::Size(), 0.5);
  cv::GaussianBlur(dirt.light, dirt.light, cv::Size(), 0.5);
  // The pencil's mean stroke relative to these marks' own mean (5 px at 2000 px).
  if (look.hand_marks > 0) {
    dirt.mark = DrawHandMarks(look.hand_marks, size, look.handling.mark_width_px / 5.0, random);
  }
  return dirt;
}

void FinishPhoto(const StyleLook& look, cv::Mat& image) {
  if (look.sharpen > 0.0) {
    cv::Mat soft;
    cv::GaussianBlur(image, soft, cv::Size(), 1.5);
    cv::addWeighted(image, 1.0 + look.sharpen, soft, -look.sharpen, 0.0, image);
  }
  if (look.jpeg_quality > 0) {
    CV_Assert(image.depth() == CV_8U);
    // Through libjpeg directly, as cv::imencode and cv::imdecode (IMREAD_GRAYSCALE
    // or IMREAD_COLOR) did it: render/ does not load OpenCV's codecs.
    imagefile::Bytes bytes;
    std::string problem;
    const bool ok = imagefile::EncodeJpeg(image, look.jpeg_quality, &bytes, &problem) &&
                    (look.grey ? imagefile::DecodeJpegGrey(bytes, &image, &problem)
                               : imagefile::DecodeJpegBgr(bytes, 1, &image, &problem));
    CV_Assert(ok);  // an 8-bit image, encoded here
    if (look.sixteen_bit) image.convertTo(image, CV_16U, 257.0);
  }
}

}  // namespace impactlab::render
