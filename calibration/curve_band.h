// The calibration curve's band beyond what least squares says. The fit's
// covariance (inflated for the residuals' correlation) assumes the curve's
// shape follows the photocell; where the digitizer misread a stretch of the
// calibration trace (a mark or a grid line followed for a few divisions, a
// sparse dashed trace's few dashes) a high order follows the misreading too,
// its residuals stay small and the band stays narrow there. How much the
// curve depends on each stretch of the trace is measured by refitting it
// without that stretch (a delete-a-block jackknife), and the band is widened
// where that says significantly more. Internal to the calibration library
// (Eigen stays private).
#pragma once

#include <Eigen/Dense>

namespace impactlab::curve_band {

// The delete-a-block jackknife covariance of a linear least-squares fit's
// coefficients: the rows (in trace order, already weighted) cut into
// `blocks` contiguous blocks (at least 3), the fit repeated without each
// interior one (the two at the ends always kept: without them the fit
// extrapolates), and (blocks - 1) / (blocks - 2) times the scatter of the
// refitted coefficients about their mean (the jackknife's (blocks - 1) /
// blocks times a sum over all blocks, estimated from the interior ones').
// Blocks longer than the residuals' correlation make it honest for
// correlated errors as well (Künsch 1989).
Eigen::MatrixXd BlockJackknifeCovariance(const Eigen::MatrixXd& weighted_basis,
                                         const Eigen::VectorXd& weighted_values, int blocks);

// The band widened by the jackknife where it says significantly more:
// least_squares plus the positive part of (jackknife - 2 least_squares),
// so that in every direction t the variance is least squares' plus whatever
// the jackknife's exceeds twice that by. Ten blocks' jackknife variance
// scatters like chi^2 with 9 degrees of freedom over 9 about the true one
// (its 95th percentile 1.88): where the curve depends on no single stretch
// more than least squares says, it is left as it was; where a misread stretch
// carries it (the jackknife's variance tens of times least squares'), the
// band takes the jackknife's.
Eigen::MatrixXd Widened(const Eigen::MatrixXd& least_squares, const Eigen::MatrixXd& jackknife);

}  // namespace impactlab::curve_band
