// The coarse course through a band's candidate peaks (internal to
// digitize/): dynamic programming over the strip's columns, and the check
// that takes a continuous line crossing a chopped trace out of its course.
#pragma once

#include <optional>
#include <vector>

#include "digitize/trace_track.h"

namespace impactlab::digitize {

// A candidate peak in a strip column, and the best course reaching it.
struct Node {
  int column = 0;
  double row = 0.0;  // sub-row peak position
  float value = 0.0f;
  double hint_reward = 0.0;  // beside a hinted point: the hint's reward, less with the distance
  double score = 0.0;
  int previous = -1;  // node index, or -1 for a start
  unsigned char link = CoarsePath::kOnCourse;
  double slope = 0.0;  // the course's slope arriving here, rows' direction, div/div
  double trust = 0.0;  // 0..1: how far that slope is to be believed
  // A one-way course (OneWay): the furthest it has gone in its direction
  // arriving here, rows times the direction.
  double furthest = 0.0;
};

// A course's chosen candidates, in column order.
struct Chosen {
  int column = 0;
  int index = 0;  // in its column's candidates
  unsigned char link = CoarsePath::kOnCourse;
};

// The best-scoring course through the columns' candidates: per column one
// candidate or none, rewarded for its peak (relative to `level`) and charged
// for leaving the course, steepness, gaps (bridged up to `max_gap` columns)
// and restarts; a step trace's levels are flat and its edges jump.
//
// A one-way course (a calibration's trace: the bar swings one way from its
// release across the sweep, and the cell's output is monotone in its
// displacement) never turns back in height by more than `back_rows` from the
// furthest it has gone in `direction` (+1: rows growing, down the screen;
// -1: up it), across gaps and restarts too.
struct OneWay {
  int direction = 0;  // 0: any course
  double back_rows = 0.0;
};
std::vector<Chosen> BestCourse(const std::vector<std::vector<Node>>& columns, const TrackGrid& grid,
                               double level, bool step_trace, int max_gap, OneWay one_way = {});

// The chopper a course shows, when it shows one the columns resolve: many
// runs of neighbouring columns, nearly all of a dash's length, with gaps of
// two columns or more between them.
std::optional<Chopper> ChopperOf(const std::vector<Chosen>& chosen);

// The candidates of runs of neighbouring columns that look foreign to a
// chopped trace's course: a continuous line (scratch, hair) it took. Empty
// when the course does not show a chopper the columns resolve, unless
// `beam` is the chopper another trace on the photo shows (the displacement
// traces share a chopped beam): then a line the course took unbroken over
// several of its periods is foreign wherever it lies, and however much of
// the course it makes.
std::vector<Chosen> ForeignRuns(const std::vector<Chosen>& chosen,
                                std::optional<Chopper> beam = std::nullopt);

// The candidates of excursions a continuous trace's course made where it
// lost the trace: stretches reached and left by restarts whose jumps the
// stretch's own slope does not explain, more than `jump_rows` each, between
// courses on either side that agree with each other (a label beside the
// trace, taken where the trace ran faint along a grid line). Empty when
// there are none. Not for a contact trace, whose levels jump by design.
std::vector<Chosen> StrayExcursions(const std::vector<Chosen>& chosen,
                                    const std::vector<std::vector<Node>>& columns,
                                    double jump_rows);

// Whether `course` (on the candidates `kept`) runs more than `away_rows`
// from the `suspect` candidates (on `all`) in at least half their columns.
bool RunsElsewhere(const std::vector<Chosen>& course, const std::vector<std::vector<Node>>& kept,
                   const std::vector<Chosen>& suspect, const std::vector<std::vector<Node>>& all,
                   double away_rows);

}  // namespace impactlab::digitize
