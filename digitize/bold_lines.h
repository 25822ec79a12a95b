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

}  // namespace impactlab::digitize
