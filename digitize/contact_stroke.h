// A faint stroke's centre across it, modelled together with the grid lines
// beside it (internal to digitize/). A contact edge is a stroke several times
// fainter than the graticule's lines and often lies within a line's width of
// one; a centre found from the stroke's half maximum or its symmetry then
// takes part of the line's light for the stroke's. Here the profile across
// the stroke is fitted as a straight background, each line's own profile
// (measured where the stroke is not), their overlap with the stroke, and the
// stroke, a Gaussian of free centre, width and height.
#pragma once

#include <vector>

namespace impactlab::digitize {

// The light of what else the profile crosses (a grid line), one value per
// profile sample, and how much of it the profile holds: a least-squares
// coefficient, drawn towards `prior` (when prior_sigma > 0) and never
// negative.
struct StrokeNeighbour {
  std::vector<double> shape;
  double prior = 1.0;
  double prior_sigma = 0.0;  // 0: free
};

struct StrokeSearch {
  double centre_lo_px = 0.0, centre_hi_px = 0.0;  // where the stroke's centre may lie
  double fwhm_lo_px = 1.0, fwhm_hi_px = 8.0;      // its full width at half maximum
  double noise = 0.0;  // one sample's noise, ink units: weighs the neighbours' priors
  // The stroke's least height, ink units (0: any): a stroke known from
  // elsewhere (the pulse's other edge, the same beam at the same speed) cannot
  // pass for a faint bump of the background.
  double height_lo = 0.0;
  // Where the stroke overlaps a neighbour the photo's tone curve does not
  // add their light (a film's or sensor's response is not linear): a term
  // stroke x neighbour (normalized to 1 at its peak) takes that up, its
  // coefficient within +-the stroke's height (the tone can take all of the
  // stroke's light away on the line's peak, or double it, no more).
  bool overlap_term = true;
};

struct StrokeFit {
  bool found = false;
  double centre_px = 0.0;
  double fwhm_px = 0.0;
  double height = 0.0;                   // the stroke's peak above the background, ink units
  double residual_rms = 0.0;             // of the whole fit, ink units
  std::vector<double> neighbour_scales;  // each neighbour's coefficient (0 when left out)
  double overlap = 0.0;  // the first neighbour's overlap coefficient over the stroke's height
  // How far the centre moves per unit of white noise on the samples: the
  // centre's standard deviation is this times one sample's noise.
  double centre_per_noise_px = 0.0;
  // How much the residuals' correlation along the profile multiplies that:
  // sqrt(1 + 2 sum of their autocorrelations), >= 1.
  double correlation = 1.0;
};

// The model fitted to (offset, value) samples: the centre (and width) by
// search within `search`, the rest by linear least squares for each trial.
StrokeFit FitStroke(const std::vector<double>& offsets, const std::vector<double>& values,
                    const std::vector<StrokeNeighbour>& neighbours, const StrokeSearch& search);

// The light of a Gaussian line of the given centre and full width at half
// maximum at each offset.
std::vector<double> GaussianShape(const std::vector<double>& offsets, double centre_px,
                                  double fwhm_px);

}  // namespace impactlab::digitize
