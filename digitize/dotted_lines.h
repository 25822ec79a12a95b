// Dotted lines (internal to digitize/): a digital scope draws its graticule
// as lit pixels a fifth of a division apart, while its menu boxes, the
// display's frame, the channels' text and the traces are solid strokes.
// Voted pixel by pixel, the strokes outweigh the dots, and the lattice found
// runs through the boxes and the frame. A person sees the grid as rows of
// dots: the ridge image kept only where it is a dot (bright, and no short
// straight stroke in any direction runs through it) holds the grid and
// little else, and the lattice is looked for there when it is found nowhere
// else (docs/digitizing.md, "Digital screens").
#pragma once

#include <array>

#include <opencv2/core.hpp>

#include "digitize/digitize.h"

namespace impactlab::digitize {

// The length, in working pixels, of the straight strokes that are taken out:
// longer than a dot seen at the working scale (a lit display pixel a pixel or
// two across), shorter than the dots' spacing along a line in any working
// copy a grid is searched in (a fifth of a division, at least five pixels
// when a division spans 25 or more).
inline constexpr int kDotStrokePx = 5;

// `ridge` where it stands `floor` above what its strokes keep: the ridge less
// its largest opening by a straight segment kDotStrokePx long in eight
// directions, zero where that is below `floor`.
cv::Mat1f DotsOf(const cv::Mat1f& ridge, float floor);

// What a lattice's outermost lines say of where it stands. Each family's
// first and last lines must stand in `photo`'s ridge image (dots, or a
// solid frame) at least a quarter as high as its inner lines' median. A
// lattice found among the dots alone a division off the grid sees dots
// along every line inside it and passes every other check, while one
// outermost line lies on the bezel and the grid's own last line stands
// beyond its other end (the generator's digital screens: 7 of the 20
// lattices found among dots, one family a division off or both, 51-219 px
// at their corners). Such a lattice is moved a division that way
// (`shift_div`, screen divisions). A line beyond the last is not asked to be
// absent: a digital scope's menu boxes stand a division or so beside the
// grid.
struct OuterLines {
  bool agree = false;           // both outermost lines of each family stand
  cv::Point2d shift_div{0, 0};  // where they do not: the move that would mend it, or 0
};
OuterLines JudgeOuterLines(const PreparedPhoto& photo, const GraticuleFit& fit);

}  // namespace impactlab::digitize
