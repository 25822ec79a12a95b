#include "signal/spectrum.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include <unsupported/Eigen/FFT>

#include "signal/signal_internal.h"

namespace impactlab {
namespace {

using signal_internal::kTwoPi;

std::size_t NextPowerOfTwo(double n) {
  std::size_t p = 1;
  while (static_cast<double>(p) < n) p <<= 1;
  return p;
}

// Symmetric Hann window of n points into `w`. The cosine advances by a
// rotation, re-seeded every 1024 points: a call to cos per point would cost
// more than the FFT.
void Hann(std::size_t n, std::vector<double>& w) {
  w.resize(n);
  const double step = kTwoPi / static_cast<double>(n - 1);
  const double cs = std::cos(step), sn = std::sin(step);
  for (std::size_t block = 0; block < n; block += 1024) {
    double c = std::cos(step * static_cast<double>(block));
    double s = std::sin(step * static_cast<double>(block));
    const std::size_t end = std::min(n, block + 1024);
    for (std::size_t i = block; i < end; ++i) {
      w[i] = 0.5 - 0.5 * c;
      const double next = c * cs - s * sn;
      s = s * cs + c * sn;
      c = next;
    }
  }
}

// Buffers reused from call to call on each thread: large fresh allocations
// cost page faults that outweigh the FFT itself.
struct Workspace {
  Eigen::FFT<double> fft;
  std::vector<double> detrended, window, windowed, padded;
  std::vector<double> segment_window, piece, power;
  std::vector<std::complex<double>> spectrum;
};

Workspace& ThreadWorkspace() {
  thread_local Workspace workspace;
  return workspace;
}

// One-sided |X_k|^2 of x times the window (none when empty), zero-padded to
// nfft, into `power`.
void PowerSpectrum(std::span<const double> x, const std::vector<double>& window, std::size_t nfft,
                   Workspace& work, std::vector<double>& power) {
  work.padded.assign(nfft, 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    work.padded[i] = window.empty() ? x[i] : x[i] * window[i];
  }
  work.fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  work.fft.fwd(work.spectrum, work.padded);
  power.resize(nfft / 2 + 1);
  for (std::size_t k = 0; k < power.size(); ++k) power[k] = std::norm(work.spectrum[k]);
}

// The maximum of |X(w)|^2, X the DTFT of the windowed record `wx`, by Newton
// steps from omega0 (rad/sample). Returns omega0 when a step leaves the lobe.
double RefineWindowed(std::span<const double> wx, double omega0, int iterations) {
  const std::size_t n = wx.size();
  const double centre = 0.5 * static_cast<double>(n - 1);
  const double bin = kTwoPi / static_cast<double>(n);
  double omega = omega0;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    // X = sum wx e^{-i w u}, X1 = dX/dw, X2 = d2X/dw2, u = i - centre. Four
    // phasors, one per lane of i mod 4, each advanced by e^{-4 i w}: four
    // independent chains instead of one serial rotation; re-seeded every 1024.
    double xr[4] = {}, xi[4] = {}, x1r[4] = {}, x1i[4] = {}, x2r[4] = {}, x2i[4] = {};
    const double cr = std::cos(4.0 * omega), ci = -std::sin(4.0 * omega);
    for (std::size_t block = 0; block < n; block += 1024) {
      double pr[4], pi[4];
      for (int lane = 0; lane < 4; ++lane) {
        const double u = static_cast<double>(block + lane) - centre;
        pr[lane] = std::cos(omega * u);
        pi[lane] = -std::sin(omega * u);
      }
      const std::size_t end = std::min(n, block + 1024);
      std::size_t i = block;
      for (; i + 4 <= end; i += 4) {
        for (int lane = 0; lane < 4; ++lane) {
          const double u = static_cast<double>(i + lane) - centre;
          const double ar = wx[i + lane] * pr[lane], ai = wx[i + lane] * pi[lane];
          xr[lane] += ar;
          xi[lane] += ai;
          x1r[lane] += u * ai;  // (-i u)(ar + i ai) = u ai - i u ar
          x1i[lane] -= u * ar;
          x2r[lane] -= u * u * ar;
          x2i[lane] -= u * u * ai;
          const double next = pr[lane] * cr - pi[lane] * ci;
          pi[lane] = pr[lane] * ci + pi[lane] * cr;
          pr[lane] = next;
        }
      }
      for (int lane = 0; i < end; ++i, ++lane) {  // the block's last few samples
        const double u = static_cast<double>(i) - centre;
        const double ar = wx[i] * pr[lane], ai = wx[i] * pi[lane];
        xr[0] += ar;
        xi[0] += ai;
        x1r[0] += u * ai;
        x1i[0] -= u * ar;
        x2r[0] -= u * u * ar;
        x2i[0] -= u * u * ai;
      }
    }
    const double sr = xr[0] + xr[1] + xr[2] + xr[3], si = xi[0] + xi[1] + xi[2] + xi[3];
    const double s1r = x1r[0] + x1r[1] + x1r[2] + x1r[3];
    const double s1i = x1i[0] + x1i[1] + x1i[2] + x1i[3];
    const double s2r = x2r[0] + x2r[1] + x2r[2] + x2r[3];
    const double s2i = x2i[0] + x2i[1] + x2i[2] + x2i[3];
    // P = |X|^2: P' = 2 Re(X1 X*), P'' = 2 Re(X2 X*) + 2 |X1|^2.
    const double d1 = 2.0 * (s1r * sr + s1i * si);
    const double d2 = 2.0 * (s2r * sr + s2i * si) + 2.0 * (s1r * s1r + s1i * s1i);
    if (!(d2 < 0.0)) break;  // not on the main lobe's cap: keep the estimate
    const double step = std::clamp(-d1 / d2, -0.25 * bin, 0.25 * bin);
    omega += step;
    if (std::abs(step) < 1e-13 * bin) break;
  }
  return std::abs(omega - omega0) > bin ? omega0 : omega;
}

// Scales |X_k|^2 to a one-sided PSD (units^2/Hz) for a window with sum w^2 = s2.
void ScaleToPsd(std::vector<double>& power, double sample_rate_hz, double s2) {
  const double scale = 1.0 / (sample_rate_hz * s2);
  for (std::size_t k = 0; k < power.size(); ++k) {
    const bool edge = k == 0 || k + 1 == power.size();
    power[k] *= (edge ? 1.0 : 2.0) * scale;
  }
}

// Vertex offset, in bins, of the parabola through three log levels.
double ParabolicOffset(double left, double centre, double right) {
  const double a = std::log(std::max(left, 1e-300));
  const double b = std::log(std::max(centre, 1e-300));
  const double c = std::log(std::max(right, 1e-300));
  const double denominator = a - 2.0 * b + c;
  if (!(denominator < 0.0)) return 0.0;
  return std::clamp(0.5 * (a - c) / denominator, -0.5, 0.5);
}

struct PeakCandidate {
  std::size_t bin;
  double psd;
};

}  // namespace

bool SpectrumOptions::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (!(zero_padding >= 1.0)) return fail("zero_padding must be at least 1");
  if (max_fft_points < 64) return fail("max_fft_points must be at least 64");
  if (welch_segment_samples < 16) return fail("welch_segment_samples must be at least 16");
  if (welch_min_segments < 2) return fail("welch_min_segments must be at least 2");
  if (!(min_frequency_hz >= 0.0) || !(max_frequency_hz >= 0.0)) {
    return fail("frequency limits must be >= 0 Hz");
  }
  if (max_frequency_hz > 0.0 && max_frequency_hz <= min_frequency_hz) {
    return fail("max_frequency_hz must exceed min_frequency_hz");
  }
  if (max_peaks < 1) return fail("max_peaks must be at least 1");
  if (!(peak_range_db > 0.0)) return fail("peak_range_db must be positive");
  if (!(min_peak_snr_db >= 0.0)) return fail("min_peak_snr_db must be >= 0");
  if (refine_iterations < 0) return fail("refine_iterations must be >= 0");
  return true;
}

void RemoveTrend(std::span<double> x, Detrend detrend) {
  const std::size_t n = x.size();
  if (detrend == Detrend::kNone || n == 0) return;
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  double slope = 0.0;
  const double centre = 0.5 * static_cast<double>(n - 1);
  if (detrend == Detrend::kLinear && n > 1) {
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double u = static_cast<double>(i) - centre;
      sxy += u * (x[i] - mean);
      sxx += u * u;
    }
    slope = sxy / sxx;
  }
  for (std::size_t i = 0; i < n; ++i) x[i] -= mean + slope * (static_cast<double>(i) - centre);
}

double RefinePeakFrequency(std::span<const double> x, double sample_rate_hz, double start_hz,
                           int iterations) {
  std::vector<double> wx;
  Hann(x.size(), wx);
  for (std::size_t i = 0; i < x.size(); ++i) wx[i] *= x[i];
  return RefineWindowed(wx, kTwoPi * start_hz / sample_rate_hz, iterations) * sample_rate_hz /
         kTwoPi;
}

Spectrum ComputeSpectrum(std::span<const double> samples, double sample_rate_hz,
                         const SpectrumOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("SpectrumOptions: " + error);
  }
  if (!(sample_rate_hz > 0.0)) throw std::invalid_argument("spectrum: sample rate must be > 0");
  const std::size_t n = samples.size();
  if (n < 16) throw std::invalid_argument("spectrum: a record needs at least 16 samples");

  Workspace& work = ThreadWorkspace();
  std::vector<double>& x = work.detrended;
  x.assign(samples.begin(), samples.end());
  RemoveTrend(x, options.detrend);

  // The whole record: Hann, zero-padded.
  std::size_t nfft = NextPowerOfTwo(options.zero_padding * static_cast<double>(n));
  while (nfft > options.max_fft_points && nfft / 2 >= n) nfft /= 2;
  Hann(n, work.window);
  double window_sum = 0.0, window_s2 = 0.0;
  work.windowed.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    window_sum += work.window[i];
    window_s2 += work.window[i] * work.window[i];
    work.windowed[i] = work.window[i] * x[i];
  }
  Spectrum spectrum;
  PowerSpectrum(work.windowed, {}, nfft, work, spectrum.psd);
  const double peak_amplitude_scale = 2.0 / window_sum;  // amplitude = this x |X_k|
  ScaleToPsd(spectrum.psd, sample_rate_hz, window_s2);
  const double power_per_psd = 0.5 * sample_rate_hz * window_s2;  // |X_k|^2 / psd, inside
  const double spacing_hz = sample_rate_hz / static_cast<double>(nfft);
  spectrum.frequency_hz.resize(spectrum.psd.size());
  for (std::size_t k = 0; k < spectrum.psd.size(); ++k) {
    spectrum.frequency_hz[k] = spacing_hz * static_cast<double>(k);
  }
  spectrum.resolution_hz = sample_rate_hz / static_cast<double>(n);

  // Welch's average of a long record, for plots of its floor.
  const std::size_t segment = options.welch_segment_samples;
  if (n >= options.welch_min_segments * segment) {
    Hann(segment, work.segment_window);
    double s2 = 0.0;
    for (double w : work.segment_window) s2 += w * w;
    std::vector<double> sum(segment / 2 + 1, 0.0);
    work.piece.resize(segment);
    int count = 0;
    for (std::size_t start = 0; start + segment <= n; start += segment / 2, ++count) {
      std::copy_n(x.begin() + static_cast<std::ptrdiff_t>(start), segment, work.piece.begin());
      RemoveTrend(work.piece, Detrend::kMean);
      PowerSpectrum(work.piece, work.segment_window, segment, work, work.power);
      for (std::size_t k = 0; k < sum.size(); ++k) sum[k] += work.power[k];
    }
    for (double& v : sum) v /= count;
    ScaleToPsd(sum, sample_rate_hz, s2);
    spectrum.welch_psd = std::move(sum);
    spectrum.welch_frequency_hz.resize(spectrum.welch_psd.size());
    for (std::size_t k = 0; k < spectrum.welch_psd.size(); ++k) {
      spectrum.welch_frequency_hz[k] = sample_rate_hz * static_cast<double>(k) / segment;
    }
    spectrum.segments_averaged = count;
  }

  // Peak search in the band, against the band's median level. A periodogram
  // bin of white noise exceeds t times its mean with probability e^-t: the
  // threshold keeps the chance of a noise peak anywhere in the band near 1e-3.
  const double nyquist = 0.5 * sample_rate_hz;
  const double lobe_hz = spectrum.resolution_hz;  // one bin of the record
  const double f_lo = options.min_frequency_hz > 0.0 ? options.min_frequency_hz : 3.0 * lobe_hz;
  const double f_hi =
      options.max_frequency_hz > 0.0 ? std::min(options.max_frequency_hz, nyquist) : 0.98 * nyquist;
  const auto k_lo =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(f_lo / spacing_hz)));
  const auto k_hi =
      std::min(spectrum.psd.size() - 2, static_cast<std::size_t>(std::floor(f_hi / spacing_hz)));
  if (k_lo >= k_hi) return spectrum;
  std::vector<double> band(spectrum.psd.begin() + static_cast<std::ptrdiff_t>(k_lo),
                           spectrum.psd.begin() + static_cast<std::ptrdiff_t>(k_hi) + 1);
  std::nth_element(band.begin(), band.begin() + static_cast<std::ptrdiff_t>(band.size() / 2),
                   band.end());
  const double median = band[band.size() / 2];
  const double independent_bins = (f_hi - f_lo) / lobe_hz + 1.0;
  const double false_alarm_db =
      10.0 * std::log10(std::log(independent_bins / 1e-3) / std::numbers::ln2);
  const double min_level =
      median * std::pow(10.0, 0.1 * std::max(options.min_peak_snr_db, false_alarm_db));

  std::vector<PeakCandidate> candidates;
  for (std::size_t k = k_lo; k <= k_hi; ++k) {
    const double p = spectrum.psd[k];
    if (p > spectrum.psd[k - 1] && p >= spectrum.psd[k + 1] && p >= min_level) {
      candidates.push_back({k, p});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const PeakCandidate& a, const PeakCandidate& b) { return a.psd > b.psd; });

  for (const PeakCandidate& candidate : candidates) {
    if (static_cast<int>(spectrum.peaks.size()) >= options.max_peaks) break;
    if (!spectrum.peaks.empty() &&
        candidate.psd < spectrum.peaks[0].psd * std::pow(10.0, -0.1 * options.peak_range_db)) {
      break;
    }
    const std::size_t k = candidate.bin;
    const double coarse_hz = spacing_hz * static_cast<double>(k);
    // A Hann main lobe spans +-2 bins, and its sidelobes stay under
    // 1 / (pi d (d^2 - 1)) of the peak at d bins: a candidate inside a chosen
    // peak's lobe, or not clearly (6 dB) above its sidelobes, is leakage.
    bool leakage = false;
    for (const SpectralPeak& chosen : spectrum.peaks) {
      const double d = std::abs(chosen.frequency_hz - coarse_hz) / lobe_hz;
      const double envelope = 1.0 / (std::numbers::pi * d * (d * d - 1.0));
      leakage = leakage || d < 2.5 || candidate.psd < 4.0 * envelope * envelope * chosen.psd;
    }
    if (leakage) continue;
    SpectralPeak peak;
    const std::vector<double>& p = spectrum.psd;  // |X_k|^2 up to a constant inside
    const double offset = ParabolicOffset(p[k - 1], p[k], p[k + 1]);
    peak.frequency_hz = spacing_hz * (static_cast<double>(k) + offset);
    if (options.refine_iterations > 0) {
      peak.frequency_hz = RefineWindowed(work.windowed, kTwoPi * peak.frequency_hz / sample_rate_hz,
                                         options.refine_iterations) *
                          sample_rate_hz / kTwoPi;
    }
    peak.psd = candidate.psd;
    peak.amplitude = peak_amplitude_scale * std::sqrt(power_per_psd * candidate.psd);
    spectrum.peaks.push_back(peak);
  }
  for (SpectralPeak& peak : spectrum.peaks) {
    peak.relative_db = 10.0 * std::log10(peak.psd / spectrum.peaks[0].psd);
  }
  return spectrum;
}

}  // namespace impactlab
