// The log stage: one `[[log]]` of a session, experiment and (optionally)
// simulation, read, analysed channel by channel, and compared
// (docs/logs.md). The results file stores exactly this struct.
//
// Per source (experiment, simulation):
//   1. read its record (io/log_reader.h LogRecord, which the caller opens) in
//      blocks; a log longer than `max_analysis_samples` is low-pass decimated on
//      the fly (signal/decimate.h), so memory stays bounded whatever its length;
//   2. the impact instant (signal/impact_detection.h); on a decimated log a second
//      pass reads the record again and keeps only the full-rate samples around the
//      coarse instant to refine it;
//   3. segments: free flight (start .. impact - guard), post-impact (impact .. end),
//      whole record; per channel and segment a spectrum with its peaks
//      (signal/spectrum.h);
//   4. per channel, the damped modes of the post-impact ring-down
//      (signal/damped_modes.h), cross-checked against the FFT peak of the same
//      ring-down window.
// Then, with a simulation, per channel: frequencies side by side, the impact
// offset, and RMS differences with and without aligning the impacts.
//
// A channel's `dominant_frequency_hz` is the fitted damped frequency of the
// oscillating mode nearest the FFT peak of the ring-down (the post-impact FFT
// peak itself when the fit failed; the whole record's when no impact was
// found); `damping_ratio` is that mode's. A mode oscillates when it completes
// `min_cycles_per_decay` periods per e-fold of its amplitude and
// `min_window_cycles` within the window; a channel whose fit has no such mode
// (a joint turning on, a stop's overdamped settling) has none, and a note
// beginning "no oscillation" says why. These are the results file's
// /logs/<id>/<source>/<channel> datasets.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/log_reader.h"
#include "io/session.h"
#include "model/estimate.h"
#include "options/result_fields.h"
#include "signal/damped_modes.h"
#include "signal/decimate.h"
#include "signal/impact_detection.h"
#include "signal/spectrum.h"

namespace impactlab {

struct LogAnalysisOptions {
  LogReadOptions read;       // how the pipeline reads the records (io/log_reader.h LogFileRecords)
  SpectrumOptions spectrum;  // detrend is set per channel: linear for angles, mean otherwise
  DampedModeOptions modes;   // max_frequency_hz 0: 1.5 x the highest of the leading FFT peaks
  ImpactDetectionOptions impact;
  std::size_t max_analysis_samples = std::size_t{1} << 20;  // per channel in memory; longer
                                                            // logs are decimated to fit
  double free_flight_guard_s = 0.005;  // free flight ends this long before the impact, s
  double fit_delay_s = 0.005;          // the ring-down fit starts this long after the impact, s
  double fit_max_duration_s = 0.0;     // ring-down window length, s; 0: to the record's end
  std::size_t max_fit_samples = 8192;  // a longer ring-down window is decimated for the fit
  double mismatch_sigmas = 4.0;        // FFT and fitted frequency disagree beyond this many
                                       // combined sigmas ...
  double mismatch_min_bins = 0.05;     // ... and this fraction of the FFT bin width
  double fft_sigma_factor = 2.0;      // sigma of the FFT peak, as a multiple of the fit's (the Hann
                                      // peak of a ring-down is 1.5-2x the bound; docs/logs.md)
  double min_cycles_per_decay = 1.0;  // a fitted mode is an oscillation when it completes at
                                      // least this many periods while its amplitude falls by e
                                      // (1: zeta <= 0.157) ...
  double min_window_cycles = 2.0;     // ... and this many periods within the ring-down window;
                                      // a channel with no such mode has no dominant frequency
  std::size_t plot_points = 2000;     // points of the decimated series and spectra kept for plots
  double plot_max_frequency_hz = 0.0;  // spectra kept up to here, Hz; 0: 5 x the highest peak

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("read", self.read, "");
    visit("spectrum", self.spectrum, "");
    visit("modes", self.modes, "");
    visit("impact", self.impact, "");
    visit("max_analysis_samples", self.max_analysis_samples, "per channel; longer are decimated");
    visit("free_flight_guard_s", self.free_flight_guard_s, "free flight ends this long before, s");
    visit("fit_delay_s", self.fit_delay_s, "ring-down fit starts this long after the impact, s");
    visit("fit_max_duration_s", self.fit_max_duration_s, "ring-down window, s (0: to the end)");
    visit("max_fit_samples", self.max_fit_samples, "a longer window is decimated for the fit");
    visit("mismatch_sigmas", self.mismatch_sigmas, "FFT and fit disagree beyond these sigmas");
    visit("mismatch_min_bins", self.mismatch_min_bins, "... and this fraction of a bin");
    visit("fft_sigma_factor", self.fft_sigma_factor, "the FFT peak's sigma over the fit's");
    visit("min_cycles_per_decay", self.min_cycles_per_decay, "an oscillation: periods per e-fold");
    visit("min_window_cycles", self.min_window_cycles, "... and periods in the ring-down window");
    visit("plot_points", self.plot_points, "points kept for plots");
    visit("plot_max_frequency_hz", self.plot_max_frequency_hz, "spectra kept up to, Hz (0: auto)");
  }

  bool Check(std::string* error) const;
};

// A spectrum of one segment, decimated for plotting (max-hold per bucket, up to
// plot_max_frequency_hz); its peaks come from the full spectrum.
struct SegmentSpectrum {
  std::string segment;                // "whole", "free_flight" or "post_impact"
  double start_s = 0.0, end_s = 0.0;  // log time
  Spectrum spectrum;
};

struct ChannelAnalysis {
  std::string name;
  LogChannelKind kind = LogChannelKind::kOther;
  std::string units;  // "rad", "m/s^2", "SI"

  std::optional<Estimate> dominant_frequency_hz;  // see the file comment; sigma 0 from the FFT
  std::optional<Estimate> damping_ratio;          // from the fit, when there is one
  std::string frequency_source;                   // "fit", "fft post_impact" or "fft whole"
  double fft_frequency_hz = 0.0;    // FFT peak of the ring-down window (the fit's samples, 4
                                    // time constants), else of the post-impact (or whole) record
  double fft_resolution_hz = 0.0;   // that spectrum's bin width
  std::vector<SpectralPeak> peaks;  // that spectrum's peaks: [0] dominant, then the next
  DampedModeFit ring_down;          // the post-impact fit (not ok: see its diagnostic)
  double ring_down_start_s = 0.0;   // log time of the fit window's first sample
  double ring_down_rate_hz = 0.0;   // its sampling rate (after any decimation)
  bool frequency_mismatch = false;  // FFT peak and fitted frequency disagree
  std::vector<std::string> notes;   // what went wrong or is worth knowing

  std::vector<SegmentSpectrum> spectra;  // whole, free_flight, post_impact (those that exist)
  DecimatedSeries series;                // the channel over time, decimated for plots

  // What the results file keeps as fields (options/result_fields.h); the
  // name names the channel's group, and the series and one spectrum (the
  // post-impact segment's, which the frequency is read from, else the whole
  // record's; pipeline/log_results.h KeptSpectrum) are stored by the file's
  // own layout. Not kept: the kind (the units say it), the FFT peak, its
  // resolution and the peaks (the spectrum shows them), the ring-down fit's
  // modes, decays and solver figures, and the other segments' spectra (up
  // to two more of about 2000 points, frequency and PSD: they would double
  // the channel's stored arrays, which are most of a log's file and its write
  // time, for plots the report does not draw).
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("channel_units", self.units, Quantity::kDimensionless,
          "the channel's values' units: rad, m/s^2 or SI");
    visit("frequency_source", self.frequency_source, Quantity::kDimensionless,
          "fit, fft post_impact or fft whole");
    visit("frequency_mismatch", self.frequency_mismatch, Quantity::kDimensionless,
          "1 when the FFT peak and the fitted frequency disagree");
    visit("dominant_frequency", self.dominant_frequency_hz, Quantity::kHertz,
          "the channel's dominant frequency (none: no oscillation)");
    visit("damping_ratio", self.damping_ratio, Quantity::kDimensionless,
          "its mode's damping ratio");
    visit("notes", self.notes, Quantity::kDimensionless, "what went wrong or is worth knowing");
  }
};

struct SourceAnalysis {
  LogSource source = LogSource::kExperiment;
  std::filesystem::path file;   // the record's, as its reader reports it
  LogReadReport read;           // rows, dropped and interpolated samples, issues
  double sample_rate_hz = 0.0;  // of the file: 1 / mean interval
  int decimation = 1;           // analysis rate = sample_rate_hz / decimation
  ImpactEstimate impact;        // found or not (diagnostic); samples index the analysis series
  std::vector<ChannelAnalysis> channels;  // the manifest's order
  double seconds = 0.0;                   // wall time: reading and analysis
};

struct ChannelComparison {
  std::string channel;
  std::string units;
  Estimate experiment_frequency_hz, simulation_frequency_hz;
  double frequency_difference_hz = 0.0;       // simulation - experiment
  double frequency_difference_percent = 0.0;  // of the experiment's
  std::optional<Estimate> experiment_damping_ratio, simulation_damping_ratio;
  double rms_difference = 0.0;            // units; simulation shifted so the impacts coincide
  double rms_difference_unaligned = 0.0;  // units; both on their own time axes
  double overlap_s = 0.0;                 // duration compared (aligned)

  // What the results file keeps as fields (options/result_fields.h), the
  // channel's own units for the RMS differences; the channel names the group.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("channel_units", self.units, Quantity::kDimensionless,
          "the channel's units: rad, m/s^2 or SI");
    visit("experiment_frequency", EvenEmpty(self.experiment_frequency_hz), Quantity::kHertz,
          "the experiment's dominant frequency");
    visit("simulation_frequency", EvenEmpty(self.simulation_frequency_hz), Quantity::kHertz,
          "the simulation's");
    visit("frequency_difference", self.frequency_difference_hz, Quantity::kHertz,
          "simulation - experiment (NaN: either has none)");
    visit("frequency_difference_percent", self.frequency_difference_percent, Quantity::kPercent,
          "the same, % of the experiment's");
    visit("experiment_damping_ratio", self.experiment_damping_ratio, Quantity::kDimensionless,
          "the experiment's damping ratio of that mode");
    visit("simulation_damping_ratio", self.simulation_damping_ratio, Quantity::kDimensionless,
          "the simulation's");
    visit("rms_difference", self.rms_difference, Quantity::kChannel,
          "RMS of simulation - experiment after aligning the impacts");
    visit("rms_difference_unaligned", self.rms_difference_unaligned, Quantity::kChannel,
          "the same as recorded");
    visit("overlap", self.overlap_s, Quantity::kSeconds,
          "the duration the aligned RMS difference compares");
  }
};

struct LogComparison {
  // The impact instants compared, like with like: the same channel's in both
  // sources, the accelerometer whose jump is strongest in the weaker of the
  // two (else the encoder with the smallest combined sigma), among the
  // channels that found the impact in both within `impact.onset_search_s` of
  // each source's own instant. Where no channel did, each source's own
  // instant, and `impact_channel` is empty. A source's own instant (its
  // strongest jump) places its segments; it may be another channel's.
  std::string impact_channel;  // e.g. "accelerometer a3"; empty: the sources' own instants
  std::optional<Estimate> experiment_impact_s, simulation_impact_s;  // log time, each source's
  std::optional<Estimate> impact_offset_s;  // simulation - experiment of the two, when both found
  std::vector<ChannelComparison> channels;

  // What the results file keeps as fields (options/result_fields.h); each
  // channel's comparison is a group of its own.
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("impact_channel", IfAny(self.impact_channel), Quantity::kDimensionless,
          "the channel whose impact instants are compared (none: each source's own)");
    visit("experiment_impact", self.experiment_impact_s, Quantity::kSeconds,
          "the experiment's impact instant compared");
    visit("simulation_impact", self.simulation_impact_s, Quantity::kSeconds, "the simulation's");
    visit("impact_offset", self.impact_offset_s, Quantity::kSeconds,
          "simulation - experiment impact time");
  }
};

struct LogAnalysis {
  std::string log_id;
  bool ok = false;
  std::string reason;  // why, when !ok (file, line and key where they apply)
  SourceAnalysis experiment;
  std::optional<SourceAnalysis> simulation;
  std::optional<LogComparison> comparison;

  std::string Brief() const;  // a few lines: impact, per channel frequency/damping, comparison
};

// `log`: the manifest's entry (its channels and time column); `records`: its
// experiment's and simulation's records (io/log_reader.h LogFileRecords reads
// its files). Never throws for bad data: a log that cannot be read or
// analysed comes back with !ok and the reason. Throws std::invalid_argument
// for bad options.
LogAnalysis AnalyseLog(const Log& log, const LogRecords& records,
                       const LogAnalysisOptions& options);

// One source alone (used by AnalyseLog; throws InputError for unreadable data).
SourceAnalysis AnalyseLogSource(const Log& log, LogSource source, const LogRecord& record,
                                const LogAnalysisOptions& options);

}  // namespace impactlab
