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
// How far to the side of a peak a ridge is looked for, frequency bins (the
// window's main lobe is 2 bins wide).
constexpr double kSideBins = 6.0;
// The lattice's sum frequency stands this far above its ring (measured:
// 76-34000 on printed figures, at most 17 for tick marks and textures).
constexpr double kMinCrossContrast = 40.0;

// The square of `side` pixels about `centre` (moved into the photo), grey.
cv::Mat1f GreyWindow(const cv::Mat& image, cv::Point centre, int side) {
  const cv::Rect window(std::clamp(centre.x - side / 2, 0, image.cols - side),
                        std::clamp(centre.y - side / 2, 0, image.rows - side), side, side);
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

  // The power of everything but the mean.
  double Total() const { return cv::sum(power_)[0] - power_(0, 0); }

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

// A window's power spectrum against each ring's median power (the level a
// peak must stand above), over the radii of a screen's periods.
class RingSpectrum {
 public:
  explicit RingSpectrum(cv::Mat1f grey)
      : spectrum_(std::move(grey)),
        r_lo_(spectrum_.n() / kMaxScreenPeriodPx),
        r_hi_(spectrum_.n() / kMinScreenPeriodPx),
        level_(static_cast<int>(std::ceil(r_hi_)) + 2, 0.0) {
    const int n = spectrum_.n();
    // The upper half plane holds every frequency once (the spectrum is symmetric).
    std::vector<std::vector<float>> ring_power(level_.size());
    for (int fy = 0; fy <= n / 2; ++fy) {
      for (int fx = -n / 2; fx < n / 2; ++fx) {
        const double r = std::hypot(fx, fy);
        // From half the lowest frequency: a comb's fundamental is looked at there.
        if (r < 0.5 * r_lo_ - 1 || r > r_hi_ + 1) continue;
        ring_power[static_cast<int>(std::lround(r))].push_back(
            static_cast<float>(spectrum_.At(fx, fy)));
      }
    }
    for (std::size_t r = 0; r < level_.size(); ++r) {
      auto& p = ring_power[r];
      if (!p.empty()) level_[r] = SelectNth(p.begin(), p.begin() + p.size() / 2, p.end());
    }
  }

  double r_lo() const { return r_lo_; }
  double r_hi() const { return r_hi_; }

  // One bin's power over its ring's level.
  double BinContrast(int fx, int fy) const { return Over(spectrum_.At(fx, fy), fx, fy); }
  // The largest of the 3 x 3 bins about (fx, fy) over the ring's level.
  double Contrast(double fx, double fy) const { return Over(spectrum_.PeakAt(fx, fy), fx, fy); }

 private:
  double Over(double power, double fx, double fy) const {
    const auto r = static_cast<std::size_t>(std::lround(std::hypot(fx, fy)));
    if (r == 0 || r >= level_.size() || !(level_[r] > 0.0)) return 0.0;
    return power / level_[r];
  }

  PowerSpectrum spectrum_;
  double r_lo_, r_hi_;
  std::vector<double> level_;
};

}  // namespace

std::optional<HalftoneScreen> FindHalftoneScreen(const cv::Mat& image) {
  int side = kScreenWindowPx;
  while (side > 64 && (side > image.cols || side > image.rows)) side /= 2;
  if (side < 128) return std::nullopt;
  const RingSpectrum spectrum(GreyWindow(image, {image.cols / 2, image.rows / 2}, side));
  const int n = side;

  // The strongest frequency against its ring, the block pattern left out.
  double best = 0.0;
  int best_fx = 0, best_fy = 0;
  for (int fy = 0; fy <= n / 2; ++fy) {
    for (int fx = -n / 2; fx < n / 2; ++fx) {
      const double r = std::hypot(fx, fy);
      if (r < spectrum.r_lo() || r > spectrum.r_hi() || OnJpegBlockPattern(fx, fy, n)) continue;
      const double c = spectrum.BinContrast(fx, fy);
      if (c > best) best = c, best_fx = fx, best_fy = fy;
    }
  }
  if (best < kMinScreenContrast) return std::nullopt;
  // A screen is a lattice: the same frequency turned a right angle is there
  // too. A comb of harmonics (a grid's lines, the centre axes' tick marks)
  // is not isolated: along the same direction a quarter nearer or further,
  // or at half the frequency (the comb's fundamental), it is as strong.
  if (spectrum.Contrast(-best_fy, best_fx) < 0.25 * best) return std::nullopt;
  const double comb = std::max({spectrum.Contrast(0.5 * best_fx, 0.5 * best_fy),
                                spectrum.Contrast(0.75 * best_fx, 0.75 * best_fy),
                                spectrum.Contrast(1.25 * best_fx, 1.25 * best_fy)});
  if (comb > 0.1 * best) return std::nullopt;
  // A screen covers the page, so its peak is a point. A periodic pattern in
  // a narrow strip (a chopped trace's dashes) is a ridge across the
  // spectrum: as strong a few bins to the side.
  const double r = std::hypot(best_fx, best_fy);
  const double side_x = -best_fy / r * kSideBins, side_y = best_fx / r * kSideBins;
  const double ridge = std::max(spectrum.Contrast(best_fx + side_x, best_fy + side_y),
                                spectrum.Contrast(best_fx - side_x, best_fy - side_y));
  if (ridge > 0.3 * best) return std::nullopt;
  // Dots are products of the two directions' waves, so their sum frequency
  // is there too; two separate combs have none.
  if (spectrum.Contrast(best_fx - best_fy, best_fy + best_fx) < kMinCrossContrast) {
    return std::nullopt;
  }
  HalftoneScreen screen;
  screen.period_px = n / r;
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
