#include "render/photo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "render/camera.h"
#include "render/display_pixel.h"
#include "render/rectangles.h"

namespace impactlab::render {

namespace {

// Coverage of an anti-aliased edge: 1 inside, 0 outside, a linear ramp
// 1 / `inv_edge` wide across it.
float EdgeCoverageFromInverseWidth(double signed_distance, double inv_edge) {
  return static_cast<float>(std::clamp(0.5 - signed_distance * inv_edge, 0.0, 1.0));
}

// The film's or sensor's response, (1 - exp(-gain E))^gamma: the exponential
// shoulder saturates the beam's core, the power lifts the shadows less than a
// display gamma would, so that the screen stays nearly black. Tabulated on a
// square-root scale of E, which follows the curve's steep toe.
class ToneCurve {
 public:
  ToneCurve(double gain, double gamma)
      : max_exposure_(12.0 / gain), inv_max_exposure_(static_cast<float>(gain / 12.0)) {
    for (int i = 0; i < kSize; ++i) {
      const double u = static_cast<double>(i) / (kSize - 1);
      table_[i] =
          static_cast<float>(std::pow(1.0 - std::exp(-gain * max_exposure_ * u * u), gamma));
    }
  }

  float operator()(float exposure) const {
    if (!(exposure > 0.0f)) return 0.0f;
    const float position = std::sqrt(exposure * inv_max_exposure_) * (kSize - 1);
    if (position >= kSize - 1) return table_[kSize - 1];
    const int i = static_cast<int>(position);
    const float f = position - i;
    return table_[i] + (table_[i + 1] - table_[i]) * f;
  }

 private:
  static constexpr int kSize = 2048;
  double max_exposure_;
  float inv_max_exposure_;
  std::array<float, kSize> table_;
};

// Film grain: white noise at half resolution, blurred a little and read back
// bilinearly, so that the grains are about two pixels across. Unit sigma.
class GrainField {
 public:
  GrainField(cv::Size image_size, cv::RNG& rng)
      : noise_(image_size.height / 2 + 2, image_size.width / 2 + 2, CV_32FC1) {
    rng.fill(noise_, cv::RNG::NORMAL, 0.0, 1.0);
    cv::GaussianBlur(noise_, noise_, cv::Size(), 0.6);
    cv::Scalar mean, sigma;
    cv::meanStdDev(noise_, mean, sigma);
    noise_ = (noise_ - mean[0]) / sigma[0];
  }

  float operator()(int col, int row) const {
    const int x0 = col / 2, y0 = row / 2;
    const float fx = 0.5f * (col % 2), fy = 0.5f * (row % 2);
    const float* top = noise_.ptr<float>(y0) + x0;
    const float* bottom = noise_.ptr<float>(y0 + 1) + x0;
    return (top[0] * (1 - fx) + top[1] * fx) * (1 - fy) +
           (bottom[0] * (1 - fx) + bottom[1] * fx) * fy;
  }

 private:
  cv::Mat noise_;
};

// Uneven light: a coarse grid of random factors 1 + sigma N(0, 1), smoothly
// interpolated over the image (bilinear in smoothstep weights).
class LightField {
 public:
  LightField(cv::Size image_size, double sigma, cv::RNG& rng)
      : grid_(5, 6, CV_32FC1),
        col_scale_((grid_.cols - 1.0) / std::max(1, image_size.width - 1)),
        row_scale_((grid_.rows - 1.0) / std::max(1, image_size.height - 1)) {
    rng.fill(grid_, cv::RNG::NORMAL, 1.0, sigma);
    cv::max(grid_, 0.3, grid_);
  }

  float operator()(int col, int row) const {
    const double x = col * col_scale_, y = row * row_scale_;
    const int x0 = std::min(static_cast<int>(x), grid_.cols - 2);
    const int y0 = std::min(static_cast<int>(y), grid_.rows - 2);
    const float fx = Smooth(static_cast<float>(x - x0)), fy = Smooth(static_cast<float>(y - y0));
    const float* top = grid_.ptr<float>(y0) + x0;
    const float* bottom = grid_.ptr<float>(y0 + 1) + x0;
    return (top[0] * (1 - fx) + top[1] * fx) * (1 - fy) +
           (bottom[0] * (1 - fx) + bottom[1] * fx) * fy;
  }

 private:
  static float Smooth(float t) { return t * t * (3.0f - 2.0f * t); }

  cv::Mat grid_;
  double col_scale_, row_scale_;
};

// Everything the per-pixel pass needs, computed once; DevelopRows may run on
// several threads at once, reading only this.
class Darkroom {
 public:
  Darkroom(const PhosphorCanvas& phosphor, const ScreenLayout& layout, const StyleLook& look,
           const CameraMapping& mapping, const Dirt& dirt, std::uint64_t noise_seed)
      : phosphor_(phosphor),
        layout_(layout),
        look_(look),
        dirt_(dirt),
        size_(PhotoSize(look)),
        grey_(look.grey),
        eight_bit_(!look.sixteen_bit || look.jpeg_quality > 0),
        to_screen_(mapping),
        graticule_(layout.graticule_div, look.screen.graticule_ticks),
        tone_(look.exposure_gain, look.tone_gamma),
        noise_seed_(noise_seed) {
    const double px_per_div = PixelsPerDivisionAt(mapping, layout.centre_div);
    // The camera's blur, for what is drawn analytically here: edges ramp over
    // about its width, and the graticule's lines widen as a Gaussian would.
    edge_div_ = std::max(1.0, 2.5 * look.blur_px) / px_per_div;
    inv_edge_ = 1.0 / edge_div_;
    const double sigma_div = std::hypot(look.screen.graticule_sigma_div, look.blur_px / px_per_div);
    graticule_peak_ = static_cast<float>(look.screen.graticule_sigma_div / sigma_div);
    graticule_reach2_ = std::pow(3.5 * sigma_div, 2);
    graticule_inv_two_sigma2_ = 1.0 / (2.0 * sigma_div * sigma_div);
    glare_inv_two_sigma2_ = 1.0 / (2.0 * look.glare_radius_div * look.glare_radius_div);
    print_div_ = Grow(look.print_image_div, look.print_border_div);
    centre_col_ = 0.5 * (size_.width - 1);
    centre_row_ = 0.5 * (size_.height - 1);
    inv_half_diagonal_ = 2.0 / std::hypot(size_.width, size_.height);
    light_gradient_x_ = look.light_gradient * std::cos(look.light_angle_rad);
    light_gradient_y_ = look.light_gradient * std::sin(look.light_angle_rad);

    cv::RNG rng(noise_seed);
    if (look.grain > 0.0) grain_.emplace(size_, rng);
    if (look.light_unevenness > 0.0) light_field_.emplace(size_, look.light_unevenness, rng);
  }

  cv::Mat NewImage() const {
    return cv::Mat(size_, CV_MAKETYPE(eight_bit_ ? CV_8U : CV_16U, grey_ ? 1 : 3));
  }

  void DevelopRows(const cv::Range& rows, cv::Mat& image) const {
    cv::Mat row_noise(1, size_.width, CV_32FC4);  // luma and three chroma normals per pixel
    for (int row = rows.start; row < rows.end; ++row) {
      if (look_.sensor_noise > 0.0) {
        // Each row's noise has its own seed: the same bytes on any number of threads.
        cv::RNG rng(SplitMix64(noise_seed_ + static_cast<std::uint64_t>(row)));
        rng.fill(row_noise, cv::RNG::NORMAL, 0.0, 1.0);
      }
      for (int col = 0; col < size_.width; ++col) {
        const cv::Vec3f value = Develop(col, row, row_noise.at<cv::Vec4f>(col));
        if (eight_bit_) {
          StoreDisplayPixel(value, grey_, 255.0f, image.ptr<uchar>(row) + col * image.channels());
        } else {
          StoreDisplayPixel(value, grey_, 65535.0f,
                            image.ptr<ushort>(row) + col * image.channels());
        }
      }
    }
  }

 private:
  static std::uint64_t SplitMix64(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }

  // The display values (BGR, about [0, 1]) of one pixel.
  cv::Vec3f Develop(int col, int row, const cv::Vec4f& noise) const {
    const cv::Point2d p = to_screen_(col, row);
    const double face_d = RoundedRectDistance(p, layout_.face_div, layout_.face_corner_div);
    const float face_alpha = EdgeCoverageFromInverseWidth(face_d, inv_edge_);
    cv::Vec3f exposure = Light(Scene(p, face_alpha), p, face_alpha, col, row);
    cv::Vec3f value = Tone(exposure);
    AddNoise(col, row, noise, value);
    float in_image = 1.0f;
    if (look_.print_border) in_image = LayOnScanner(p, value);
    if (!dirt_.dark.empty()) value *= 1.0f - 0.85f / 255.0f * dirt_.dark.at<uchar>(row, col);
    if (!dirt_.light.empty()) {
      value +=
          (look_.paper_bgr - value) * (0.8f / 255.0f * dirt_.light.at<uchar>(row, col) * in_image);
    }
    if (!dirt_.tape.empty()) {
      value += (look_.handling.tape_bgr - value) *
               (look_.handling.tape_opacity / 255.0f * dirt_.tape.at<uchar>(row, col));
    }
    if (!dirt_.mark.empty()) {
      value += (look_.mark_bgr - value) * (1.0f / 255.0f * dirt_.mark.at<uchar>(row, col));
    }
    return value;
  }

  // The light leaving the scope at screen position p: face, bezel and beyond.
  cv::Vec3f Scene(cv::Point2d p, float face_alpha) const {
    cv::Vec3f exposure(0.0f, 0.0f, 0.0f);
    if (face_alpha > 0.0f) {
      const double d2 = graticule_.Distance2(p);
      const float graticule =
          d2 < graticule_reach2_ && !GraticuleMissing(p)
              ? graticule_peak_ * static_cast<float>(std::exp(-d2 * graticule_inv_two_sigma2_))
              : 0.0f;
      exposure = look_.screen.face_bgr + graticule * look_.screen.graticule_bgr +
                 phosphor_.Sample(p) * look_.screen.phosphor_bgr;
    }
    if (face_alpha < 1.0f) {
      exposure = exposure * face_alpha +
                 SurroundExposure(p, layout_, look_.surround, edge_div_) * (1.0f - face_alpha);
    }
    return exposure;
  }

  // Where the graticule's paint is worn off (randomised style).
  bool GraticuleMissing(cv::Point2d p) const {
    for (const cv::Rect2d& gap : look_.screen.graticule_missing_div) {
      if (gap.contains(p)) return true;
    }
    return false;
  }

  // Falloff towards the corners, uneven room light, glare on the glass.
  cv::Vec3f Light(cv::Vec3f exposure, cv::Point2d p, float face_alpha, int col, int row) const {
    const double x = (col - centre_col_) * inv_half_diagonal_;
    const double y = (row - centre_row_) * inv_half_diagonal_;
    const double falloff = 1.0 + look_.vignetting * (x * x + y * y);
    const double gradient = 1.0 + x * light_gradient_x_ + y * light_gradient_y_;
    exposure *= static_cast<float>(gradient / (falloff * falloff));
    if (light_field_) exposure *= (*light_field_)(col, row);
    if (look_.glare > 0.0 && face_alpha > 0.0f) {
      const cv::Point2d d = p - look_.glare_centre_div;
      const double r2 = d.dot(d) * glare_inv_two_sigma2_;
      // A broad sheen with the lamp's small, bright image in its middle.
      if (r2 < 20.0) {
        const double sheen = std::exp(-r2) + (r2 < 1.0 ? 1.5 * std::exp(-25.0 * r2) : 0.0);
        exposure +=
            cv::Vec3f(0.95f, 1.0f, 1.0f) * static_cast<float>(look_.glare * sheen * face_alpha);
      }
    }
    return exposure;
  }

  // Development: the colour sensor's or the black-and-white print's response.
  cv::Vec3f Tone(const cv::Vec3f& exposure) const {
    if (look_.development == Development::kColour) {
      return {tone_(exposure[0]), tone_(exposure[1]), tone_(exposure[2])};
    }
    const cv::Vec3f film_sensitivity_bgr(0.11f, 0.59f, 0.30f);  // panchromatic film
    const float t = tone_(exposure.dot(film_sensitivity_bgr));
    const float black = look_.black_level;
    return look_.paper_bgr * (look_.development == Development::kMonochrome
                                  ? black + (1.0f - black) * t
                                  : 1.0f - (1.0f - black) * t);
  }

  void AddNoise(int col, int row, const cv::Vec4f& noise, cv::Vec3f& value) const {
    if (grain_) {
      // Grain shows most in the mid tones.
      const float v = value[1];
      value += look_.paper_bgr * static_cast<float>(look_.grain * (0.4f + 2.4f * v * (1.0f - v)) *
                                                    (*grain_)(col, row));
    }
    if (look_.sensor_noise > 0.0) {
      // Shot noise grows as the square root of the signal (here its green,
      // most of a P31 trace's light); read noise keeps a floor.
      const float sigma =
          static_cast<float>(look_.sensor_noise) * std::sqrt(0.1f + std::max(0.0f, value[1]));
      for (int c = 0; c < 3; ++c) {
        value[c] += sigma * noise[0] + static_cast<float>(look_.chroma_noise) * noise[c + 1];
      }
    }
  }

  // The print on the scanner bed: the white border around the image area,
  // then the bed with the print's shadow. Returns how much of the pixel is
  // the print's image area.
  float LayOnScanner(cv::Point2d p, cv::Vec3f& value) const {
    const double image_d = RoundedRectDistance(p, look_.print_image_div, 0.05);
    if (image_d <= -edge_div_) return 1.0f;
    const double print_d = RoundedRectDistance(p, print_div_, 0.15);
    const float in_image = EdgeCoverageFromInverseWidth(image_d, inv_edge_);
    const float on_print = EdgeCoverageFromInverseWidth(print_d, inv_edge_);
    const float shadow =
        1.0f - 0.35f * static_cast<float>(std::exp(-std::max(print_d, 0.0) / 0.08));
    const cv::Vec3f scanner_bed_bgr(0.80f, 0.80f, 0.79f);
    // The border was never developed: whiter than a toned image's highlights.
    const cv::Vec3f border_bgr = look_.paper_bgr * 0.35f + cv::Vec3f(0.93f, 0.94f, 0.94f) * 0.65f;
    const cv::Vec3f around = border_bgr * on_print + scanner_bed_bgr * (shadow * (1.0f - on_print));
    value = value * in_image + around * (1.0f - in_image);
    return in_image;
  }

  const PhosphorCanvas& phosphor_;
  const ScreenLayout& layout_;
  const StyleLook& look_;
  const Dirt& dirt_;
  cv::Size size_;
  bool grey_;
  bool eight_bit_;
  ScreenFromPixel to_screen_;
  Graticule graticule_;
  ToneCurve tone_;
  std::uint64_t noise_seed_;
  std::optional<GrainField> grain_;
  std::optional<LightField> light_field_;
  double edge_div_ = 0.0, inv_edge_ = 0.0;
  float graticule_peak_ = 1.0f;
  double graticule_reach2_ = 0.0, graticule_inv_two_sigma2_ = 0.0;
  double glare_inv_two_sigma2_ = 0.0;
  cv::Rect2d print_div_;
  double centre_col_ = 0.0, centre_row_ = 0.0, inv_half_diagonal_ = 0.0;
  double light_gradient_x_ = 0.0, light_gradient_y_ = 0.0;  // per unit of half diagonal
};

}  // namespace

cv::Mat Photograph(const PhosphorCanvas& phosphor, const ScreenLayout& layout,
                   const StyleLook& look, const CameraMapping& mapping, const Dirt& dirt,
                   std::mt19937_64& random) {
  const Darkroom darkroom(phosphor, layout, look, mapping, dirt, random());
  cv::Mat image = darkroom.NewImage();
  // Rows are independent; OpenCV's thread pool (cv::setNumThreads) runs them.
  cv::parallel_for_(cv::Range(0, image.rows),
                    [&](const cv::Range& rows) { darkroom.DevelopRows(rows, image); });
  return image;
}

}  // namespace impactlab::render
