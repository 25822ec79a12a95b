// A faint grid as a whole (internal to digitize/): the evenly spaced comb of
// lines that a family's votes along one direction hold most of.
//
// The Hough peaks find lines one at a time, each against the photo's
// brightest line (a print's frame, a bezel's lip, a trace's flat stretch):
// a grid lit at a few percent of those falls below every per-line floor,
// although a person sees it at once, because it repeats. The comb adds the
// votes of all its lines, so a grid of eleven lines stands out where no one
// of them does, and a frame's two lines or a trace's one cannot outweigh it
// (each line's share is capped near the comb's typical line).
#pragma once

#include <vector>

namespace impactlab::digitize {

struct CombLine {
  double rho = 0.0;    // position along the profile, its index units
  double votes = 0.0;  // the profile's height there above its local floor
};

// `profile` above its local floor, never below 0: the running median over a
// window of `half` positions either side. Noise votes everywhere, more where
// the photo is wider across, and a broad hump (glare, a print's border) is
// no line; a line a few positions wide stands above it.
std::vector<double> AboveFloor(const std::vector<double>& profile, int half);

// The best comb of `n_lines` equally spaced lines in `profile` (votes per
// position along the transversal, one direction), spaced between
// `min_spacing` and `max_spacing` positions; each line placed at the
// profile's peak within a sixth of the spacing of its tooth. Empty when the
// profile holds no comb (too short, or flat).
std::vector<CombLine> FindComb(const std::vector<double>& profile, int n_lines, double min_spacing,
                               double max_spacing);

}  // namespace impactlab::digitize
