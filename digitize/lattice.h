// The graticule's lattice, roughly (internal to digitize/): which lines of the
// working copy are the grid's, and which division each one is.
//
// Thin bright structure votes in a Hough transform; the two families of
// lines (near vertical, near horizontal) are the two directions whose votes
// concentrate most. Within a family the grid is the longest run of lines
// whose positions along a transversal follow a projective progression
// u(n) = (a n + b) / (c n + 1) (a perspective view of equal spacing) and
// whose directions turn smoothly with n; traces, scratches and the bezel's
// edge fall out of step with it. The two families must be one perspective
// view; where they are not, each is matched again through its comb of
// evenly spaced lines (grid_comb.h), held by the other as matched apart.
// Each family's lines are then fitted as a pencil l(n) = A + n B (the image
// of the screen lines x = n under a homography), and their crossings give
// the homography.
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

// How far above the working copy's noise (robust sigmas) a ridge pixel must
// stand to vote: a grid line's pixels stand well above it in most photos,
// while noise that passes only fills every Hough cell alike.
inline constexpr double kRidgeFloorSigmas = 3.0;
// ... and where no lattice stands out so, the floor the search looks again
// with: a faint grid under heavy noise (sensor noise several times a thin
// line's height) has most of its pixels below three sigmas, and the
// directions are then the traces', labels' or a print's frame's. Its lines
// are long, and each of their pixels above one and a half sigmas adds up
// where the noise's, in every cell alike, does not.
inline constexpr double kFaintRidgeFloorSigmas = 1.5;

// The height a ridge pixel must stand at to vote: `floor_sigmas` robust
// sigmas above the median of the frame's middle (and at least 0.005), the
// median in `median` when asked for.
float RidgeFloor(const cv::Mat1f& ridge, double floor_sigmas, float* median = nullptr);
// nullopt when no lattice of `divisions` is found; `why` then says what
// failed. Ridge pixels vote when they stand `ridge_floor_sigmas` above the
// noise.
std::optional<Lattice> FindLattice(const PreparedPhoto& photo, std::array<int, 2> divisions,
                                   double max_rotation_deg, std::string* why,
                                   double ridge_floor_sigmas = kRidgeFloorSigmas);

// The homography taking `from` to `to` (four or more points), by the
// normalised direct linear transform.
cv::Matx33d FitHomography(const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to);

}  // namespace impactlab::digitize
