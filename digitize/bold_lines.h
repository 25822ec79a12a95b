// Bold lines (internal to digitize/): the ridge image keeps what is thinner
// than its opening's square, five working pixels, so a trace wider than that
// at the working scale (a bold line printed in a report's figure, a broad
// beam on a small photo) loses its core there and shows only as its two
// edges, which a scratch or a grid line out-earns. Where the traces'
// reading fails, they are read again on a ridge image that keeps lines up to
// half a division wide, and where that fails too, on one that keeps only
// lines wider than the grid's (docs/digitizing.md, "Bold traces").
#pragma once

#include "digitize/digitize.h"

namespace impactlab::digitize {

// The side of the square whose opening the ridge image is taken less
// (PreparePhoto): a little wider than a grid line or a thin trace.
inline constexpr int kRidgeOpeningPx = 5;

// The side of the square, in working pixels, whose opening the bold ridge
// image is taken less: half a division (odd, so that it is centred), and never
// under the thin ridge image's own square.
int BoldOpeningPx(const PreparedPhoto& photo, const GraticuleFit& graticule);

// `photo` with a ridge image that keeps bright structure up to
// BoldOpeningPx wide: the working copy less its opening by that square.
PreparedPhoto WithBoldLines(const PreparedPhoto& photo, const GraticuleFit& graticule);

// The side of the square, in working pixels, whose opening keeps what is
// wider than a grid line: twice the lines' full width at half maximum (odd),
// never under the thin ridge image's own square. 0 when that square would be
// no narrower than BoldOpeningPx (nothing is left between the two).
int WideOpeningPx(const PreparedPhoto& photo, const GraticuleFit& graticule);

// `photo` with a ridge image that keeps bright structure wider than the grid
// lines and up to BoldOpeningPx wide: the opening by WideOpeningPx less the
// opening by BoldOpeningPx. A bold trace's body stands there at its height
// less what of it is no wider than a grid line, while the grid lines (and
// thin scratches, hairs) are gone: a trace printed in the grid's own ink,
// or lying along a grid line, is told from the lines by its width, as a
// person tells it.
PreparedPhoto WithWideLines(const PreparedPhoto& photo, const GraticuleFit& graticule);

// A successful reading of thin lines that sees a continuously drawn trace
// along less than this share of the sweep may have lost a bold trace's core
// and followed something thin beside it (a hair, a pen stroke, a grid line).
inline constexpr double kWeakCoverage = 0.6;

// Low coverage alone is no sign of that: a run's traces swing steeply, and
// the samples dropped there leave many short gaps (run photos that read fine
// see their traces along 0.36-0.58 of the sweep). A lost bold trace shows
// otherwise: the trace measured is at least kBroadShare of the thin image's
// square wide (that image keeps a fifth less of its height, or none of its
// core), or the reading misses more than kLongGapShare of the sweep in gaps
// of kLongGapDiv and more (it lost the trace, or took a stroke or a hair
// beside it for a short stretch).
inline constexpr double kBroadShare = 0.5;
inline constexpr double kLongGapDiv = 0.25;
inline constexpr double kLongGapShare = 0.4;

// The share of a sweep `sweep_div` divisions long that lies in `trace`'s gaps
// of at least kLongGapDiv, the stretches before its first sample and after
// its last included (1 for a trace without samples).
double LongGapShare(const DigitizedTrace& trace, double sweep_div);

// Whether `trace`, read on `photo`'s ridge image of thin lines, asks for the
// traces to be read on bold lines as well: a continuously drawn trace (one
// read in dashes misses much of the sweep by design) seen along less than
// kWeakCoverage of the sweep, and broad or missing long stretches of it.
bool AsksForBoldReading(const DigitizedTrace& trace, const PreparedPhoto& photo, double sweep_div);

}  // namespace impactlab::digitize
