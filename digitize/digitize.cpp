// DigitizePhoto: the stages in order, timed; and the traces a manifest names.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "digitize/bold_lines.h"
#include "digitize/digitize.h"
#include "digitize/hand_marks.h"
#include "io/errors.h"

namespace impactlab {

namespace {

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The beam's line width and the brightest trace's height: what a mark must
// exceed. The width is the widest continuously drawn trace's (a first
// reading's median over its samples). A chopped trace's reading is no
// measure of it: where its sparse dashes were joined by a label's or a
// ring's unbroken strokes, those can outnumber them and widen the median
// past the mark itself. Only when every trace is chopped is the narrowest
// of them taken (marks widen a reading, never narrow it).
std::array<double, 2> TraceScale(const std::vector<DigitizedTrace>& traces) {
  double continuous = 0.0, chopped = std::numeric_limits<double>::infinity(), height = 0.0;
  for (const DigitizedTrace& t : traces) {
    if (digitize::ReadInDashes(t)) {
      if (t.width_px > 0.0) chopped = std::min(chopped, t.width_px);
    } else {
      continuous = std::max(continuous, t.width_px);
    }
    height = std::max(height, t.height);
  }
  const double width = continuous > 0.0 ? continuous : std::isfinite(chopped) ? chopped : 0.0;
  return {width, height};
}

// The traces read with hand marks kept out: a first reading gives the
// traces' width and height, the marks are what is much wider, and the
// traces are read again without them when there are any. When the first
// reading fails, a mark may be why: the grid lines stand in for the
// traces' scale. When the second reading fails, the first stands, or its
// failure.
std::vector<DigitizedTrace> ExtractTracesBesideMarks(const PreparedPhoto& prepared,
                                                     const GraticuleFit& graticule,
                                                     const std::vector<TraceRequest>& requests,
                                                     const TraceOptions& options,
                                                     DigitizeResult& result) {
  std::vector<DigitizedTrace> first;
  std::optional<InputError> failure;
  try {
    first = ExtractTraces(prepared, graticule, requests, options);
  } catch (const InputError& e) {
    if (!options.hand_marks) throw;
    failure = e;
  }
  if (!options.hand_marks) return first;
  const auto [width, height] =
      failure ? std::array{2.0 * graticule.line_width_px, 1.5 * graticule.line_contrast}
              : TraceScale(first);
  const digitize::HandMarkMap marks =
      digitize::FindHandMarks(prepared, graticule, width, height, first);
  if (marks.empty()) {
    if (failure) throw *failure;
    return first;
  }
  std::vector<DigitizedTrace> traces;
  try {
    traces = ExtractTraces(digitize::WithoutMarks(prepared, marks), graticule, requests, options);
  } catch (const InputError&) {
    // Without the marks a trace was lost: the first reading stands, or its failure.
    if (failure) throw *failure;
    return first;
  }
  for (DigitizedTrace& trace : traces) {
    trace.mark_stretches_div = digitize::DropSamplesOnMarks(marks, trace);
  }
  result.mark_outlines_px = marks.outlines_px;
  return traces;
}

// The bold reading replaces the thin one where it sees a trace wider than the
// grid's lines along at least this much more of the sweep.
constexpr double kBoldCoverageGain = 0.2;

// Whether one of the thin reading's traces may have lost a bold trace
// (digitize::AsksForBoldReading).
bool SomeTraceWeak(const std::vector<DigitizedTrace>& traces, const PreparedPhoto& photo,
                   const GraticuleFit& graticule) {
  return std::any_of(traces.begin(), traces.end(), [&](const DigitizedTrace& t) {
    return digitize::AsksForBoldReading(t, photo, graticule.divisions[0]);
  });
}

// Two readings of one trace follow different lines where their samples at
// the same place along the sweep (within kSameColumnDiv) lie more than
// kOtherLineDiv apart; the thin reading followed another line when at least
// kOtherLineShare of its samples that the bold reading also has do so.
constexpr double kSameColumnDiv = 0.05, kOtherLineDiv = 0.25, kOtherLineShare = 0.1;

// The sample of `samples` (in x order, as a reading runs along the sweep)
// nearest to `x` along the sweep; null when there is none.
const cv::Point2d* NearestAlongSweep(const std::vector<cv::Point2d>& samples, double x) {
  const auto next = std::lower_bound(samples.begin(), samples.end(), x,
                                     [](const cv::Point2d& q, double at) { return q.x < at; });
  const cv::Point2d* nearest = nullptr;
  if (next != samples.end()) nearest = &*next;
  if (next != samples.begin() && (nearest == nullptr || x - std::prev(next)->x < nearest->x - x)) {
    nearest = &*std::prev(next);
  }
  return nearest;
}

bool FollowsAnotherLine(const DigitizedTrace& thin, const DigitizedTrace& bold) {
  const std::vector<cv::Point2d>& b = bold.screen_div;
  std::size_t compared = 0, apart = 0;
  for (const cv::Point2d& p : thin.screen_div) {
    const cv::Point2d* nearest = NearestAlongSweep(b, p.x);
    if (nearest == nullptr || std::abs(nearest->x - p.x) > kSameColumnDiv) continue;
    ++compared;
    if (std::abs(nearest->y - p.y) > kOtherLineDiv) ++apart;
  }
  return compared > 0 && static_cast<double>(apart) >= kOtherLineShare * compared;
}

// A thin reading that sees a trace along less than this share of what the
// bold reading sees of it has lost the trace, not merely samples of it.
constexpr double kThinLostShare = 0.5;

// Whether the bold reading sees what a person sees where the thin one saw
// little: every trace along as much of the sweep at least, and one along a
// good deal more as a line wider than the grid's (a printed trace's ink or a
// broad beam), where the thin reading's samples lie on another line (a grid
// line, a hair or a pen stroke beside it) or where the thin reading saw
// under half as much of it (kThinLostShare: randomised seed 3031's
// calibration, a grainy 4.6 px trace, 8 % of the sweep on thin lines
// and 93 % on bold ones). A thin reading that agrees with the bold one and
// sees most of what it sees is kept as it was.
bool BoldReadsMore(const std::vector<DigitizedTrace>& thin, const std::vector<DigitizedTrace>& bold,
                   const GraticuleFit& graticule) {
  if (bold.size() != thin.size()) return false;
  bool gains = false;
  for (std::size_t i = 0; i < thin.size(); ++i) {
    if (bold[i].coverage < thin[i].coverage) return false;
    const bool thin_lost = thin[i].coverage < kThinLostShare * bold[i].coverage;
    gains = gains || (bold[i].coverage >= thin[i].coverage + kBoldCoverageGain &&
                      bold[i].width_px > graticule.line_width_px &&
                      (thin_lost || FollowsAnotherLine(thin[i], bold[i])));
  }
  return gains;
}

// The traces read on the ridge image of thin lines, or, where that reading
// fails, on one that keeps lines up to half a division wide: a bold trace (a
// line printed in a report's figure, a broad beam on a small photo) leaves
// only its edges in the thin image, which a scratch or a grid line
// out-earns. When the bold reading fails too, the first failure stands.
// A thin reading that succeeds on a stroke or a hair beside such a trace
// sees it along little of the sweep (randomised seed 1032's calibration
// an arrow, 7 %; seed 1004's: a hair a third of a division
// off for two divisions, 48 %): where a trace is seen along little of the
// sweep and is broad or missing long stretches of it (SomeTraceWeak), the
// bold reading is tried as well and taken when it reads more
// (BoldReadsMore). Every other photo read on thin lines is read as before.
std::vector<DigitizedTrace> ReadThinOrBold(const PreparedPhoto& prepared,
                                           const GraticuleFit& graticule,
                                           const std::vector<TraceRequest>& requests,
                                           const TraceOptions& options, DigitizeResult& result) {
  try {
    std::vector<DigitizedTrace> thin =
        ExtractTracesBesideMarks(prepared, graticule, requests, options, result);
    if (!SomeTraceWeak(thin, prepared, graticule) ||
        digitize::BoldOpeningPx(prepared, graticule) <= digitize::kRidgeOpeningPx) {
      return thin;
    }
    DigitizeResult bold_result;
    try {
      std::vector<DigitizedTrace> bold = ExtractTracesBesideMarks(
          digitize::WithBoldLines(prepared, graticule), graticule, requests, options, bold_result);
      if (BoldReadsMore(thin, bold, graticule)) {
        result.mark_outlines_px = std::move(bold_result.mark_outlines_px);
        return bold;
      }
    } catch (const InputError&) {
      // The bold reading sees nothing better: the thin one stands.
    }
    return thin;
  } catch (const InputError& thin_failure) {
    if (digitize::BoldOpeningPx(prepared, graticule) <= digitize::kRidgeOpeningPx) throw;
    try {
      return ExtractTracesBesideMarks(digitize::WithBoldLines(prepared, graticule), graticule,
                                      requests, options, result);
    } catch (const InputError&) {
      // Read again below on the lines wider than the grid's.
    }
    if (digitize::WideOpeningPx(prepared, graticule) == 0) throw;
    try {
      return ExtractTracesBesideMarks(digitize::WithWideLines(prepared, graticule), graticule,
                                      requests, options, result);
    } catch (const InputError&) {
      throw thin_failure;
    }
  }
}

// The traces read on thin, bold or wide lines (ReadThinOrBold); where every
// reading failed, read so once more telling a bold trace from the grid's
// lines by its width as well as its height. A bold trace printed in the
// grid's own ink saturates like the lines and stands no higher than they do;
// where it runs along one over much of the sweep (a contact level, a
// calibration's flat end) it was refused as a grid line followed by
// mistake, which is measured as wide as a line. Only a photo that no
// reading reads is read so: every reading of a photo read before stands (a
// width test in every reading let a reading with hand marks taken out,
// which saw the trace along 16 % of the sweep, replace a reading along 46 %
// of it: randomised seed 1021's calibration ). When it fails too, it
// is read once more seeking a trace refused as a grid line off the grid's
// rows; when that fails too, the first failure stands.
std::vector<DigitizedTrace> ExtractTracesThinOrBold(const PreparedPhoto& prepared,
                                                    const GraticuleFit& graticule,
                                                    const std::vector<TraceRequest>& requests,
                                                    const TraceOptions& options,
                                                    DigitizeResult& result) {
  try {
    return ReadThinOrBold(prepared, graticule, requests, options, result);
  } catch (const InputError& failure) {
    if (options.tell_bold_by_width) throw;
    TraceOptions by_width = options;
    by_width.tell_bold_by_width = true;
    try {
      return ReadThinOrBold(prepared, graticule, requests, by_width, result);
    } catch (const InputError&) {
      // Read again below off the grid's rows.
    }
    // A trace refused as a grid line is then sought again with the grid's
    // rows withheld (docs/digitizing.md, "A trace in the grid's ink"): a
    // trace printed in the grid's ink, its course drawn onto a row that pays
    // as well as it does.
    TraceOptions off_rows = by_width;
    off_rows.off_grid_rows = true;
    try {
      return ReadThinOrBold(prepared, graticule, requests, off_rows, result);
    } catch (const InputError&) {
      throw failure;
    }
  }
}

// A calibration's trace runs one way (TraceRequest::one_way_until_s): the bar swings
// from its release across the sweep and the cell's output is monotone in its
// displacement, so the trace's height never turns back (on the generator's
// truth by at most 0.06 division, the beam's own wobble). A reading that
// turns back by more than kTurnsBackDiv took something else for a stretch
// (a pen ring's arc, an arrow, a stroke across the trace, a grid line): the
// photo is read again with the course sought one way
// (TraceOptions::one_way_courses), and that reading is taken only where it
// does run one way, to within kRunsOneWayDiv (the course's own tolerance
// and the centre's noise). Heights are taken as the median of
// kTurnMedianSamples about each sample: a lone sample off is no turn.
constexpr double kTurnsBackDiv = 0.5, kRunsOneWayDiv = 0.25;
constexpr std::size_t kTurnMedianSamples = 5;

// How far a trace's reading up to `until_s` turns back in height (divisions), the least of
// the two ways it may be taken to run: the most its height falls back from
// the furthest it had gone, down the screen or up it.
double TurnBackDiv(const DigitizedTrace& trace, double until_s) {
  std::vector<double> y;
  for (std::size_t i = 0; i < trace.screen_div.size() && i < trace.trace.time_s.size(); ++i) {
    if (trace.trace.time_s[i] <= until_s) y.push_back(trace.screen_div[i].y);
  }
  if (y.size() < kTurnMedianSamples) return 0.0;
  std::vector<double> height;
  std::array<double, kTurnMedianSamples> window{};
  for (std::size_t i = 0; i + kTurnMedianSamples <= y.size(); ++i) {
    for (std::size_t k = 0; k < kTurnMedianSamples; ++k) window[k] = y[i + k];
    std::nth_element(window.begin(), window.begin() + kTurnMedianSamples / 2, window.end());
    height.push_back(window[kTurnMedianSamples / 2]);
  }
  double least = std::numeric_limits<double>::infinity();
  for (const double way : {1.0, -1.0}) {
    double furthest = -std::numeric_limits<double>::infinity(), back = 0.0;
    for (const double h : height) {
      furthest = std::max(furthest, way * h);
      back = std::max(back, furthest - way * h);
    }
    least = std::min(least, back);
  }
  return least;
}

// The share of `again`'s samples that `first` has not at the same place
// along the sweep (none within kSameColumnDiv), or has on another line
// (more than kOtherLineDiv away).
double ShareReadAnew(const DigitizedTrace& again, const DigitizedTrace& first) {
  const std::vector<cv::Point2d>& b = first.screen_div;
  std::size_t anew = 0;
  for (const cv::Point2d& p : again.screen_div) {
    const cv::Point2d* nearest = NearestAlongSweep(b, p.x);
    if (nearest == nullptr || std::abs(nearest->x - p.x) > kSameColumnDiv ||
        std::abs(nearest->y - p.y) > kOtherLineDiv) {
      ++anew;
    }
  }
  return again.screen_div.empty()
             ? 0.0
             : static_cast<double>(anew) / static_cast<double>(again.screen_div.size());
}

// Whether the one-way reading `again` of the traces read first as `first`
// reads something the first did not where it turned back: a one-way trace
// that the first reading turned back on is read anew along at least
// kReadAnewShare of its samples. A one-way reading that only leaves out
// part of the first (the stretch it turned back on, or the trace beyond a
// hair the course then keeps to) is no better evidence than the first: the
// calibration's fit judges a stretch off its curve with the whole reading
// before it (randomised seed 4008's calibration, whose course kept
// to a hair along the trace read one way, and 3027's, a straight
// stroke across a bold trace taken for a hand mark: either reading one way
// was a part of the first, the one calibrated and the other refused before).
constexpr double kReadAnewShare = 0.05;

bool ReadsAnew(const std::vector<DigitizedTrace>& again, const std::vector<DigitizedTrace>& first,
               const std::vector<TraceRequest>& requests) {
  for (std::size_t i = 0; i < again.size() && i < first.size() && i < requests.size(); ++i) {
    const double until = requests[i].one_way_until_s;
    if (until > 0.0 && TurnBackDiv(first[i], until) > kTurnsBackDiv &&
        ShareReadAnew(again[i], first[i]) < kReadAnewShare) {
      return false;
    }
  }
  return true;
}

// Whether a one-way trace's reading among `traces` (one per request, in
// order) turns back by more than `limit_div`.
bool OneWayTraceTurnsBack(const std::vector<DigitizedTrace>& traces,
                          const std::vector<TraceRequest>& requests, double limit_div) {
  for (std::size_t i = 0; i < traces.size() && i < requests.size(); ++i) {
    const double until = requests[i].one_way_until_s;
    if (until > 0.0 && TurnBackDiv(traces[i], until) > limit_div) return true;
  }
  return false;
}

}  // namespace

DigitizeResult DigitizePhoto(const Photo& photo, std::array<int, 2> divisions,
                             const std::vector<TraceRequest>& requests,
                             const DigitizeOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("digitize options: " + error);
  }
  DigitizeResult result;
  // Each stage refuses a photo it cannot read with an InputError (its file,
  // the key to fix, why); here that ends the run as a result, which keeps
  // what the stages before it found.
  const auto refused = [&result](const InputError& e) {
    result.ok = false;
    result.failed_at = e.where();
    result.reason = e.problem();
    result.traces.clear();
    result.mark_outlines_px.clear();
    return result;
  };
  auto start = std::chrono::steady_clock::now();
  std::optional<PreparedPhoto> prepared;
  try {
    prepared.emplace(PreparePhoto(photo, options.graticule));
    result.prepare_ms = prepared->prepare_ms;
    start = std::chrono::steady_clock::now();
    result.graticule = FindGraticule(*prepared, divisions, options.graticule);
    result.graticule_found = true;
  } catch (const InputError& e) {
    return refused(e);
  }
  result.graticule_ms = MillisecondsSince(start);

  start = std::chrono::steady_clock::now();
  try {
    result.traces =
        ExtractTracesThinOrBold(*prepared, result.graticule, requests, options.traces, result);
    if (!options.traces.one_way_courses &&
        OneWayTraceTurnsBack(result.traces, requests, kTurnsBackDiv)) {
      TraceOptions one_way = options.traces;
      one_way.one_way_courses = true;
      DigitizeResult again;
      try {
        std::vector<DigitizedTrace> traces =
            ExtractTracesThinOrBold(*prepared, result.graticule, requests, one_way, again);
        if (!OneWayTraceTurnsBack(traces, requests, kRunsOneWayDiv) &&
            ReadsAnew(traces, result.traces, requests)) {
          result.traces = std::move(traces);
          result.mark_outlines_px = std::move(again.mark_outlines_px);
        }
      } catch (const InputError&) {
        // Read one way the trace is lost: the first reading stands.
      }
    }
  } catch (const InputError& e) {
    result.traces_ms = MillisecondsSince(start);
    return refused(e);
  }
  result.traces_ms = MillisecondsSince(start);

  start = std::chrono::steady_clock::now();
  for (const DigitizedTrace& trace : result.traces) {
    result.pulses.push_back(trace.settings.impact ? MeasurePulse(*prepared, result.graticule, trace)
                                                  : std::nullopt);
  }
  result.pulse_ms = MillisecondsSince(start);
  return result;
}

std::string DigitizeResult::Failure() const {
  return ok ? std::string() : InputError(failed_at, reason).what();
}

std::string HintsUsed(const DigitizeResult& result) {
  std::string hints = result.graticule.from_corners_hint ? "graticule_corners" : "";
  for (const DigitizedTrace& trace : result.traces) {
    if (trace.from_points_hint) hints += (hints.empty() ? "" : ", ") + trace.name + ".points";
  }
  return hints;
}

std::vector<TraceRequest> TraceRequestsOf(const Run& run) {
  std::vector<TraceRequest> requests;
  for (const auto& [name, settings] : run.traces) {
    if (!settings.csv) requests.push_back({name, settings});
  }
  return requests;
}

std::vector<TraceRequest> TraceRequestsOf(const Calibration& calibration) {
  if (calibration.trace.csv) return {};
  // Without the pendulum the swing's quarter period is unknown: the whole
  // sweep is taken to run one way (the cell is monotone on the far side of
  // equilibrium too).
  return {{calibration.cell, calibration.trace, std::numeric_limits<double>::infinity()}};
}

}  // namespace impactlab
