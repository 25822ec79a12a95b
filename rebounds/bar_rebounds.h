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
  std::vector<double> xmax, xmax_sigma;      // session numbering
  std::vector<double> t_peak, t_peak_sigma;  // s since release
  std::vector<double> duration;              // s, between the flank's zero crossings
  std::vector<double> duration_sigma;        // s, one-sigma, same length
  Estimate release;                          // X0 as the history shows it (sigma 0: not known)

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
  }
};

// Session numbering: PENDUL rebound N is session rebound N - first_rebound.
// The sequence is kept gap-free: it stops at the first rebound the
// extraction left out.
BarRebounds InSessionNumbering(const ReboundExtraction& extraction, int first_rebound);

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

// Past the rebounds `session` holds, those only one bar's trace shows (the
// other's lost under a mark, or beyond its record's end): that bar's maxima
// less the bars' common swing, which the rebounds [0, both) both bars read
// measure (the pair's centre of mass swings on through every impact, so each
// bar's maximum is the mean plus a constant length with alternating sign),
// its error added in quadrature. Nothing when no rebound was read by both.
void ExtendFromOneBar(const BarRebounds& right, const BarRebounds& left, std::size_t both,
                      BarRebounds& session);

// Where the session's `rows` maxima reach past the rebounds one bar's own
// walk measured: which bar lost which rebounds, and that their maxima rest
// on the other bar's trace, in words; nullopt when both bars measured all.
std::optional<std::string> OneBarStretch(const BarRebounds& right, const BarRebounds& left,
                                         std::size_t rows);

// The session's maxima from both bars (session numbering, gap-free): the
// mean of the bars' own where both have the rebound (the thesis's average of
// the two displacements at its peak, without reading one bar at the other's
// sample times), each bar weighted by its sigma through the bars' common
// swing (a bar read badly at a rebound gives way to the other), the sigma
// scaled where the two disagree beyond their errors; past the last rebound both have, the
// averaged history's own as long as it has them. The sequence stops at the
// first rebound the bars disagree about (past it neither can be trusted);
// where the average's numbering slipped (AverageSlip) or its rows end, the
// rebounds one bar still shows follow (ExtendFromOneBar).
BarRebounds MeanOfBars(const BarRebounds& right, const BarRebounds& left,
                       const BarRebounds& averaged);

}  // namespace impactlab
