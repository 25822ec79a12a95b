#include "digitize/halftone.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "digitize/select.h"

namespace impactlab::digitize {

namespace {

// The spectrum is read in a square of this side (or the largest power of two
// that fits) from the photo's middle, where the screen is.
constexpr int kScreenWindowPx = 512;
// Periods a halftone screen can have at a scan's resolution, pixels: finer
// ones are blurred away by the scan itself, coarser ones are not a print's.
constexpr double kMinScreenPeriodPx = 2.2, kMaxScreenPeriodPx = 16.0;
// A screen's fundamental stands this far above the median of its ring.
constexpr double kMinScreenContrast = 100.0;

cv::Mat1f GreyWindow(const cv::Mat& image, int side) {
  const cv::Rect window((image.cols - side) / 2, (image.rows - side) / 2, side, side);
  cv::Mat crop = image(window), grey;
  if (crop.channels() == 3) {
    cv::cvtColor(crop, grey, cv::COLOR_BGR2GRAY);
  } else if (crop.channels() == 4) {
    cv::cvtColor(crop, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = crop;
  }
  cv::Mat1f out;
  grey.convertTo(out, CV_32F, grey.depth() == CV_16U ? 1.0 / 65535 : 1.0 / 255);
  return out;
}

class PowerSpectrum {
 public:
  explicit PowerSpectrum(cv::Mat1f grey) : n_(grey.cols) {
    grey -= cv::mean(grey)[0];
    cv::Mat1f hann;
    cv::createHanningWindow(hann, grey.size(), CV_32F);
    grey = grey.mul(hann);
    cv::Mat complex;
    cv::dft(grey, complex, cv::DFT_COMPLEX_OUTPUT);
    std::vector<cv::Mat1f> parts;
    cv::split(complex, parts);
    cv::magnitude(parts[0], parts[1], power_);
    power_ = power_.mul(power_);
  }

  int n() const { return n_; }

  // The power at frequency (fx, fy), bins (negative allowed), the largest of
  // the 3 x 3 bins about it (a peak between bins spreads over them).
  double PeakAt(double fx, double fy) const {
    double best = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) best = std::max(best, At(Wrap(fx) + dx, Wrap(fy) + dy));
    }
    return best;
  }

  double At(int u, int v) const { return power_(Wrap(v), Wrap(u)); }

  int Wrap(double f) const {
    const int i = static_cast<int>(std::lround(f));
    return ((i % n_) + n_) % n_;
  }

 private:
  int n_;
  cv::Mat1f power_;
};

// Frequencies of a JPEG's 8 x 8 block pattern: both components multiples
// of n / 8 (within a bin).
bool OnJpegBlockPattern(int fx, int fy, int n) {
  const auto near_multiple = [n](int f) {
    const double r = std::remainder(static_cast<double>(f), n / 8.0);
    return std::abs(r) <= 1.0;
  };
  return near_multiple(fx) && near_multiple(fy);
}

}  // namespace

std::optional<HalftoneScreen> FindHalftoneScreen(const cv::Mat& image) {
  int side = kScreenWindowPx;
  while (side > 64 && (side > image.cols || side > image.rows)) side /= 2;
  if (side < 128) return std::nullopt;
  const PowerSpectrum spectrum(GreyWindow(image, side));
  const int n = spectrum.n();
  const double r_lo = n / kMaxScreenPeriodPx, r_hi = n / kMinScreenPeriodPx;

  // Each ring's median power: the level a peak must stand above. The upper
  // half plane holds every frequency once (the spectrum is symmetric).
  const int rings = static_cast<int>(std::ceil(r_hi)) + 2;
  std::vector<std::vector<float>> ring_power(rings);
  for (int fy = 0; fy <= n / 2; ++fy) {
    for (int fx = -n / 2; fx < n / 2; ++fx) {
      const double r = std::hypot(fx, fy);
      if (r < r_lo - 1 || r > r_hi + 1) continue;
      ring_power[static_cast<int>(std::lround(r))].push_back(
          static_cast<float>(spectrum.At(fx, fy)));
    }
  }
  std::vector<double> ring_level(rings, 0.0);
  for (int r = 0; r < rings; ++r) {
    auto& p = ring_power[r];
    if (p.empty()) continue;
    ring_level[r] = SelectNth(p.begin(), p.begin() + p.size() / 2, p.end());
  }
  const auto contrast_at = [&](double fx, double fy) {
    const int r = static_cast<int>(std::lround(std::hypot(fx, fy)));
    if (r <= 0 || r >= rings || !(ring_level[r] > 0.0)) return 0.0;
    return spectrum.PeakAt(fx, fy) / ring_level[r];
  };

  // The strongest frequency against its ring, the block pattern left out.
  double best = 0.0;
  int best_fx = 0, best_fy = 0;
  for (int fy = 0; fy <= n / 2; ++fy) {
    for (int fx = -n / 2; fx < n / 2; ++fx) {
      const double r = std::hypot(fx, fy);
      if (r < r_lo || r > r_hi || OnJpegBlockPattern(fx, fy, n)) continue;
      const int ring = static_cast<int>(std::lround(r));
      if (!(ring_level[ring] > 0.0)) continue;
      const double c = spectrum.At(fx, fy) / ring_level[ring];
      if (c > best) best = c, best_fx = fx, best_fy = fy;
    }
  }
  if (best < kMinScreenContrast) return std::nullopt;
  // A screen is a lattice: the same frequency turned a right angle is there
  // too. A comb of a grid's line harmonics is not isolated: along the same
  // direction a quarter nearer or further it is as strong.
  if (contrast_at(-best_fy, best_fx) < 0.25 * best) return std::nullopt;
  const double comb = std::max(contrast_at(0.75 * best_fx, 0.75 * best_fy),
                               contrast_at(1.25 * best_fx, 1.25 * best_fy));
  if (comb > 0.1 * best) return std::nullopt;

  HalftoneScreen screen;
  screen.period_px = n / std::hypot(best_fx, best_fy);
  // The image's rows run down: a frequency (fx, fy) is a lattice direction
  // of atan2(-fy, fx) on the page; folded into [0, 90).
  double angle = std::atan2(-best_fy, best_fx) * 180.0 / std::numbers::pi;
  angle = std::fmod(std::fmod(angle, 90.0) + 90.0, 90.0);
  screen.angle_deg = angle;
  screen.contrast = best;
  return screen;
}

cv::Mat Descreen(const cv::Mat& image, const HalftoneScreen& screen) {
  cv::Mat out;
  cv::GaussianBlur(image, out, cv::Size(), 0.35 * screen.period_px);
  return out;
}

}  // namespace impactlab::digitize
