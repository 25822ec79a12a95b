// The graticule's lattice, roughly (internal to digitize/): which lines of the
// working copy are the grid's, and which division each one is.
//
// Thin bright structure votes in a Hough transform; the two families of
// lines (near vertical, near horizontal) are the two directions whose votes
// concentrate most. Within a family the grid is the longest run of lines
// whose positions along a transversal follow a projective progression
// u(n) = (a n + b) / (c n + 1) (a perspective view of equal spacing) and
// whose directions turn smoothly with n; traces, scratches and the bezel's
// edge fall out of step with it. Each family's lines are then fitted as a
// pencil l(n) = A + n B (the image of the screen lines x = n under a
// homography), and their crossings give the homography.
#pragma once

#include <array>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "digitize/digitize.h"

namespace impactlab::digitize {

struct Lattice {
  cv::Matx33d working_from_screen;          // working pixels from (x_div, y_div, 1)
  std::array<int, 2> lines_found = {0, 0};  // vertical, horizontal lines seen in the Hough votes
};

// nullopt when no lattice of `divisions` is found; `why` then says what failed.
std::optional<Lattice> FindLattice(const PreparedPhoto& photo, std::array<int, 2> divisions,
                                   double max_rotation_deg, std::string* why);

// The homography taking `from` to `to` (four or more points), by the
// normalised direct linear transform.
cv::Matx33d FitHomography(const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to);

}  // namespace impactlab::digitize
