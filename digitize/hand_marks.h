// Hand marks (internal to digitize/): what a person added to a print — a
// grease-pencil stroke along or across a trace, a ring, an arrow, a written
// label — is drawn with a pencil or pen far wider than the beam's line. A
// trace's own line never is: its width is the spot's, whatever it draws. So
// ink that survives an opening by a square a good deal wider than the
// traces' measured width, and stands as high as a trace above what is
// around it, is a mark; the tracking is not offered it, and samples on it
// are dropped (docs/digitizing.md, "Hand marks").
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "digitize/digitize.h"

namespace impactlab::digitize {

struct HandMarkMap {
  cv::Mat1b mask;  // 255 where a mark lies, grown by the reach of a trace's profile
  int shrink = 1;  // a mask pixel covers shrink x shrink photo pixels
  std::vector<std::vector<cv::Point>> outlines_px;  // each mark's outline, photo pixels

  bool empty() const { return outlines_px.empty(); }
  bool Covers(cv::Point2d photo_px) const;
};

// The marks on `photo`, given the traces' typical width and height (from a
// first reading, or the grid lines' when no trace was read) and the traces
// of that first reading (empty when it failed): ink lying mostly along a
// course they read is the beam's own line, wherever it is thick (a slow
// stretch, a crossing with a grid line printed in the same ink). Only the
// graticule's area is searched. Empty when there are none.
HandMarkMap FindHandMarks(const PreparedPhoto& photo, const GraticuleFit& graticule,
                          double trace_width_px, double trace_height,
                          const std::vector<DigitizedTrace>& first_reading);

// Whether a reading of a trace shows a chopped beam: ten or more runs of
// samples (gaps of at most 0.05 division) whose lengths and gaps are nearly
// all alike and short. Such a beam draws no unbroken run, so what its
// reading followed unbroken (a ring's arc, a stroke along it) is not its own.
bool ReadInDashes(const DigitizedTrace& trace);

// `photo` with the marks taken out of its ridge image, which the tracking
// reads: a mark crossing a trace leaves a gap that the tracking bridges.
PreparedPhoto WithoutMarks(const PreparedPhoto& photo, const HandMarkMap& marks);

// Drops `trace`'s samples that lie on a mark; returns the stretches of the
// sweep (divisions, [from, to]) a mark took from the trace: where samples
// were dropped, and where the trace's course between two kept samples runs
// across a mark (the tracking bridged it, or its samples there were already
// refused as off the line).
std::vector<std::array<double, 2>> DropSamplesOnMarks(const HandMarkMap& marks,
                                                      DigitizedTrace& trace);

}  // namespace impactlab::digitize
