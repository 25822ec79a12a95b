// Halftone screens (internal to digitize/): a figure reproduced in print is
// made of ink dots on a regular lattice (the screen), whose size follows the
// tone. A grid line is then a row of dots and a trace a band of them: every
// measurement that assumes a continuous line (the lattice's ridges, the grid
// lines' profiles, a trace's centre) sees the dots instead. The screen is
// found in the photo's spectrum and taken out by a low-pass filter that
// removes its period, which is what a person's eye does at reading distance.
#pragma once

#include <optional>

#include <opencv2/core.hpp>

namespace impactlab::digitize {

struct HalftoneScreen {
  double period_px = 0.0;  // the dots' spacing along the screen's lattice, photo pixels
  double angle_deg = 0.0;  // the lattice's direction, degrees in [0, 90)
  double contrast = 0.0;   // the screen's spectral peak over the spectrum's level at its frequency
};

// The halftone screen of `image` (8 or 16 bit, 1, 3 or 4 channels), found as a
// pair of orthogonal, equally long frequencies in the spectrum of the photo's
// middle that stand far above everything else at their radius (periods
// 2.2–16 px). A JPEG's 8 x 8 block pattern (periods 8/k along the axes) is
// not taken for one. nullopt: no screen.
std::optional<HalftoneScreen> FindHalftoneScreen(const cv::Mat& image);

// The image low-passed so that `screen`'s dots merge into continuous tone: a
// Gaussian whose sigma is 0.35 of the screen's period leaves 9 % of the
// screen's fundamental (exp(-2 pi^2 0.35^2)) and widens a line by about a
// period. Same type as `image`.
cv::Mat Descreen(const cv::Mat& image, const HalftoneScreen& screen);

}  // namespace impactlab::digitize
