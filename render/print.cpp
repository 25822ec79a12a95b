// The print reproduction (docs/rendering.md, "The randomised style"): the
// finished photo as a figure in a printed report, scanned. The photo's tones
// become ink coverage (a trace's light prints dark), screened as
// amplitude-modulated round dots on a rotated square lattice, printed on toned
// paper with the ink spreading a little; then the scanner blurs and adds its
// noise. Only pixel values change: the geometry stays the photo's.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "render/display_pixel.h"
#include "render/styles.h"

namespace impactlab::render {

namespace {

// The radius (in cell periods) of the round dot centred in a unit square cell
// that covers `area` of it: the inverse of
//   A(r) = pi r^2                                             r <= 1/2
//   A(r) = pi r^2 - 4 (r^2 acos(1 / 2r) - 1/2 sqrt(r^2 - 1/4)) 1/2 < r <= sqrt(1/2)
// (past r = 1/2 the disc is clipped by the cell's sides: the dots join into a
// chequerboard and then leave round holes, as a real screen's do). Tabulated.
class DotRadius {
 public:
  DotRadius() {
    // A(r) on a fine grid of r, inverted by walking it.
    constexpr int kFine = 1 << 15;
    const double r_max = std::sqrt(0.5);
    int i = 0;
    for (int k = 0; k <= kFine && i < kSize; ++k) {
      const double r = r_max * k / kFine;
      while (i < kSize && Area(r) >= static_cast<double>(i) / (kSize - 1)) {
        table_[i++] = static_cast<float>(r);
      }
    }
    for (; i < kSize; ++i) table_[i] = static_cast<float>(r_max);
  }

  float operator()(float area) const {
    const float position = std::clamp(area, 0.0f, 1.0f) * (kSize - 1);
    const int i = std::min(static_cast<int>(position), kSize - 2);
    const float f = position - i;
    return table_[i] + (table_[i + 1] - table_[i]) * f;
  }

  static double Area(double r) {
    const double disc = std::numbers::pi * r * r;
    if (r <= 0.5) return disc;
    return disc - 4.0 * (r * r * std::acos(0.5 / r) - 0.5 * std::sqrt(r * r - 0.25));
  }

 private:
  static constexpr int kSize = 4096;
  std::array<float, kSize> table_{};
};

const DotRadius& TheDotRadius() {
  static const DotRadius radius;
  return radius;
}

std::uint64_t PrintRowSeed(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace

namespace {

// Each pixel inked where it lies within the round dot of its cell whose area
// is the coverage there (CV_32FC1, 0..1, in place), the dot's radius grown by
// the ink's spread; anti-aliased over a pixel.
void PrintDots(const PrintLook& print, cv::Mat& coverage) {
  const DotRadius& dot_radius = TheDotRadius();
  const double angle = print.angle_deg * std::numbers::pi / 180.0;
  const double cu = std::cos(angle) / print.period_px, su = std::sin(angle) / print.period_px;
  const float period = static_cast<float>(print.period_px);
  const float spread = static_cast<float>(print.ink_spread);
  cv::parallel_for_(cv::Range(0, coverage.rows), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row) {
      float* value = coverage.ptr<float>(row);
      for (int col = 0; col < coverage.cols; ++col) {
        const float area = value[col];
        if (!(area > 1e-4f)) {
          value[col] = 0.0f;
          continue;
        }
        // The pixel's position on the screen's lattice, in periods, and its
        // distances from the dots' centres at the four corners of the lattice
        // square it lies in. Each dot is 1 inside its (spread) radius with a
        // one-pixel ramp across its edge; where dots join, their union.
        const double u = col * cu + row * su, w = row * cu - col * su;
        const double fu = u - std::floor(u), fw = w - std::floor(w);
        const float dot_px = (dot_radius(area) + spread) * period + 0.5f;
        float paper = 1.0f;
        for (const double du : {fu, fu - 1.0}) {
          for (const double dw : {fw, fw - 1.0}) {
            const float r_px = static_cast<float>(std::sqrt(du * du + dw * dw)) * period;
            paper *= 1.0f - std::clamp(dot_px - r_px, 0.0f, 1.0f);
          }
        }
        value[col] = 1.0f - paper;
      }
    }
  });
}

// Each cell's dot has the area of the tone around it, averaged over about a
// cell: a Gaussian of half a period, wide enough that a thin line's dots, on
// rows of the lattice either side of it, centre on the line to about 1 % of a
// period whatever its offset from the rows (the lattice's sampling error
// falls as exp(-2 pi^2 sigma^2 / period^2)).
void AverageOverCell(const PrintLook& print, cv::Mat& tone) {
  cv::GaussianBlur(tone, tone, cv::Size(), 0.5 * print.period_px);
}

// The value of `image` (CV_32FC1) below which `share` of its values at
// `points` (bilinear, those inside it) lie.
float QuantileAt(const cv::Mat& image, const std::vector<cv::Point2d>& points, double share) {
  std::vector<float> values;
  for (const cv::Point2d& p : points) {
    const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
    if (x < 0 || y < 0 || x + 1 >= image.cols || y + 1 >= image.rows) continue;
    const float fx = static_cast<float>(p.x - x), fy = static_cast<float>(p.y - y);
    const float* top = image.ptr<float>(y) + x;
    const float* bottom = image.ptr<float>(y + 1) + x;
    values.push_back((top[0] * (1 - fx) + top[1] * fx) * (1 - fy) +
                     (bottom[0] * (1 - fx) + bottom[1] * fx) * fy);
  }
  if (values.empty()) return 0.0f;
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(share * (values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

// The value of `image` (CV_32FC1) below which `share` of its pixels lie.
float Quantile(const cv::Mat& image, double share) {
  std::vector<float> values(image.begin<float>(), image.end<float>());
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(share * (values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

// The report's caption under the figure, in solid type (captions are not
// screened), turned with the figure: ink coverage added into `ink`.
void PrintCaption(const PrintLook& print, cv::Point2d centre_px, cv::Point2d along_px,
                  double height_px, cv::Mat& ink) {
  const std::string text =
      "Fig. " + std::to_string(print.figure_number) + ".  Displacements and contact";
  constexpr int kFont = cv::FONT_HERSHEY_DUPLEX;
  const int thickness = std::max(1, static_cast<int>(std::lround(height_px / 12.0)));
  const double scale =
      cv::getFontScaleFromHeight(kFont, std::max(1, cvRound(height_px)), thickness);
  int baseline = 0;
  const cv::Size extent = cv::getTextSize(text, kFont, scale, thickness, &baseline);
  cv::Mat type = cv::Mat::zeros(extent.height + baseline + 2 * thickness + 2,
                                extent.width + 2 * thickness + 2, CV_32FC1);
  cv::putText(type, text, cv::Point(thickness + 1, extent.height + thickness + 1), kFont, scale,
              cv::Scalar(1.0), thickness, cv::LINE_AA);
  // The type's centre onto centre_px, its baseline along along_px (image
  // y runs down: OpenCV's positive angle turns the type anticlockwise).
  const cv::Point2f from(0.5f * type.cols, 0.5f * type.rows);
  const double turn_deg = -std::atan2(along_px.y, along_px.x) * 180.0 / std::numbers::pi;
  cv::Mat move = cv::getRotationMatrix2D(from, turn_deg, 1.0);
  move.at<double>(0, 2) += centre_px.x - from.x;
  move.at<double>(1, 2) += centre_px.y - from.y;
  cv::Mat placed;
  cv::warpAffine(type, placed, move, ink.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0.0);
  cv::max(ink, placed, ink);
}

}  // namespace

void ScreenHalftone(const PrintLook& print, cv::Mat& tone) {
  CV_Assert(tone.type() == CV_32FC1);
  AverageOverCell(print, tone);
  PrintDots(print, tone);
}

cv::Mat ReproduceInPrint(const StyleLook& look, const cv::Mat& photo,
                         const std::vector<cv::Point2d>& grid_px, cv::Point2d caption_px,
                         cv::Point2d caption_along_px, double caption_height_px, const Dirt& dirt,
                         std::mt19937_64& random) {
  CV_Assert(photo.type() == CV_8UC1);
  const PrintLook& print = look.handling.print;
  // The photo's grey value back to its tone t (0: the dark screen, 1: a
  // trace's core, Darkroom's tone curve): a trace's light prints dark, the
  // dark screen as clean paper.
  const float paper =
      0.114f * look.paper_bgr[0] + 0.587f * look.paper_bgr[1] + 0.299f * look.paper_bgr[2];
  const float black = look.development == Development::kColour ? 0.0f : look.black_level;
  std::array<float, 256> tone_of{};
  for (int v = 0; v < 256; ++v) {
    const float grey = v / 255.0f;
    float t = grey;
    if (look.development == Development::kMonochrome) t = (grey / paper - black) / (1.0f - black);
    if (look.development == Development::kNegative) t = (1.0f - grey / paper) / (1.0f - black);
    tone_of[v] = std::clamp(t, 0.0f, 1.0f);
  }
  cv::Mat ink(photo.size(), CV_32FC1);
  for (int row = 0; row < photo.rows; ++row) {
    const uchar* in = photo.ptr<uchar>(row);
    float* out = ink.ptr<float>(row);
    for (int col = 0; col < photo.cols; ++col) out[col] = tone_of[in[col]];
  }
  // The tones as the screen averages them (which leaves little of the
  // photo's noise); the printer set their contrast from these. The ground is
  // most of the photo (its 75th percentile), the grid what its lines show:
  // their median prints with print.grid_coverage (traces, brighter, more),
  // and ink starts between the ground and the grid's dimmest tenth (under
  // vignetting or a light gradient), so that the whole grid prints: a figure
  // whose grid did not print would have been no use to its reader.
  AverageOverCell(print, ink);
  const float ground = Quantile(ink, 0.75);
  const float grid = std::max(QuantileAt(ink, grid_px, 0.5), ground + 0.03f);
  const float dim_grid = std::clamp(QuantileAt(ink, grid_px, 0.1), ground + 0.02f, grid);
  const float floor = std::max(
      ground + static_cast<float>(print.floor_of_grid) * (dim_grid - ground), ground + 0.01f);
  const float gain = static_cast<float>(print.grid_coverage) / (grid - floor);
  ink = (ink - floor) * gain;
  cv::max(ink, 0.0f, ink);
  cv::min(ink, 1.0f, ink);
  PrintDots(print, ink);
  // The caption: solid type under the figure, turned as the figure is.
  PrintCaption(print, caption_px, caption_along_px, caption_height_px, ink);
  // The scanner's optics blur the printed dots.
  if (print.scan_blur_px > 0.0) cv::GaussianBlur(ink, ink, cv::Size(), print.scan_blur_px);

  // The paper's tone varies smoothly: a coarse grid of factors, cubic-resized.
  cv::RNG rng(random());
  constexpr int kMottleStep = 16;
  cv::Mat mottle_grid(6, 8, CV_32FC1);
  rng.fill(mottle_grid, cv::RNG::NORMAL, 1.0, std::max(print.paper_mottle, 1e-9));
  cv::Mat mottle;
  cv::resize(mottle_grid, mottle, {photo.cols / kMottleStep + 2, photo.rows / kMottleStep + 2}, 0,
             0, cv::INTER_CUBIC);
  const std::uint64_t noise_seed = random();

  const HandlingLook& handling = look.handling;
  const bool eight_bit = !look.sixteen_bit || look.jpeg_quality > 0;
  cv::Mat image(photo.size(), CV_MAKETYPE(eight_bit ? CV_8U : CV_16U, look.grey ? 1 : 3));
  cv::parallel_for_(cv::Range(0, photo.rows), [&](const cv::Range& rows) {
    cv::Mat row_noise(1, photo.cols, CV_32FC1);
    for (int row = rows.start; row < rows.end; ++row) {
      // Each row's noise has its own seed: the same bytes on any number of threads.
      cv::RNG row_rng(PrintRowSeed(noise_seed + static_cast<std::uint64_t>(row)));
      row_rng.fill(row_noise, cv::RNG::NORMAL, 0.0, print.scan_noise);
      const float* inked = ink.ptr<float>(row);
      const int y0 = row / kMottleStep;
      const float fy = static_cast<float>(row % kMottleStep) / kMottleStep;
      for (int col = 0; col < photo.cols; ++col) {
        const int x0 = col / kMottleStep;
        const float fx = static_cast<float>(col % kMottleStep) / kMottleStep;
        const float* top = mottle.ptr<float>(y0) + x0;
        const float* bottom = mottle.ptr<float>(y0 + 1) + x0;
        const float tone = (top[0] * (1 - fx) + top[1] * fx) * (1 - fy) +
                           (bottom[0] * (1 - fx) + bottom[1] * fx) * fy;
        cv::Vec3f value = print.paper_bgr * tone * (1.0f - inked[col]) + print.ink_bgr * inked[col];
        // What was laid on the printed page: tape, then pencil and ink.
        if (!dirt.tape.empty()) {
          value += (handling.tape_bgr - value) *
                   (handling.tape_opacity / 255.0f * dirt.tape.at<uchar>(row, col));
        }
        if (!dirt.mark.empty()) {
          value += (look.mark_bgr - value) * (1.0f / 255.0f * dirt.mark.at<uchar>(row, col));
        }
        value += cv::Vec3f::all(row_noise.at<float>(col));
        if (eight_bit) {
          StoreDisplayPixel(value, look.grey, 255.0f,
                            image.ptr<uchar>(row) + col * image.channels());
        } else {
          StoreDisplayPixel(value, look.grey, 65535.0f,
                            image.ptr<ushort>(row) + col * image.channels());
        }
      }
    }
  });
  return image;
}

}  // namespace impactlab::render
