// Following one trace along its band, coarsely (internal to digitize/).
//
// The band is cut out of the working copy's ridge image and rectified to the
// screen (columns = screen x, rows = screen y), the grid lines are taken out
// of it, and each column's bright peaks become candidates. Dynamic
// programming then picks one candidate per column, or none, maximising the
// peaks' brightness less a penalty for leaving the course (the square of the
// miss from the course's own slope carried on, over the distance; capped for
// a contact trace, whose edges jump), a little for steepness, and one for
// gaps. Gaps of up to max_gap_div (a chopper's blanking, a speck) are bridged
// on course, and a trace that vanishes may reappear anywhere at a fixed price.
#pragma once

#include <limits>
#include <optional>
#include <vector>

#include "digitize/digitize.h"

namespace impactlab::digitize {

// The strip's columns: column c is screen x = c / px_per_div.
struct TrackGrid {
  double px_per_div = 20.0;
  int columns = 0;
  double XOf(int column) const { return column / px_per_div; }
};

TrackGrid MakeTrackGrid(const PreparedPhoto& photo, const GraticuleFit& graticule,
                        const TraceOptions& options);

// What earlier traces took: per column, screen heights and half-widths (div)
// no later trace may use.
struct Claims {
  explicit Claims(int columns) : taken(columns) {}
  std::vector<std::vector<std::pair<double, double>>> taken;
  bool Taken(int column, double y_div) const;
};

struct CoarsePath {
  TrackGrid grid;
  std::vector<double> y_div;  // per column: the trace's screen height, NaN where not seen
  std::vector<float> peak;    // per column: its ridge height (0 where not seen)
  // How the path reaches each column from the previous one it saw.
  static constexpr unsigned char kOnCourse = 0;  // along the trace, bridging short gaps
  static constexpr unsigned char kStep = 1;      // up or down a contact trace's edge
  static constexpr unsigned char kRestart = 2;   // after a long gap, from anywhere
  std::vector<unsigned char> link;
  double level = 0.0;  // the trace's typical ridge height
  double floor = 0.0;  // the smallest peak taken as a candidate
  int seen_columns = 0;

  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
};

// A chopper as a course shows it, in the strip's columns: its dashes' and
// its gaps' usual lengths.
struct Chopper {
  double dash_columns = 0.0, gap_columns = 0.0;
};

// The chopper a path's course shows, when it shows one the columns resolve.
std::optional<Chopper> ChopperOf(const CoarsePath& path);

// With `off_grid_rows`, no candidate is taken on a horizontal grid line's
// row (within a line's width of it): the course is sought again so where its
// first one followed a grid line. With `one_way` (a calibration's trace,
// TraceRequest::one_way_until_s) and TraceOptions::one_way_courses the
// course is sought never turning back by more than a reading's noise, the
// way, up or down, that keeps more of the course sought any way. With
// `beam_chopper` (the chopper another displacement trace on the photo shows:
// they share a chopped beam) a line the course takes unbroken over several
// of its periods is not the trace's (ForeignRuns).
CoarsePath TrackTrace(const PreparedPhoto& photo, const GraticuleFit& graticule,
                      const TraceSettings& settings, const TraceOptions& options,
                      const TrackGrid& grid, const Claims& claims, bool off_grid_rows = false,
                      bool one_way = false, std::optional<Chopper> beam_chopper = std::nullopt);

// Adds the path's course (and its bridged gaps) to `claims`.
void Claim(const CoarsePath& path, double half_width_div, Claims& claims);

}  // namespace impactlab::digitize
