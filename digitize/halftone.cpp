#include "digitize/halftone.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "digitize/select.h"

namespace impactlab::digitize {

namespace {

// The spectrum is read in a square of this side (or the largest power of two
// that fits) from the photo's middle, where the screen is.
constexpr int kScreenTilePx = 256;
// Periods a halftone screen can have at a scan's resolution, pixels: finer
// ones are blurred away by the scan itself, coarser ones are not a print's.
constexpr double kMinScreenPeriodPx = 2.2, kMaxScreenPeriodPx = 16.0;
// A screen's fundamental stands this far above the median of its ring.
constexpr double kMinScreenContrast = 100.0;
// How far to the side of a peak a ridge is looked for, frequency bins (the
// window's main lobe reaches 2 bins, a peak's reading one more).
constexpr double kSideBins = 5.0;
// The strongest frequencies tried as a screen's, in order.
constexpr std::ptrdiff_t kScreenPeaksTried = 64;
// The lattice's sum frequency stands this far above its ring (measured:
// 76-34000 on printed figures, at most 17 for tick marks and textures).
constexpr double kMinCrossContrast = 10.0;
// A screen without its sum frequency (below) is taken only when its
// fundamental stands this far above its ring, its turned twin is as strong
// within these ratios, and nothing along the same direction below it (from
// 0.3 to 0.9 of its frequency: a comb's lower harmonics) reaches this share
// of it. Measured on the 55 generated prints of the randomised benchmark: 45
// screens found (16 by the sum frequency alone), and none in 262 photos
// without one (its 149 others, the external and sample photos; candidates
// there had twins at 0.32-0.81 of the peak, harmonics below at 0.10-0.69).
constexpr double kMinCleanScreenContrast = 150.0;
constexpr double kMinTwinRatio = 0.75, kMaxTwinRatio = 1.35;
constexpr double kMaxBelowShare = 0.3;
// A screen running along the grid's lines without its sum frequency (below)
// is taken when its sidebands stay under this share of its peak, its turned
// twin is within this ratio of it either way (each read as the largest of
// its 3 x 3 bins: the same dots), and nothing below it along its direction
// reaches this share (candidates with a sum frequency in photos without a
// screen had 0.52 or more, IsScreenPeak).
constexpr double kMaxAlongGridSidebands = 0.25;
constexpr double kMinAlongGridTwinRatio = 0.85;
constexpr double kMaxAlongGridBelowShare = 0.5;
// Before the four tiles are read, a screen is looked for in the top left
// one alone and then in the bottom right one alone, each asked for this
// share of the contrasts above (which are the four's): a screen covers the
// page, so in a tile that has ink it stands about as high as in the four's
// average. Only where either finds one are the four read. Measured with the
// four's own search on 338 photos (bench_robustness's 204, the external set's
// 110 and the sample's 24): 67 screens, every one found by the two, by the
// top left tile alone too (lowest contrast there at full thresholds 137,
// against 161 in the four); the bottom tiles alone missed 2 and 3 of the 46
// generated prints, whose dots lie only where they have ink; on the 271
// photos without a screen, the two found one on 15 (the four then did not).
constexpr double kOneTileShare = 0.25;

// The grey of the square of `side` pixels at `corner` into `out`.
void ReadGreyTile(const cv::Mat& image, cv::Point corner, int side, cv::Mat1f& out) {
  const cv::Mat crop = image(cv::Rect(corner.x, corner.y, side, side));
  cv::Mat grey;
  if (crop.channels() == 3) {
    cv::cvtColor(crop, grey, cv::COLOR_BGR2GRAY);
  } else if (crop.channels() == 4) {
    cv::cvtColor(crop, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = crop;
  }
  grey.convertTo(out, CV_32F, grey.depth() == CV_16U ? 1.0 / 65535 : 1.0 / 255);
}

// The power spectrum of the photo's middle, averaged over a 2 x 2 block of
// square tiles of `side` pixels (Welch's estimate: steadier than one
// window's, and a quarter of the memory, which a large transform spends
// mostly on fresh pages), or over some of them (Add: 0 top left, 1 top
// right, 2 bottom left, 3 bottom right). Each tile's mean is taken out and a
// Hann window put on, so that its edges add no spectral lines.
class PowerSpectrum {
 public:
  // No tile yet: zero power.
  PowerSpectrum(const cv::Mat& image, int side)
      : image_(image),
        n_(side),
        x0_(std::max(0, image.cols / 2 - side)),
        y0_(std::max(0, image.rows / 2 - side)),
        hann_(side),
        power_(cv::Mat1f::zeros(side, side)) {
    for (int i = 0; i < n_; ++i) {
      hann_[i] = static_cast<float>(0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * i / (n_ - 1)));
    }
  }

  // Adds tile `tile`'s power.
  void Add(int tile) {
    const cv::Point corner(x0_ + (tile % 2) * n_, y0_ + (tile / 2) * n_);
    cv::Mat1f grey;
    cv::Mat2f complex;
    ReadGreyTile(image_, corner, n_, grey);
    grey -= cv::mean(grey)[0];
    for (int r = 0; r < n_; ++r) {
      float* p = grey.ptr<float>(r);
      for (int c = 0; c < n_; ++c) p[c] *= hann_[r] * hann_[c];
    }
    cv::dft(grey, complex, cv::DFT_COMPLEX_OUTPUT);
    for (int r = 0; r < n_; ++r) {
      const cv::Vec2f* z = complex.ptr<cv::Vec2f>(r);
      float* p = power_.ptr<float>(r);
      for (int c = 0; c < n_; ++c) p[c] += z[c][0] * z[c][0] + z[c][1] * z[c][1];
    }
  }

  // Adds `other`'s power, bin by bin: a tile's power read once serves both
  // its own spectrum and the four's (its sum is the same, added in turn).
  void Add(const PowerSpectrum& other) { power_ += other.power_; }

  // A spectrum of its own with the same power.
  PowerSpectrum Clone() const {
    PowerSpectrum copy = *this;
    copy.power_ = power_.clone();
    return copy;
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
  // The powers, row by row (fy = 0 .. n - 1), each from fx = 0 to n - 1.
  const float* Data() const { return power_.ptr<float>(0); }

  int Wrap(double f) const {
    const int i = static_cast<int>(std::lround(f));
    return ((i % n_) + n_) % n_;
  }

 private:
  cv::Mat image_;  // shared, not copied
  int n_;
  int x0_, y0_;  // the 2 x 2 block's top left corner
  std::vector<float> hann_;
  cv::Mat1f power_;
};

// Frequencies of a JPEG's 8 x 8 block pattern: both components multiples
// of n / 8 (within a bin; n a power of two).
bool OnJpegBlockPattern(int fx, int fy, int n) {
  const int block = n / 8;
  const auto near_multiple = [block](int f) {
    const int r = ((f % block) + block) % block;
    return r <= 1 || r >= block - 1;
  };
  return near_multiple(fx) && near_multiple(fy);
}

// The ring a frequency lies on: its distance from zero, whole bins.
int RingOf(double fx, double fy) {
  return static_cast<int>(std::lround(std::sqrt(fx * fx + fy * fy)));
}

// Which bins of an n x n spectrum each ring holds, and which bins have the
// periods a screen can have: the same for every photo of a tile size, so
// laid out once (a tile's spectrum costs a third more when its rings are
// gathered afresh).
struct RingLayout {
  struct Bin {
    int fx, fy, ring;
    int index;              // row-major, into the spectrum
    bool on_block_pattern;  // OnJpegBlockPattern
  };

  explicit RingLayout(int n)
      : r_lo(n / kMaxScreenPeriodPx),
        r_hi(n / kMinScreenPeriodPx),
        rings(static_cast<int>(std::ceil(r_hi)) + 2) {
    // The upper half plane holds every frequency once (the spectrum is
    // symmetric); rings from half the lowest frequency, where a comb's
    // fundamental is looked at.
    const int ring_lo = static_cast<int>(std::floor(0.5 * r_lo)) - 1;
    const int ring_hi = rings - 1;
    std::vector<std::vector<int>> ring_bins(rings);
    for (int fy = 0; fy <= std::min(n / 2, ring_hi); ++fy) {
      for (int fx = -std::min(n / 2, ring_hi); fx <= std::min(n / 2 - 1, ring_hi); ++fx) {
        const double r = std::sqrt(static_cast<double>(fx * fx + fy * fy));
        const int ring = static_cast<int>(std::lround(r));  // RingOf
        if (ring < ring_lo || ring > ring_hi) continue;
        ring_bins[ring].push_back(fy * n + (fx < 0 ? fx + n : fx));
        if (r >= r_lo && r <= r_hi) {
          screen_bins.push_back(
              {fx, fy, ring, fy * n + (fx < 0 ? fx + n : fx), OnJpegBlockPattern(fx, fy, n)});
        }
      }
    }
    for (const std::vector<int>& bins : ring_bins) {
      ring_start.push_back(static_cast<int>(ring_index.size()));
      ring_index.insert(ring_index.end(), bins.begin(), bins.end());
    }
    ring_start.push_back(static_cast<int>(ring_index.size()));
  }

  // The layout for tiles of `n` pixels (128 or 256, kScreenTilePx halved).
  static const RingLayout& For(int n) {
    static const RingLayout whole(kScreenTilePx), half(kScreenTilePx / 2);
    return n == kScreenTilePx ? whole : half;
  }

  double r_lo, r_hi;  // the radii of a screen's periods, bins
  int rings;          // rings 0 .. rings - 1 have a level
  // Ring k's bins (row-major indices into the spectrum) are
  // ring_index[ring_start[k] .. ring_start[k + 1]).
  std::vector<int> ring_index, ring_start;
  std::vector<Bin> screen_bins;  // in rows from fy = 0, each from its lowest fx
};

// A window's power spectrum against each ring's median power (the level a
// peak must stand above), over the radii of a screen's periods.
class RingSpectrum {
 public:
  using Bin = RingLayout::Bin;

  explicit RingSpectrum(const PowerSpectrum& spectrum)
      : spectrum_(spectrum), layout_(RingLayout::For(spectrum_.n())), level_(layout_.rings, 0.0) {
    const float* power = spectrum_.Data();
    std::vector<float> ring_power(layout_.ring_index.size());
    for (std::size_t i = 0; i < ring_power.size(); ++i) {
      ring_power[i] = power[layout_.ring_index[i]];
    }
    for (int r = 0; r < layout_.rings; ++r) {
      const auto first = ring_power.begin() + layout_.ring_start[r];
      const auto last = ring_power.begin() + layout_.ring_start[r + 1];
      if (first != last) level_[r] = SelectNth(first, first + (last - first) / 2, last);
    }
  }

  // The bins whose periods a screen can have.
  const std::vector<Bin>& screen_bins() const { return layout_.screen_bins; }

  // One bin's power over its ring's level.
  double BinContrast(const Bin& bin) const {
    return level_[bin.ring] > 0.0 ? spectrum_.Data()[bin.index] / level_[bin.ring] : 0.0;
  }
  // The largest of the 3 x 3 bins about (fx, fy) over the ring's level.
  double Contrast(double fx, double fy) const {
    const int r = RingOf(fx, fy);
    if (r <= 0 || r >= static_cast<int>(level_.size()) || !(level_[r] > 0.0)) return 0.0;
    return spectrum_.PeakAt(fx, fy) / level_[r];
  }

 private:
  PowerSpectrum spectrum_;
  const RingLayout& layout_;
  std::vector<double> level_;
};

}  // namespace

namespace {

// Whether nothing along the direction of the peak at (fx, fy) below it
// (from 0.3 to 0.9 of its frequency) reaches kMaxBelowShare of its
// `contrast`: a comb of harmonics has its lower ones there, all the way
// down to its fundamental.
bool NothingBelow(const RingSpectrum& spectrum, int fx, int fy, double contrast,
                  double share = kMaxBelowShare) {
  const double r = std::sqrt(static_cast<double>(fx * fx + fy * fy));
  for (double t = 0.3; t <= 0.9; t += 0.5 / r) {
    if (spectrum.Contrast(t * fx, t * fy) >= share * contrast) return false;
  }
  return true;
}

// Whether the peak at (fx, fy), standing `contrast` above its ring, is a
// halftone screen's fundamental rather than anything else periodic; without
// its sum frequency only when `clean_peak_enough` (below). The contrasts
// asked for are `contrast_share` of the constants above.
bool IsScreenPeak(const RingSpectrum& spectrum, int fx, int fy, double contrast,
                  bool clean_peak_enough, double contrast_share) {
  // A screen is a lattice: the same frequency turned a right angle is there
  // too.
  if (spectrum.Contrast(-fy, fx) < 0.25 * contrast) return false;
  // A screen covers the page, so its peak is a point. A periodic pattern in
  // a narrow strip (a chopped trace's dashes) is a ridge across the
  // spectrum: as strong a few bins to the side.
  const double r = std::sqrt(static_cast<double>(fx * fx + fy * fy));
  const double side_x = -fy / r * kSideBins, side_y = fx / r * kSideBins;
  const double ridge = std::max(spectrum.Contrast(fx + side_x, fy + side_y),
                                spectrum.Contrast(fx - side_x, fy - side_y));
  if (ridge > 0.5 * contrast) return false;
  // Dots are products of the two directions' waves, so their sum frequency
  // is there too; two separate combs have none.
  const bool sum_frequency =
      spectrum.Contrast(fx - fy, fy + fx) >= contrast_share * kMinCrossContrast;
  // A comb of harmonics (a grid's lines, the centre axes' tick marks) is not
  // isolated: along the same direction a quarter nearer or further, or at
  // half the frequency (the comb's fundamental), it is as strong.
  const double comb =
      std::max({spectrum.Contrast(0.5 * fx, 0.5 * fy), spectrum.Contrast(0.75 * fx, 0.75 * fy),
                spectrum.Contrast(1.25 * fx, 1.25 * fy)});
  if (comb > 0.1 * contrast) {
    // Or a screen running along the grid's lines: the figure modulates its
    // dots (a row of them inked on every grid line), which puts sidebands
    // beside its peak at multiples of the grid's frequency, and where the
    // screen's direction is the lines' they fall where a comb's neighbouring
    // harmonics would (randomised seed 1018's run 0.405, a 6.3 px screen 3
    // degrees off the grid: a fifth of its peak at 1.25 times its
    // frequency; none of its prints was found so). A comb has its lower
    // harmonics all the way down, a screen nothing: with its sum frequency
    // and nothing below it, the peak is a screen's. Measured: on the
    // randomised benchmark's 149 photos without a screen and the 113
    // external and sample ones, the 460 candidate peaks with a sum
    // frequency had 0.52 of their height or more below them.
    if (sum_frequency && NothingBelow(spectrum, fx, fy, contrast)) return true;
    // Or such a screen without its sum frequency (its dots' transform
    // vanishing there): a screen's fundamental, as strong turned a right
    // angle as the same dots make it, standing well above everything along
    // its direction below it. A comb of lines has its lower harmonics as
    // strong as its higher ones or stronger (a line's transform falls with
    // frequency), and a square grid's harmonic has its turned twin too
    // (randomised seed 1009's calibration, a 6.7 px screen 2.4
    // degrees off the grid at the grid's 7th harmonic: sidebands 0.12 of
    // its peak, its sum frequency 3 above its ring, 0.39 of it below, its
    // twin 1.01; read as a photo, its lattice was refused at 1.68 px RMS,
    // descreened it is within 0.2 px of the true mapping at 0.36 px RMS).
    if (!clean_peak_enough || comb > kMaxAlongGridSidebands * contrast ||
        contrast < contrast_share * kMinCleanScreenContrast) {
      return false;
    }
    // Both read alike, each the largest of its 3 x 3 bins.
    const double twin = spectrum.Contrast(-fy, fx) / spectrum.Contrast(fx, fy);
    return twin >= kMinAlongGridTwinRatio && twin <= 1.0 / kMinAlongGridTwinRatio &&
           NothingBelow(spectrum, fx, fy, contrast, kMaxAlongGridBelowShare);
  }
  if (sum_frequency) return true;
  if (!clean_peak_enough) return false;
  // Except where the dots hide it: a round dot's transform (a jinc) vanishes
  // at the sum frequency when its radius is 0.43 of the period (ink cover
  // 0.58, common on a grid line's dots once the ink spreads), and a screen
  // finer than 3.1 px has its sum frequency beyond the periods searched. A
  // figure printed on blank paper has dots only where it has ink (lines and
  // traces), so its screen is no brighter than that. Such a screen is told
  // from a comb by its clean peak: as strong turned a right angle (the same
  // dots), and nothing along its direction below it, where a comb of
  // harmonics has its lower ones.
  if (contrast < contrast_share * kMinCleanScreenContrast) return false;
  const double twin = spectrum.Contrast(-fy, fx) / contrast;
  if (twin < kMinTwinRatio || twin > kMaxTwinRatio) return false;
  return NothingBelow(spectrum, fx, fy, contrast);
}

// The screen in `power` (a tile's spectrum, or the four's), its contrasts
// asked for at `contrast_share` of the constants above.
std::optional<HalftoneScreen> SearchScreen(const PowerSpectrum& power, double contrast_share) {
  const RingSpectrum spectrum(power);
  const int n = power.n();

  // The frequencies standing out of their rings, the strongest first (the
  // block pattern left out); the first that is a screen's is taken: a
  // centre axis's ticks may stand higher than a faint screen.
  struct Peak {
    double contrast;
    int fx, fy;
  };
  std::vector<Peak> peaks;
  for (const RingSpectrum::Bin& bin : spectrum.screen_bins()) {
    if (bin.on_block_pattern) continue;
    const double c = spectrum.BinContrast(bin);
    if (c >= contrast_share * kMinScreenContrast) peaks.push_back({c, bin.fx, bin.fy});
  }
  const auto tried = peaks.begin() + std::min<std::ptrdiff_t>(kScreenPeaksTried, peaks.size());
  std::partial_sort(peaks.begin(), tried, peaks.end(),
                    [](const Peak& a, const Peak& b) { return a.contrast > b.contrast; });
  // Screens with their sum frequency first, over all the peaks tried; a
  // clean peak without it only when none has one.
  for (const bool clean_peak_enough : {false, true}) {
    for (auto peak = peaks.begin(); peak != tried; ++peak) {
      if (!IsScreenPeak(spectrum, peak->fx, peak->fy, peak->contrast, clean_peak_enough,
                        contrast_share)) {
        continue;
      }
      HalftoneScreen screen;
      screen.period_px =
          n / std::sqrt(static_cast<double>(peak->fx * peak->fx + peak->fy * peak->fy));
      // The image's rows run down: a frequency (fx, fy) is a lattice direction
      // of atan2(-fy, fx) on the page; folded into [0, 90).
      double angle = std::atan2(-peak->fy, peak->fx) * 180.0 / std::numbers::pi;
      angle = std::fmod(std::fmod(angle, 90.0) + 90.0, 90.0);
      screen.angle_deg = angle;
      screen.contrast = peak->contrast;
      return screen;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<HalftoneScreen> FindHalftoneScreen(const cv::Mat& image) {
  int side = kScreenTilePx;
  while (side > 64 && (2 * side > image.cols || 2 * side > image.rows)) side /= 2;
  if (side < 128) return std::nullopt;
  // Two tiles alone, each with its contrasts asked for at kOneTileShare,
  // decide whether the four are read: half the transforms on a photo
  // without a screen. The screen is always the four's, their powers added
  // in the same order (0, 1, 2, 3) whichever were read first.
  PowerSpectrum top_left(image, side);
  top_left.Add(0);
  std::optional<PowerSpectrum> bottom_right;
  if (!SearchScreen(top_left, kOneTileShare)) {
    bottom_right.emplace(image, side);
    bottom_right->Add(3);
    if (!SearchScreen(*bottom_right, kOneTileShare)) return std::nullopt;
  }
  PowerSpectrum four = top_left.Clone();
  four.Add(1);
  four.Add(2);
  if (bottom_right) {
    four.Add(*bottom_right);
  } else {
    four.Add(3);
  }
  return SearchScreen(four, 1.0);
}

cv::Mat Descreen(const cv::Mat& image, const HalftoneScreen& screen) {
  cv::Mat out;
  cv::GaussianBlur(image, out, cv::Size(), 0.35 * screen.period_px);
  return out;
}

}  // namespace impactlab::digitize
