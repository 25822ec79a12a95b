// A contact edge from where the beam leaves one level and reaches the other
// (internal to digitize/). The circuit switches in about a microsecond, so
// the level the beam leaves ends, and the level it reaches begins, at the
// edge's place on the sweep. Read along the sweep at each level's height the
// two are mirror images of each other about the edge, whatever the beam's end
// looks like (its spot, the camera's blur, a tone curve that acts on both
// alike). And whatever else both rows hold at the same place along the sweep
// (a vertical grid line, the faint stroke between the levels, the
// background's slope) cancels in their difference
//
//   D(u) = leaving(u) - reaching(u),
//
// which is antisymmetric about the edge: D(m + s) + D(m - s) = 2 mu for every
// s. The bright levels carry the edge, not the stroke several times fainter
// than a grid line; a line lying on the edge no longer hides it.
//
// A line cancels only as far as the photo adds light: where it crosses one
// level's bright part and the other's dark background, a saturating tone
// curve shows it fainter on the bright one. What is left of it in D is about
// the line's own profile times how differently bright the two rows are
// there, times the share of the line that does not cancel (between none and
// all of it): a term of the fit, which costs the centre precision only when
// the line lies within the beam's end.
#pragma once

#include <vector>

namespace impactlab::digitize {

struct LevelJumpSearch {
  double centre_lo_px = 0.0, centre_hi_px = 0.0;  // where the edge may lie
  double half_window_px = 4.0;  // the antisymmetry is asked of D out to this either side
  // The profiles of the grid lines both rows cross, on the same offsets.
  std::vector<std::vector<double>> lines;
};

struct LevelJump {
  bool found = false;
  double centre_px = 0.0;
  // The centre's standard deviation from what the antisymmetry leaves, the
  // residuals' correlation along the profile allowed for.
  double sigma_px = 0.0;
  double step = 0.0;          // D well before the edge less D well after it, ink units
  double residual_rms = 0.0;  // of the antisymmetry, ink units
  // Each row's own step, where it crosses half way between its level and
  // its background (the lines' light taken out where the row is dark): the
  // leaving level's end and the reaching level's beginning. They coincide
  // when the circuit switches within the beam's width; an edge that settles
  // slowly (an RC exponential: the reaching level is approached, never
  // jumped to) begins the reaching level several time constants after the
  // leaving one ends, and the two rows are no mirror images. NaN where a
  // row shows no such crossing.
  double leaving_end_px = 0.0, reaching_start_px = 0.0;
};

// The edge from the two levels' profiles on the same equally spaced offsets:
// `leaving` bright before the edge (lower offsets), `reaching` after it.
// found = false when the levels do not step across the window by more than
// what the antisymmetry leaves unexplained, or the centre is pressed against
// the search's end.
LevelJump FitLevelJump(const std::vector<double>& offsets, const std::vector<double>& leaving,
                       const std::vector<double>& reaching, const LevelJumpSearch& search);

}  // namespace impactlab::digitize
