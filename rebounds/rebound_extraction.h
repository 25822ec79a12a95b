// Rebound maxima, times and durations from a displacement history (thesis
// Chapter III "Reduction of data", Figure 15), and the contact time from the
// contact circuit's pulse.
//
// The bars meet at equilibrium once every half period of the pendulum, so
// rebound N is the stretch between impact N and the next, a half period
// later; the history is walked by that clock, refined at each impact by the
// rebound's own falling flank, so gaps in a digitized trace cannot merge or
// split rebounds. The release swing before the first impact is rebound 0
// (PENDUL's numbering, Figure 6). Each maximum comes from a least-squares fit
// of the exact pendulum's swing (amplitude, peak time and an offset) to the
// samples near the peak, so its precision is far below the sample spacing
// and it carries an uncertainty from the fit's residuals.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "io/trace.h"
#include "model/contact_pulse.h"
#include "model/displacement_history.h"
#include "model/estimate.h"
#include "model/pendulum.h"

namespace impactlab {

// The fewest samples a history must hold for ExtractRebounds.
inline constexpr std::size_t kMinHistorySamples = 16;

// Bounds on a trace's time axis, checked before any work that grows with its
// span: a wrong unit or a typo (time_per_div = 1e8, a CSV's time column in
// ns) would otherwise walk billions of empty swings. Generous for every real
// session: a 22 in pendulum swings out and back in 0.75 s, a photo's 10
// divisions at 0.5 s/div hold 7 of those, rebounds die out within tens.
struct TraceSpanLimits {
  // Most half swings (out and back at small amplitude, the shortest) of the
  // pendulum a trace may span.
  double max_half_swings = 1000.0;
  // Most samples a trace may need at its median sample interval (span /
  // interval): 1e8 is a deep-memory digital scope's whole record.
  double max_samples = 1e8;
  // Fewest samples per half swing a trace of rebounds needs (a peak fit
  // takes at least 7 within 0.9 of a half swing).
  double min_samples_per_half_swing = 8.0;

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("max_half_swings", self.max_half_swings, "most half swings a trace may span");
    visit("max_samples", self.max_samples, "most samples a trace may need");
    visit("min_samples_per_half_swing", self.min_samples_per_half_swing,
          "fewest samples per half swing");
  }

  bool Check(std::string* error) const;
};

// Why a trace spanning `span_s` (s) at `sample_interval_s` (s; 0 when not yet
// known, e.g. a photo before it is digitized) cannot be measured with this
// pendulum, with the figures; empty when it can. `samples` (0: not known)
// adds the resolution check for traces of rebounds.
std::string TraceSpanProblem(double span_s, double sample_interval_s, std::size_t samples,
                             const Pendulum& pendulum, const TraceSpanLimits& limits = {});

struct ReboundExtractionOptions {
  // Rebounds end where their maximum falls below this fraction of the
  // largest X in the history; the release swing ends where X first falls
  // below a quarter of it.
  double threshold_fraction = 0.03;
  // Half-width of the peak fit window as a fraction of the rebound's duration.
  // Wide windows average more samples; the model fits the whole swing shape.
  double peak_window_fraction = 0.45;
  int min_samples_per_peak = 7;
  // The history's span, checked before the rebounds are walked.
  TraceSpanLimits limits;

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("threshold_fraction", self.threshold_fraction,
          "rebounds end below this of the largest X");
    visit("peak_window_fraction", self.peak_window_fraction, "peak fit half-window, of duration");
    visit("min_samples_per_peak", self.min_samples_per_peak, "fewest samples in a peak fit");
    visit("limits", self.limits, "");
  }

  bool Check(std::string* error) const;
};

struct ExtractedRebound {
  int number = 0;        // PENDUL numbering: 0 = release swing, N after impact N
  Estimate xmax;         // length units
  Estimate t_peak;       // s since release
  double start_s = 0.0;  // X crosses 0 going out (the flank through the swing's shape)
  double end_s = 0.0;    // X crosses 0 coming back
  Estimate duration;     // end - start, s
  int samples_in_fit = 0;
  double fit_rms = 0.0;  // residual rms of the peak fit, length units
};

struct ReboundExtraction {
  // Whether the history could be walked; otherwise `reason` says why (too few
  // samples, never leaving 0, a span the limits refuse) and nothing else is set.
  bool ok = false;
  std::string reason;
  // Complete rebounds after the first impact (rebound 1, 2, ...), in order; a
  // rebound with too few samples near its peak is left out (its number is
  // skipped, the later ones keep theirs).
  std::vector<ExtractedRebound> rebounds;
  // Starts of the gaps between rebounds (contacts), s.
  std::vector<double> impact_times;
  // X0 as the history shows it: the release swing's fitted amplitude, with
  // its standard error from the fall's fit (0 where too few samples fell to
  // fit it and the top sample stands for it); 0 and 0 where the history
  // begins after the first impact and does not show the release at all.
  Estimate release;
};

// A history with too few samples, one that never leaves 0 or whose span
// breaks `options.limits` (memory and time stay bounded by the number of
// samples) is a result with `ok` false and the reason. Throws
// std::invalid_argument only for options that fail their Check (a caller's
// mistake).
ReboundExtraction ExtractRebounds(const DisplacementHistory& history, const Pendulum& pendulum,
                                  const ReboundExtractionOptions& options);

// The average of two histories (the thesis averaged right and left), on the
// union of their times wherever both can be read there: between close samples
// by a local cubic (or a chord), across a gap up to `max_bridge_s` wide (a
// chopper's slots, shared by the bars) by a least-squares cubic through the
// samples either side; sigma combined. Wider gaps stay gaps.
DisplacementHistory AverageHistories(const DisplacementHistory& a, const DisplacementHistory& b,
                                     double max_bridge_s = 0.0);

// The contact pulse a trace shows, or why it shows none.
struct ContactPulseMeasurement {
  bool ok = false;
  std::string reason;  // when not ok: too few samples, no step, no complete pulse
  ContactPulse pulse;  // when ok
};

// Finds the pulse: of the complete ones, that holding most of the samples at
// the pulse level (the bars touch once in a sweep; a label across the rest
// level reads as a short pulse of its own), refused when none holds most of
// them. Edges are located where the trace crosses
// the level halfway between its low and high states, by linear interpolation
// between the samples that straddle it.
ContactPulseMeasurement MeasureContactPulse(const Trace& trace);

}  // namespace impactlab
