// The calibration curve's band beyond what least squares says. The fit's
// covariance (inflated for the residuals' correlation) assumes the curve's
// shape follows the photocell; where the digitizer misread a stretch of the
// calibration trace (a mark or a grid line followed for a few divisions, a
// sparse dashed trace's few dashes) a high order follows the misreading too,
// its residuals stay small and the band stays narrow there. How much the
// curve depends on each stretch of the trace is measured by refitting it
// without that stretch (a delete-a-block jackknife), and the band is made to
// cover both. Internal to the calibration library (Eigen stays private).
#pragma once

#include <Eigen/Dense>

namespace impactlab::curve_band {

// The delete-a-block jackknife covariance of a linear least-squares fit's
// coefficients: the rows (in trace order, already weighted) cut into
// `blocks` contiguous blocks, the fit repeated without each, and
// (blocks - 1) / blocks times the scatter of the refitted coefficients
// about their mean. Blocks longer than the residuals' correlation make it
// honest for correlated errors as well (Künsch 1989).
Eigen::MatrixXd BlockJackknifeCovariance(const Eigen::MatrixXd& weighted_basis,
                                         const Eigen::VectorXd& weighted_values, int blocks);

// a plus the positive part of (b - a): a covariance at least as wide as
// either in every direction (t' C t >= t' a t and >= t' b t for every t),
// and a itself where b is no wider.
Eigen::MatrixXd Covering(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

}  // namespace impactlab::curve_band
