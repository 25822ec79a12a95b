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

#include <opencv2/imgproc.hpp>

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

// Writes one scanned pixel (BGR in [0, 1]) in the file's format.
template <typename Sample>
void StorePrinted(const cv::Vec3f& bgr, bool grey, float full_scale, Sample* out) {
  if (grey) {
    out[0] = cv::saturate_cast<Sample>((0.114f * bgr[0] + 0.587f * bgr[1] + 0.299f * bgr[2]) *
                                       full_scale);
    return;
  }
  for (int c = 0; c < 3; ++c) out[c] = cv::saturate_cast<Sample>(bgr[c] * full_scale);
}

}  // namespace

void ScreenHalftone(const PrintLook& print, cv::Mat& tone) {
  CV_Assert(tone.type() == CV_32FC1);
  // Each cell's dot has the area of the tone around it, averaged over about a
  // cell: a Gaussian of half a period, wide enough that a thin line's dots,
  // on rows of the lattice either side of it, centre on the line to about 1 %
  // of a period whatever its offset from the rows (the lattice's sampling
  // error falls as exp(-2 pi^2 sigma^2 / period^2)).
  cv::GaussianBlur(tone, tone, cv::Size(), 0.5 * print.period_px);
  const DotRadius& dot_radius = TheDotRadius();
  const double angle = print.angle_deg * std::numbers::pi / 180.0;
  const double cu = std::cos(angle) / print.period_px, su = std::sin(angle) / print.period_px;
  const float period = static_cast<float>(print.period_px);
  const float spread = static_cast<float>(print.ink_spread);
  cv::parallel_for_(cv::Range(0, tone.rows), [&](const cv::Range& rows) {
    for (int row = rows.start; row < rows.end; ++row) {
      float* value = tone.ptr<float>(row);
      for (int col = 0; col < tone.cols; ++col) {
        const float coverage = value[col];
        if (!(coverage > 1e-4f)) {
          value[col] = 0.0f;
          continue;
        }
        // The pixel's position on the screen's lattice, in periods, and its
        // distances from the dots' centres at the four corners of the lattice
        // square it lies in. Each dot is 1 inside its (spread) radius with a
        // one-pixel ramp across its edge; where dots join, their union.
        const double u = col * cu + row * su, w = row * cu - col * su;
        const double fu = u - std::floor(u), fw = w - std::floor(w);
        const float dot_px = (dot_radius(coverage) + spread) * period + 0.5f;
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

cv::Mat ReproduceInPrint(const StyleLook& look, const cv::Mat& photo, const Dirt& dirt,
                         std::mt19937_64& random) {
  CV_Assert(photo.type() == CV_8UC1);
  const PrintLook& print = look.print;
  // The photo's grey value back to its tone t (0: the dark screen, 1: a
  // trace's core, Darkroom's tone curve), then to ink coverage: a trace's
  // light prints dark, the dark screen as clean paper.
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
  // The printer made the screen's own tone, most of the photo (its 75th
  // percentile), the paper's; ink starts ink_floor above it.
  std::array<std::size_t, 256> histogram{};
  for (int row = 0; row < photo.rows; ++row) {
    const uchar* in = photo.ptr<uchar>(row);
    for (int col = 0; col < photo.cols; ++col) ++histogram[in[col]];
  }
  std::size_t counted = 0;
  float background = 0.0f;
  std::array<int, 256> by_tone{};
  for (int v = 0; v < 256; ++v) by_tone[v] = v;
  std::sort(by_tone.begin(), by_tone.end(), [&](int a, int b) {
    return tone_of[a] < tone_of[b] || (tone_of[a] == tone_of[b] && a < b);
  });
  for (const int v : by_tone) {
    counted += histogram[v];
    background = tone_of[v];
    if (counted >= photo.total() * 3 / 4) break;
  }
  const double floor = std::min(0.9, background + print.ink_floor);
  std::array<float, 256> coverage_of{};
  for (int v = 0; v < 256; ++v) {
    const double c = print.ink_gain * (tone_of[v] - floor) / (1.0 - floor);
    coverage_of[v] = static_cast<float>(std::clamp(c, 0.0, 1.0));
  }
  cv::Mat ink(photo.size(), CV_32FC1);
  for (int row = 0; row < photo.rows; ++row) {
    const uchar* in = photo.ptr<uchar>(row);
    float* out = ink.ptr<float>(row);
    for (int col = 0; col < photo.cols; ++col) out[col] = coverage_of[in[col]];
  }
  ScreenHalftone(print, ink);
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
          value += (look.tape_bgr - value) *
                   (look.tape_opacity / 255.0f * dirt.tape.at<uchar>(row, col));
        }
        if (!dirt.mark.empty()) {
          value += (look.mark_bgr - value) * (1.0f / 255.0f * dirt.mark.at<uchar>(row, col));
        }
        value += cv::Vec3f::all(row_noise.at<float>(col));
        if (eight_bit) {
          StorePrinted(value, look.grey, 255.0f, image.ptr<uchar>(row) + col * image.channels());
        } else {
          StorePrinted(value, look.grey, 65535.0f, image.ptr<ushort>(row) + col * image.channels());
        }
      }
    }
  });
  return image;
}

}  // namespace impactlab::render
