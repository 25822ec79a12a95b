// Spectra of log channels: a Hann-windowed, zero-padded FFT of one record, the
// dominant frequency refined far below the bin width, and the next peaks
// (docs/logs.md, "Spectra").
//
// Window: Hann. Its first sidelobe is -31 dB and sidelobes fall as 1/f^3, so a
// strong mode does not bury a weak one a few bins away (a rectangular window's
// -13 dB, 1/f sidelobes do), and its smooth main lobe is what makes peak
// interpolation accurate; the cost is a main lobe twice as wide (+-2 bins).
// For a real signal whose envelope is real (a damped sinusoid) the windowed
// magnitude spectrum is symmetric about the tone, so its maximum is the damped
// frequency itself.
//
// Peak frequencies, in three steps: the largest bin of the zero-padded
// spectrum (x8 up to max_fft_points, then less: long records need no padding);
// a parabola through the log magnitudes of that bin and its neighbours; then
// Newton steps on |X(f)|^2, X the record's windowed DTFT evaluated directly
// (derivatives in closed form, O(N) per step) - the exact maximum, free of the
// interpolation's bias (~1e-5 bin on a clean tone, where the negative-frequency
// image's sidelobes still pull).
//
// Peaks are searched on the record's own spectrum (its resolution, 1 /
// duration, is what separates modes), above a threshold set so that white
// noise gives a false peak anywhere in the band with probability ~1e-3 (and
// at least `min_peak_snr_db` above the band's median).
//
// Welch averaging (Hann segments of `welch_segment_samples`, 50 % overlap) is
// added for records holding at least `welch_min_segments` segments: its floor
// has a fraction of the single periodogram's variance, which is what a plot
// of a long, noisy record needs; it takes no part in the peak estimates, whose
// precision needs the whole record.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace impactlab {

enum class Detrend {
  kNone,
  kMean,    // accelerometers: bias
  kLinear,  // angles: a joint turning at constant speed is a ramp
};

struct SpectrumOptions {
  double zero_padding = 8.0;  // FFT length >= this times the record (next power of two)
  std::size_t max_fft_points = std::size_t{1} << 17;  // padding shrinks (to none) to stay below
  Detrend detrend = Detrend::kLinear;                 // removed before windowing
  std::size_t welch_segment_samples = 4096;           // Welch segment length, samples
  std::size_t welch_min_segments = 8;                 // Welch is added from this many segments on
  double min_frequency_hz = 0.0;  // peaks below are ignored (0: 3 bins, above the DC lobe)
  double max_frequency_hz = 0.0;  // peaks above are ignored (0: 0.98 of Nyquist)
  int max_peaks = 5;              // the dominant peak and up to max_peaks - 1 more
  double peak_range_db = 40.0;    // next peaks at most this far below the dominant, dB
  double min_peak_snr_db = 13.0;  // peaks at least this far above the band's median level, dB
  int refine_iterations = 3;      // Newton steps on the DTFT for each peak (0: none)

  // The settings; the detrend is chosen per channel by the log analysis.
  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("zero_padding", self.zero_padding, "FFT length at least this times the record");
    visit("max_fft_points", self.max_fft_points, "padding shrinks to stay below");
    visit("welch_segment_samples", self.welch_segment_samples, "Welch segment length, samples");
    visit("welch_min_segments", self.welch_min_segments, "Welch is added from this many segments");
    visit("min_frequency_hz", self.min_frequency_hz, "peaks below are ignored, Hz (0: 3 bins)");
    visit("max_frequency_hz", self.max_frequency_hz, "peaks above are ignored, Hz (0: Nyquist)");
    visit("max_peaks", self.max_peaks, "the dominant peak and up to this many - 1 more");
    visit("peak_range_db", self.peak_range_db, "next peaks at most this far below, dB");
    visit("min_peak_snr_db", self.min_peak_snr_db, "peaks at least this far above the median, dB");
    visit("refine_iterations", self.refine_iterations, "Newton steps on the DTFT per peak");
  }

  bool Check(std::string* error) const;
};

struct SpectralPeak {
  double frequency_hz = 0.0;
  double psd = 0.0;          // units^2/Hz at the peak's bin
  double relative_db = 0.0;  // 10 log10(psd / dominant psd); 0 for the dominant
  double amplitude = 0.0;    // amplitude of a steady sinusoid with this peak, units
};

struct Spectrum {
  std::vector<double> frequency_hz;        // one-sided grid, 0 .. Nyquist (zero-padded spacing)
  std::vector<double> psd;                 // one-sided power spectral density, units^2/Hz
  double resolution_hz = 0.0;              // bin width of the record, 1 / duration
  std::vector<double> welch_frequency_hz;  // long records only: Welch's grid, Hz
  std::vector<double> welch_psd;           // and its averaged PSD, units^2/Hz
  int segments_averaged = 0;               // Welch segments (0: no Welch average)
  std::vector<SpectralPeak> peaks;         // [0] the dominant, then by decreasing psd
};

// Throws std::invalid_argument for bad options, a rate <= 0 or fewer than 16 samples.
Spectrum ComputeSpectrum(std::span<const double> samples, double sample_rate_hz,
                         const SpectrumOptions& options);

// The maximum of the Hann-windowed record's |DTFT| nearest `start_hz` (within
// its main lobe), by Newton steps; the record should be detrended already.
double RefinePeakFrequency(std::span<const double> samples, double sample_rate_hz, double start_hz,
                           int iterations);

// Removes the mean or the least-squares line, in place.
void RemoveTrend(std::span<double> samples, Detrend detrend);

}  // namespace impactlab
