#include "signal/log_analysis.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "io/errors.h"

namespace impactlab {
namespace {

// The channels of one source at the analysis rate, held in memory.
struct AnalysisSeries {
  double start_time_s = 0.0;
  double rate_hz = 0.0;  // analysis rate
  int decimation = 1;
  std::vector<std::vector<double>> values;  // [channel][sample]
  LogReadReport read;

  std::size_t size() const { return values.empty() ? 0 : values.front().size(); }
  double TimeOf(double sample) const { return start_time_s + sample / rate_hz; }
};

// Pass 1: every channel, decimated on the fly when the log would not fit.
AnalysisSeries ReadForAnalysis(const Log& log, const LogRecord& record,
                               const LogAnalysisOptions& options) {
  AnalysisSeries series;
  series.values.resize(log.channels.size());
  std::vector<StreamingDecimator> decimators;
  series.read = record([&](const LogBlock& block) {
    if (decimators.empty()) {
      const auto budget = static_cast<long long>(options.max_analysis_samples);
      series.decimation =
          static_cast<int>(std::max<long long>(1, (block.estimated_samples + budget - 1) / budget));
      for (std::size_t c = 0; c < log.channels.size(); ++c) {
        decimators.emplace_back(series.decimation);
        series.values[c].reserve(
            static_cast<std::size_t>(block.estimated_samples / series.decimation + 64));
      }
    }
    for (std::size_t c = 0; c < log.channels.size(); ++c) {
      decimators[c].Push(block.values[c], series.values[c]);
    }
  });
  for (std::size_t c = 0; c < decimators.size(); ++c) decimators[c].Finish(series.values[c]);
  series.start_time_s = series.read.first_time_s;
  series.rate_hz = 1.0 / (series.read.mean_interval_s * series.decimation);
  return series;
}

std::vector<ChannelSamples> SamplesOf(const Log& log,
                                      const std::vector<std::vector<double>>& values) {
  std::vector<ChannelSamples> samples;
  for (std::size_t c = 0; c < log.channels.size(); ++c) {
    samples.push_back({log.channels[c].name, KindOf(log.channels[c]), values[c]});
  }
  return samples;
}

// Pass 2 (decimated logs): the full-rate samples around the coarse instant.
ImpactEstimate RefineImpact(const Log& log, const LogRecord& record, const AnalysisSeries& series,
                            const ImpactEstimate& coarse, const LogAnalysisOptions& options) {
  const double file_rate = 1.0 / series.read.mean_interval_s;
  const double reach_s =
      1.2 * std::max(options.impact.onset_search_s,
                     options.impact.encoder_fit_s + options.impact.encoder_gap_s) +
      4.0 * series.decimation / file_rate;
  const auto centre =
      static_cast<long long>(std::llround((coarse.time_s.value - series.start_time_s) * file_rate));
  const auto reach = static_cast<long long>(std::ceil(reach_s * file_rate));
  const long long first = std::max<long long>(0, centre - reach), last = centre + reach;
  std::vector<std::vector<double>> window(log.channels.size());
  record([&](const LogBlock& block) {
    const long long begin = std::max(first, block.first_sample);
    const long long end =
        std::min(last, block.first_sample + static_cast<long long>(block.time_s.size()));
    for (long long i = begin; i < end; ++i) {
      for (std::size_t c = 0; c < window.size(); ++c) {
        window[c].push_back(block.values[c][static_cast<std::size_t>(i - block.first_sample)]);
      }
    }
  });
  ImpactEstimate fine = DetectImpact(SamplesOf(log, window),
                                     series.start_time_s + static_cast<double>(first) / file_rate,
                                     file_rate, options.impact);
  if (!fine.found) return coarse;
  // Sample indices in the analysis series, like the coarse estimate's.
  auto analysis_sample = [&](double time_s) {
    return static_cast<long long>(std::ceil((time_s - series.start_time_s) * series.rate_hz));
  };
  fine.sample = analysis_sample(fine.time_s.value);
  for (ChannelImpact& channel : fine.channels) {
    if (channel.found) channel.sample = analysis_sample(channel.time_s.value);
  }
  return fine;
}

// Max-hold per bucket over [0, band], so peaks survive.
void MaxHold(std::vector<double>& frequency_hz, std::vector<double>& psd, double band_hz,
             std::size_t points) {
  std::size_t n = psd.size();
  while (n > 2 && frequency_hz[n - 1] > band_hz) --n;
  const std::size_t size = std::max<std::size_t>(1, (n + points - 1) / points);
  std::vector<double> f, p;
  for (std::size_t begin = 0; begin < n; begin += size) {
    const std::size_t end = std::min(n, begin + size);
    const auto top = std::max_element(psd.begin() + static_cast<std::ptrdiff_t>(begin),
                                      psd.begin() + static_cast<std::ptrdiff_t>(end));
    f.push_back(frequency_hz[static_cast<std::size_t>(top - psd.begin())]);
    p.push_back(*top);
  }
  frequency_hz = std::move(f);
  psd = std::move(p);
}

// The spectrum kept for plots: up to `plot_max_frequency_hz` (or 5 times its
// highest peak), about `points` points; the peaks as computed.
void DecimateSpectrum(Spectrum& spectrum, const LogAnalysisOptions& options) {
  double band_hz = options.plot_max_frequency_hz;
  if (band_hz <= 0.0) {
    band_hz = spectrum.frequency_hz.back();
    double highest = 0.0;
    for (const SpectralPeak& peak : spectrum.peaks) highest = std::max(highest, peak.frequency_hz);
    if (highest > 0.0)
      band_hz = std::min(band_hz, std::max(5.0 * highest, 50.0 * spectrum.resolution_hz));
  }
  MaxHold(spectrum.frequency_hz, spectrum.psd, band_hz, options.plot_points);
  if (!spectrum.welch_psd.empty()) {
    MaxHold(spectrum.welch_frequency_hz, spectrum.welch_psd, band_hz, options.plot_points);
  }
}

// Sample ranges of the segments, [begin, end) at the analysis rate.
struct Segment {
  const char* name;
  std::size_t begin, end;
};

std::vector<Segment> SegmentsOf(const AnalysisSeries& series, const ImpactEstimate& impact,
                                const LogAnalysisOptions& options) {
  const std::size_t n = series.size();
  std::vector<Segment> segments = {{"whole", 0, n}};
  if (!impact.found) return segments;
  const double at = (impact.time_s.value - series.start_time_s) * series.rate_hz;
  const auto guard = options.free_flight_guard_s * series.rate_hz;
  const auto free_end =
      static_cast<std::size_t>(std::clamp(std::floor(at - guard), 0.0, double(n)));
  const auto post_begin = static_cast<std::size_t>(std::clamp(std::ceil(at), 0.0, double(n)));
  segments.push_back({"free_flight", 0, free_end});
  segments.push_back({"post_impact", post_begin, n});
  return segments;
}

// The highest frequency the fit should consider: above the leading peaks.
double FitBandLimit(const std::vector<SpectralPeak>& peaks, double rate_hz,
                    const LogAnalysisOptions& options) {
  if (options.modes.max_frequency_hz > 0.0) return options.modes.max_frequency_hz;
  double highest = 0.0;
  const auto leading =
      std::min<std::size_t>(peaks.size(), options.modes.modes + options.modes.extra_modes);
  for (std::size_t i = 0; i < leading; ++i) highest = std::max(highest, peaks[i].frequency_hz);
  if (highest <= 0.0) return 0.45 * rate_hz;
  return std::min(0.45 * rate_hz, std::max(1.5 * highest, 2.0 * peaks[0].frequency_hz));
}

// The ring-down fit on [begin, end) of one channel, decimated when long.
void FitRingDown(std::span<const double> values, std::size_t begin, std::size_t end,
                 const AnalysisSeries& series, const LogAnalysisOptions& options,
                 ChannelAnalysis& channel) {
  DampedModeOptions modes = options.modes;
  modes.max_frequency_hz = FitBandLimit(channel.peaks, series.rate_hz, options);
  const std::size_t n = end - begin;
  // The FIR stays flat to 0.35 of its output rate: the band must fit below.
  const int allowed = std::max(1, static_cast<int>(0.35 * series.rate_hz / modes.max_frequency_hz));
  int factor = static_cast<int>((n + options.max_fit_samples - 1) / options.max_fit_samples);
  factor = std::clamp(factor, 1, allowed);
  std::size_t used = n;
  if (factor > 1) {
    used = std::min(n, (options.max_fit_samples + 2 * kDecimationEdgeSamples) * factor);
  } else {
    used = std::min(n, options.max_fit_samples);
  }
  if (used < n) {
    channel.notes.push_back(fmt::format("ring-down fit uses the first {:.3f} s of {:.3f} s",
                                        used / series.rate_hz, n / series.rate_hz));
  }
  std::vector<double> window(values.begin() + static_cast<std::ptrdiff_t>(begin),
                             values.begin() + static_cast<std::ptrdiff_t>(begin + used));
  double start = static_cast<double>(begin);
  if (factor > 1) {
    // The decimator holds the edge sample past either end: drop what it reaches.
    std::vector<double> decimated = Decimate(window, factor);
    const std::size_t edge = std::min<std::size_t>(kDecimationEdgeSamples, decimated.size() / 4);
    window.assign(decimated.begin() + static_cast<std::ptrdiff_t>(edge),
                  decimated.end() - static_cast<std::ptrdiff_t>(edge));
    start += static_cast<double>(edge * factor);
  }
  channel.ring_down_start_s = series.TimeOf(start);
  channel.ring_down_rate_hz = series.rate_hz / factor;
  channel.ring_down = FitDampedModes(window, channel.ring_down_rate_hz, modes);
  const DampedModeFit& fit = channel.ring_down;
  if (!fit.ok || fit.modes.empty()) return;

  // The cross-check's FFT: the fit's own samples, up to 4 time constants of
  // its strongest mode - beyond, a Hann window over a long tail of noise would
  // weigh the ring-down by its near-zero edge.
  const double decay = fit.modes[0].decay_rate_per_s;
  std::size_t length = window.size();
  if (decay > 0.0) {
    length = std::clamp<std::size_t>(
        static_cast<std::size_t>(std::ceil(4.0 / decay * channel.ring_down_rate_hz)), 64,
        window.size());
  }
  SpectrumOptions spectrum = options.spectrum;
  spectrum.detrend = Detrend::kMean;
  const std::span<const double> ring(window.data(), std::min(length, window.size()));
  if (ring.size() < 16) return;
  const Spectrum check = ComputeSpectrum(ring, channel.ring_down_rate_hz, spectrum);
  if (!check.peaks.empty()) {
    channel.fft_frequency_hz = check.peaks[0].frequency_hz;
    channel.fft_resolution_hz = check.resolution_hz;
  }
}

// Whether a fitted mode is an oscillation: it completes `min_cycles_per_decay`
// periods while its amplitude changes by e (f / |sigma|, sigma its decay rate;
// a growing mode, zeta < 0, likewise) and `min_window_cycles` periods within
// the window of `window_s`.
bool Oscillates(const DampedMode& mode, double window_s, const LogAnalysisOptions& options) {
  const double f = mode.frequency_hz.value;
  return f * window_s >= options.min_window_cycles &&
         f >= options.min_cycles_per_decay * std::abs(mode.decay_rate_per_s);
}

// Dominant frequency and damping: the oscillating fitted mode nearest the
// ring-down's FFT peak (the strongest when the ring-down shows no peak);
// none when no fitted mode oscillates.
void CrossCheck(const LogAnalysisOptions& options, ChannelAnalysis& channel) {
  const DampedModeFit& fit = channel.ring_down;
  if (!fit.ok || fit.modes.empty()) {
    const std::string& why = fit.ok ? fit.note : fit.reason;
    if (!why.empty()) channel.notes.push_back("ring-down fit: " + why);
    return;
  }
  const double window_s = fit.samples / channel.ring_down_rate_hz;
  std::vector<std::size_t> oscillating;
  for (std::size_t k = 0; k < fit.modes.size(); ++k) {
    if (Oscillates(fit.modes[k], window_s, options)) oscillating.push_back(k);
  }
  if (oscillating.empty()) {
    const DampedMode& strongest = fit.modes[0];
    channel.dominant_frequency_hz.reset();
    channel.damping_ratio.reset();
    channel.frequency_source.clear();
    channel.notes.push_back(fmt::format(
        "no oscillation: the ring-down's strongest mode ({:.4g} Hz, zeta {:.3g}) completes "
        "{:.2g} periods while its amplitude changes by e and {:.2g} in the {:.3g} s window "
        "(an oscillation needs {:.3g} and {:.3g}); no dominant frequency",
        strongest.frequency_hz.value, strongest.damping_ratio.value,
        strongest.decay_rate_per_s != 0.0
            ? strongest.frequency_hz.value / std::abs(strongest.decay_rate_per_s)
            : std::numeric_limits<double>::infinity(),
        strongest.frequency_hz.value * window_s, window_s, options.min_cycles_per_decay,
        options.min_window_cycles));
    return;
  }
  if (channel.fft_frequency_hz <= 0.0) {
    const DampedMode& mode = fit.modes[oscillating.front()];
    channel.dominant_frequency_hz = mode.frequency_hz;
    channel.damping_ratio = mode.damping_ratio;
    channel.frequency_source = "fit";
    channel.notes.push_back(
        "no spectral peak above the noise; the fit's strongest oscillating mode is used");
    return;
  }
  std::size_t nearest = oscillating.front();
  for (std::size_t k : oscillating) {
    if (std::abs(fit.modes[k].frequency_hz.value - channel.fft_frequency_hz) <
        std::abs(fit.modes[nearest].frequency_hz.value - channel.fft_frequency_hz)) {
      nearest = k;
    }
  }
  const DampedMode& mode = fit.modes[nearest];
  const double difference = mode.frequency_hz.value - channel.fft_frequency_hz;
  const double sigma = mode.frequency_hz.sigma *
                       std::sqrt(1.0 + options.fft_sigma_factor * options.fft_sigma_factor);
  const double tolerance = std::max(options.mismatch_sigmas * sigma,
                                    options.mismatch_min_bins * channel.fft_resolution_hz);
  channel.frequency_mismatch = std::abs(difference) > tolerance;
  if (channel.frequency_mismatch) {
    channel.notes.push_back(fmt::format(
        "FFT peak {:.5g} Hz and fitted {:.5g} Hz disagree by {:.3g} Hz (tolerance {:.3g} Hz)",
        channel.fft_frequency_hz, mode.frequency_hz.value, difference, tolerance));
  }
  if (nearest != 0) {
    channel.notes.push_back(
        fmt::format("the FFT's dominant peak is the fit's mode {} by energy ({:.5g} Hz holds more)",
                    nearest + 1, fit.modes[0].frequency_hz.value));
  }
  if (!fit.covariance_ok) channel.notes.push_back("ring-down fit: " + fit.note);
  channel.dominant_frequency_hz = mode.frequency_hz;
  channel.damping_ratio = mode.damping_ratio;
  channel.frequency_source = "fit";
}

ChannelAnalysis AnalyseChannel(const LogChannel& manifest_channel, std::span<const double> values,
                               const AnalysisSeries& series, const ImpactEstimate& impact,
                               const LogAnalysisOptions& options) {
  ChannelAnalysis channel;
  channel.name = manifest_channel.name;
  channel.kind = KindOf(manifest_channel);
  channel.units = UnitsOf(channel.kind);
  channel.series =
      MinMaxDecimate(values, series.start_time_s, 1.0 / series.rate_hz, options.plot_points);

  SpectrumOptions spectrum_options = options.spectrum;
  spectrum_options.detrend =
      channel.kind == LogChannelKind::kAngle ? Detrend::kLinear : Detrend::kMean;
  for (const Segment& segment : SegmentsOf(series, impact, options)) {
    if (segment.end < segment.begin + 16) {
      channel.notes.push_back(fmt::format("segment {} is too short for a spectrum", segment.name));
      continue;
    }
    SegmentSpectrum entry;
    entry.segment = segment.name;
    entry.start_s = series.TimeOf(static_cast<double>(segment.begin));
    entry.end_s = series.TimeOf(static_cast<double>(segment.end - 1));
    entry.spectrum = ComputeSpectrum(values.subspan(segment.begin, segment.end - segment.begin),
                                     series.rate_hz, spectrum_options);
    const bool is_reference = entry.segment == (impact.found ? "post_impact" : "whole");
    if (is_reference) {
      channel.peaks = entry.spectrum.peaks;
      if (!channel.peaks.empty()) {
        channel.fft_frequency_hz = channel.peaks[0].frequency_hz;
        channel.dominant_frequency_hz = Estimate{channel.fft_frequency_hz, 0.0};
        channel.frequency_source = "fft " + entry.segment;
      }
      channel.fft_resolution_hz = entry.spectrum.resolution_hz;
    }
    DecimateSpectrum(entry.spectrum, options);
    channel.spectra.push_back(std::move(entry));
  }
  if (!impact.found) {
    channel.notes.push_back("no impact found: no ring-down fit; spectrum of the whole record");
    return channel;
  }
  // On a decimated series the FIR spreads the impact's spike over its reach.
  const auto delay = static_cast<std::size_t>(std::ceil(options.fit_delay_s * series.rate_hz)) +
                     (series.decimation > 1 ? kDecimationEdgeSamples : 0);
  const std::size_t begin = static_cast<std::size_t>(std::max<long long>(0, impact.sample)) + delay;
  std::size_t end = series.size();
  if (options.fit_max_duration_s > 0.0) {
    end = std::min(end,
                   begin + static_cast<std::size_t>(options.fit_max_duration_s * series.rate_hz));
  }
  if (begin >= end) {
    channel.notes.push_back("no samples after the impact for a ring-down fit");
    return channel;
  }
  FitRingDown(values, begin, end, series, options, channel);
  CrossCheck(options, channel);
  return channel;
}

struct SourceResult {
  SourceAnalysis analysis;
  AnalysisSeries series;
};

SourceResult Analyse(const Log& log, LogSource source, const LogRecord& record,
                     const LogAnalysisOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  SourceResult result;
  SourceAnalysis& analysis = result.analysis;
  analysis.source = source;
  result.series = ReadForAnalysis(log, record, options);
  analysis.file = result.series.read.file;
  AnalysisSeries& series = result.series;
  analysis.read = series.read;
  analysis.sample_rate_hz = 1.0 / series.read.mean_interval_s;
  analysis.decimation = series.decimation;

  analysis.impact = DetectImpact(SamplesOf(log, series.values), series.start_time_s, series.rate_hz,
                                 options.impact);
  if (analysis.impact.found && series.decimation > 1) {
    analysis.impact = RefineImpact(log, record, series, analysis.impact, options);
  }
  for (std::size_t c = 0; c < log.channels.size(); ++c) {
    analysis.channels.push_back(
        AnalyseChannel(log.channels[c], series.values[c], series, analysis.impact, options));
  }
  analysis.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

// RMS of experiment(t) - simulation(t + shift) where both exist.
std::pair<double, double> RmsDifference(const std::vector<double>& experiment,
                                        const AnalysisSeries& e,
                                        const std::vector<double>& simulation,
                                        const AnalysisSeries& s, double shift_s) {
  if (simulation.size() < 2) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
  double sum = 0.0;
  long long count = 0;
  double first = 0.0, last = 0.0;
  for (std::size_t i = 0; i < experiment.size(); ++i) {
    const double t = e.TimeOf(static_cast<double>(i));
    const double u = (t + shift_s - s.start_time_s) * s.rate_hz;
    if (u < 0.0 || u > static_cast<double>(simulation.size() - 1)) continue;
    const auto j = std::min(static_cast<std::size_t>(u), simulation.size() - 2);
    const double f = u - static_cast<double>(j);
    const double value = simulation[j] + f * (simulation[j + 1] - simulation[j]);
    const double d = experiment[i] - value;
    sum += d * d;
    if (count == 0) first = t;
    last = t;
    ++count;
  }
  if (count == 0) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
  return {std::sqrt(sum / static_cast<double>(count)), last - first};
}

const ChannelImpact* FoundOn(const ImpactEstimate& impact, const std::string& channel,
                             double reach_s) {
  for (const ChannelImpact& c : impact.channels) {
    if (c.channel == channel && c.found &&
        std::abs(c.time_s.value - impact.time_s.value) <= reach_s) {
      return &c;
    }
  }
  return nullptr;
}

// The impact instants compared (LogComparison): one channel's in both sources.
void CompareImpacts(const Log& log, const ImpactEstimate& ie, const ImpactEstimate& is,
                    const LogAnalysisOptions& options, LogComparison& comparison) {
  if (!ie.found || !is.found) return;
  comparison.experiment_impact_s = ie.time_s;
  comparison.simulation_impact_s = is.time_s;
  // A channel whose strongest jump lies elsewhere saw another event (a
  // drive starting): it must agree with its source's instant.
  const double reach_s = options.impact.onset_search_s;
  const ChannelImpact *best_e = nullptr, *best_s = nullptr;
  LogChannelKind best_kind = LogChannelKind::kOther;
  for (const LogChannel& channel : log.channels) {
    const LogChannelKind kind = KindOf(channel);
    if (kind != LogChannelKind::kAcceleration && kind != LogChannelKind::kAngle) continue;
    const ChannelImpact* e = FoundOn(ie, channel.name, reach_s);
    const ChannelImpact* s = FoundOn(is, channel.name, reach_s);
    if (e == nullptr || s == nullptr) continue;
    bool better = best_e == nullptr;
    if (!better && kind != best_kind) better = kind == LogChannelKind::kAcceleration;
    if (!better && kind == best_kind && kind == LogChannelKind::kAcceleration) {
      better = std::min(e->jump_snr, s->jump_snr) > std::min(best_e->jump_snr, best_s->jump_snr);
    }
    if (!better && kind == best_kind && kind == LogChannelKind::kAngle) {
      better = std::hypot(e->time_s.sigma, s->time_s.sigma) <
               std::hypot(best_e->time_s.sigma, best_s->time_s.sigma);
    }
    if (better) {
      best_e = e;
      best_s = s;
      best_kind = kind;
    }
  }
  if (best_e != nullptr) {
    comparison.impact_channel =
        (best_kind == LogChannelKind::kAcceleration ? "accelerometer " : "encoder ") +
        best_e->channel;
    comparison.experiment_impact_s = best_e->time_s;
    comparison.simulation_impact_s = best_s->time_s;
  }
  comparison.impact_offset_s = Estimate{
      comparison.simulation_impact_s->value - comparison.experiment_impact_s->value,
      std::hypot(comparison.simulation_impact_s->sigma, comparison.experiment_impact_s->sigma)};
}

LogComparison Compare(const Log& log, const SourceResult& experiment,
                      const SourceResult& simulation, const LogAnalysisOptions& options) {
  LogComparison comparison;
  CompareImpacts(log, experiment.analysis.impact, simulation.analysis.impact, options, comparison);
  const double shift = comparison.impact_offset_s ? comparison.impact_offset_s->value : 0.0;
  for (std::size_t c = 0; c < log.channels.size(); ++c) {
    const ChannelAnalysis& a = experiment.analysis.channels[c];
    const ChannelAnalysis& b = simulation.analysis.channels[c];
    ChannelComparison row;
    row.channel = a.name;
    row.units = a.units;
    if (a.dominant_frequency_hz && b.dominant_frequency_hz) {
      row.experiment_frequency_hz = *a.dominant_frequency_hz;
      row.simulation_frequency_hz = *b.dominant_frequency_hz;
      row.frequency_difference_hz = b.dominant_frequency_hz->value - a.dominant_frequency_hz->value;
      row.frequency_difference_percent =
          100.0 * row.frequency_difference_hz / a.dominant_frequency_hz->value;
    } else {
      row.frequency_difference_hz = row.frequency_difference_percent =
          std::numeric_limits<double>::quiet_NaN();
    }
    row.experiment_damping_ratio = a.damping_ratio;
    row.simulation_damping_ratio = b.damping_ratio;
    const auto aligned = RmsDifference(experiment.series.values[c], experiment.series,
                                       simulation.series.values[c], simulation.series, shift);
    row.rms_difference = aligned.first;
    row.overlap_s = aligned.second;
    row.rms_difference_unaligned =
        RmsDifference(experiment.series.values[c], experiment.series, simulation.series.values[c],
                      simulation.series, 0.0)
            .first;
    comparison.channels.push_back(row);
  }
  return comparison;
}

}  // namespace

bool LogAnalysisOptions::Check(std::string* error) const {
  std::string inner;
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (!read.Check(&inner)) return fail("read: " + inner);
  if (!spectrum.Check(&inner)) return fail("spectrum: " + inner);
  if (!modes.Check(&inner)) return fail("modes: " + inner);
  if (!impact.Check(&inner)) return fail("impact: " + inner);
  if (max_analysis_samples < 1024) return fail("max_analysis_samples must be at least 1024");
  if (!(free_flight_guard_s >= 0.0)) return fail("free_flight_guard_s must be >= 0");
  if (!(fit_delay_s >= 0.0)) return fail("fit_delay_s must be >= 0");
  if (!(fit_max_duration_s >= 0.0)) return fail("fit_max_duration_s must be >= 0");
  if (max_fit_samples < 64) return fail("max_fit_samples must be at least 64");
  if (!(mismatch_sigmas > 0.0)) return fail("mismatch_sigmas must be positive");
  if (!(mismatch_min_bins >= 0.0)) return fail("mismatch_min_bins must be >= 0");
  if (!(fft_sigma_factor >= 0.0)) return fail("fft_sigma_factor must be >= 0");
  if (!(min_cycles_per_decay >= 0.0)) return fail("min_cycles_per_decay must be >= 0");
  if (!(min_window_cycles >= 0.0)) return fail("min_window_cycles must be >= 0");
  if (plot_points < 16) return fail("plot_points must be at least 16");
  if (!(plot_max_frequency_hz >= 0.0)) return fail("plot_max_frequency_hz must be >= 0");
  return true;
}

SourceAnalysis AnalyseLogSource(const Log& log, LogSource source, const LogRecord& record,
                                const LogAnalysisOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("LogAnalysisOptions: " + error);
  }
  return Analyse(log, source, record, options).analysis;
}

LogAnalysis AnalyseLog(const Log& log, const LogRecords& records,
                       const LogAnalysisOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("LogAnalysisOptions: " + error);
  }
  LogAnalysis result;
  result.log_id = log.id;
  try {
    SourceResult experiment = Analyse(log, LogSource::kExperiment, records.experiment, options);
    if (records.simulation) {
      SourceResult simulation = Analyse(log, LogSource::kSimulation, *records.simulation, options);
      result.comparison = Compare(log, experiment, simulation, options);
      result.simulation = std::move(simulation.analysis);
    }
    result.experiment = std::move(experiment.analysis);
    result.ok = true;
  } catch (const InputError& error) {
    result.reason = error.what();
  } catch (const std::invalid_argument& error) {
    result.reason = error.what();
  }
  return result;
}

std::string LogAnalysis::Brief() const {
  if (!ok) return fmt::format("log {}: failed: {}\n", log_id, reason);
  std::string text = fmt::format("log {}\n", log_id);
  auto source_lines = [&](const SourceAnalysis& s) {
    text += fmt::format("  {}: {} samples at {:.6g} Hz", NameOf(s.source), s.read.samples,
                        s.sample_rate_hz);
    if (s.read.IssueCount() > 0) {
      text += fmt::format(" ({} issues: {} dropped, {} interpolated)", s.read.IssueCount(),
                          s.read.dropped_rows, s.read.filled_samples);
    }
    text += s.impact.found
                ? fmt::format("; impact at {:.6f} s +- {:.2g} ({})\n", s.impact.time_s.value,
                              s.impact.time_s.sigma, s.impact.method)
                : fmt::format("; no impact: {}\n", s.impact.reason);
    for (const ChannelAnalysis& c : s.channels) {
      text += fmt::format("    {:<6}", c.name);
      if (c.dominant_frequency_hz) {
        text += fmt::format(" f = {:.5f} +- {:.2g} Hz ({})", c.dominant_frequency_hz->value,
                            c.dominant_frequency_hz->sigma, c.frequency_source);
      } else {
        text += " no dominant frequency";
      }
      if (c.damping_ratio) {
        text += fmt::format(", zeta = {:.5f} +- {:.2g}", c.damping_ratio->value,
                            c.damping_ratio->sigma);
      }
      if (c.frequency_mismatch) text += " [FFT/fit mismatch]";
      text += "\n";
    }
  };
  source_lines(experiment);
  if (simulation) source_lines(*simulation);
  if (comparison) {
    if (comparison->impact_offset_s) {
      text += fmt::format("  impact offset (simulation - experiment) {:.6f} +- {:.2g} s ({})\n",
                          comparison->impact_offset_s->value, comparison->impact_offset_s->sigma,
                          comparison->impact_channel.empty()
                              ? "each source's own instant: no channel found it in both"
                              : comparison->impact_channel + " in both");
    }
    for (const ChannelComparison& c : comparison->channels) {
      text += fmt::format(
          "    {:<6} df = {:+.4f} Hz ({:+.2f} %), RMS difference {:.4g} {} aligned, "
          "{:.4g} unaligned\n",
          c.channel, c.frequency_difference_hz, c.frequency_difference_percent, c.rms_difference,
          c.units, c.rms_difference_unaligned);
    }
  }
  return text;
}

}  // namespace impactlab
