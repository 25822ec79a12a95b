// Each bar's rebounds in the session's numbering, and the session's maxima
// from both bars: the thesis averaged the two displacements (Chapter III).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "options/result_fields.h"
#include "rebounds/rebound_extraction.h"

namespace impactlab {

// One bar's rebounds as extracted from its displacement history.
struct BarRebounds {
  // Each row's rebound, session numbering, ascending. A rebound whose peak
  // the bar's trace does not show (under a mark, in a gap) has no row, and
  // the later ones keep their numbers. Empty: the rows are rebounds 0, 1, ...
  // (the results file writes it as the rows' dimension scale).
  std::vector<int> rebound;
  std::vector<double> xmax, xmax_sigma;
  std::vector<double> t_peak, t_peak_sigma;  // s since release
  std::vector<double> duration;              // s, between the flank's zero crossings
  std::vector<double> duration_sigma;        // s, one-sigma, same length
  Estimate release;                          // X0 as the history shows it (sigma 0: not known)
  // Stretches of the bar's trace left out as misread before its rebounds were
  // read (far outside its calibrated voltages: calibration/displacement.h),
  // each one's first and last sample's times, s; empty when none.
  std::vector<double> left_out_from_s, left_out_to_s;

  // What the results file keeps of a bar (options/result_fields.h).
  template <typename Self, typename Visit>
  static void VisitFields(Self& self, Visit&& visit) {
    visit("xmax", self.xmax, Quantity::kLength,
          "each rebound's maximum, as this bar's cell saw it");
    visit("xmax_std_error", self.xmax_sigma, Quantity::kLength, "its standard error");
    visit("t_peak", self.t_peak, Quantity::kSeconds, "when each maximum falls, s since release");
    visit("t_peak_std_error", self.t_peak_sigma, Quantity::kSeconds, "its standard error");
    visit("duration", self.duration, Quantity::kSeconds, "each rebound's impact-to-impact time");
    visit("duration_std_error", self.duration_sigma, Quantity::kSeconds, "its standard error");
    visit("release_x", self.release, Quantity::kLength, "X0 as this bar's trace shows it");
    visit("left_out_from", self.left_out_from_s, Quantity::kSeconds,
          "where each stretch of the trace left out as misread starts, s since release");
    visit("left_out_to", self.left_out_to_s, Quantity::kSeconds, "where it ends");
  }

  // Row i's rebound (session numbering).
  int Number(std::size_t i) const { return rebound.empty() ? static_cast<int>(i) : rebound[i]; }
  // The row of rebound n, if the bar has one.
  std::optional<std::size_t> RowOf(int n) const;
  // The rows from rebound 0 up to the first rebound the bar lacks.
  std::size_t GapFreeRows() const;
};

// Session numbering: PENDUL rebound N is session rebound N - first_rebound.
// Every rebound the extraction kept, with its number: where it left one out
// (too few samples near its peak) the later ones keep theirs.
BarRebounds InSessionNumbering(const ReboundExtraction& extraction, int first_rebound);

// The rows of `bar` from rebound 0 up to the first it lacks: a history read
// alone (one bar's, or the two bars' average) gives the session's maxima
// only as an unbroken sequence.
BarRebounds GapFree(BarRebounds bar);

// Each maximum's standard error with its cell curve's: the peak fit averages
// the samples' independent noise, but every sample near the peak reads
// through the same stretch of the curve, so the curve's error there passes to
// the maximum whole. The same for the release X0; and a duration's, from the
// curve's error at X = 0, which moves both of its crossings outwards (or
// both inwards) by that error over the flank's speed there.
// `curve_sigma_at(x)`: the curves' one-sigma error at x.
void AddCurveSigma(BarRebounds& bar, const std::function<double(double)>& curve_sigma_at);

// The first rebound (session numbering) the two bars disagree about, and
// why. The bars meet at every impact and swing out for the same time, so a
// rebound's peaks lie within a millisecond of each other; peaks more than a
// tenth of the rebound's duration apart mean one bar's walk slipped a
// rebound (a misread stretch of its trace). Their maxima are no test: the
// momentum the bars exchange leaves them a constant length apart, with
// alternating sign, which grows against the shrinking rebounds.
struct BarDisagreement {
  std::size_t rebound = 0;
  std::string why;
};
std::optional<BarDisagreement> FirstDisagreement(const BarRebounds& right, const BarRebounds& left);

// The first rebound of the averaged history (session numbering) whose peak
// is not where a bar's rebound of that number peaks, and why. The average is
// read only where both bars are: where one bar's trace is lost at the start,
// the average's walk begins later and its numbering slips by the rebounds
// lost.
std::optional<BarDisagreement> AverageSlip(const BarRebounds& right, const BarRebounds& left,
                                           const BarRebounds& averaged);

// Why the session's maxima stopped at rebound `rows` where one bar's trace
// shows it and the other's does not: its peak is more than a tenth of a half
// period from where the pendulum's clock (the peaks both bars show) puts it;
// nullopt where that is not why.
std::optional<BarDisagreement> OffTheClock(const BarRebounds& right, const BarRebounds& left,
                                           std::size_t rows);

// Which of the session's first `rows` rebounds one bar's trace does not
// show (lost under a mark, in a gap or past its record's end), so that their
// maxima rest on the other bar's, in words; nullopt when both show them all.
std::optional<std::string> OneBarStretch(const BarRebounds& right, const BarRebounds& left,
                                         std::size_t rows);

// `bar`'s rows but those whose maximum is stated to more than its own size
// (not finite, or sigma > |xmax|): such a row says nothing of the maximum (a
// bar read through a curve unknown there: randomised seed 2034's run
// 0.405's right bar, its maxima stated to 7-21 times X0), and the bar is
// read as not showing that rebound.
BarRebounds Informative(const BarRebounds& bar);

// The session's maxima from both bars (session numbering, gap-free), each
// rebound from the best the bars give (their Informative rows):
// - both bars show it and their peaks agree: the mean of the bars' own (the thesis's average of
//   the two displacements at its peak, without reading one bar at the
//   other's sample times), each bar weighted by its sigma through the bars'
//   common swing (a bar read badly at a rebound gives way to the other), the
//   sigma scaled where the two disagree beyond their errors;
// - else the averaged history's own, while its numbering holds (AverageSlip);
// - else the one bar that shows it, less the bars' common swing, which the
//   rebounds both bars show measure (the pair's centre of mass swings on
//   through every impact, so each bar's maximum is the mean plus a constant
//   length with alternating sign), its error added in quadrature; only where
//   two or more of those agree on it, once the one furthest off (a bar
//   misread there) is left out.
// A rebound whose peaks the bars disagree about (FirstDisagreement) is the
// one bar's whose peak lies on the pendulum's clock (the peaks both bars
// agree on, half a period apart), the other's reading left out; the clock
// and the common swing come from the rebounds the bars agree on.
// The sequence stops at the first rebound none of these gives, at the first
// the bars disagree about where the clock does not tell one bar (both or
// neither on it, or no clock; a lost bar's one row, below, gives way to the
// other bar's), and at the first taken from one history alone
// whose peak is more than a tenth of a half period from where the clock puts
// it. The averaged history gives no row where the bars disagree anywhere
// (it mixes the misread bar's trace).
// The run's typed X0 (half the gap between the bars at release) and its
// first_rebound, for CommonSwingFromRelease; x0 0: not given.
struct TypedRelease {
  double x0 = 0.0;
  int first_rebound = 1;
};
// `typed`: where the bars share fewer than two rebounds, so that they do not
// measure their common swing, each bar's release reads it too
// (CommonSwingFromRelease), and two or more of these readings and the shared
// rebound's that agree give it, as the shared rebounds' do; where only one
// bar's release reads it and the other bar's trace shows at most one rebound
// (lost under marks, in a halftone's tone, off its band), the first bar's
// maxima give the pair's through that reading alone, its sigma at least the
// offset it reads (nothing tells a misread release from bars let go
// unevenly), added in quadrature.
BarRebounds MeanOfBars(const BarRebounds& right, const BarRebounds& left,
                       const BarRebounds& averaged, const TypedRelease& typed = {});

// The bars' common swing at session rebound 0 from where one bar was let go:
// the pair's centre of mass starts (X0_right - X0_left) / 2 = X0_right - X0
// = X0 - X0_left from the impact point, X0 the typed half gap between the
// bars, and swings on through every impact, so at session rebound 0,
// `first_rebound` half periods later, it is (-1)^first_rebound times that.
// Its sigma is the bar's release's (the typed X0 taken as exact). Unknown
// (sigma 0) where the bar's trace does not show its release, or shows it
// more than kReleaseOffX0 of X0 from the typed X0 (a slip in either: the
// typed X0's own check names it).
Estimate CommonSwingFromRelease(const BarRebounds& bar, bool right_bar, const TypedRelease& typed);

}  // namespace impactlab
