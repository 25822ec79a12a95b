// Bold lines (internal to digitize/): the ridge image keeps what is thinner
// than its opening's square, five working pixels, so a trace wider than that
// at the working scale (a bold line printed in a report's figure, a broad
// beam on a small photo) loses its core there and shows only as its two
// edges, which a scratch or a grid line out-earns. Where the traces'
// reading fails, they are read again on a ridge image that keeps lines up to
// half a division wide (docs/digitizing.md, "Bold traces").
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

}  // namespace impactlab::digitize
