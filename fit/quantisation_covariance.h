// The scatter that an encoder's whole counts put into a least-squares fit.
//
// A count says only which step of the encoder's grid the angle lies in. Read
// at the step's centre, the reading's error e is a sawtooth of the angle
// itself: where the arm rests or creeps it holds one value for hundreds of
// samples, and at the start of a motion it says when the first step is
// crossed, not when the motion began. Such an error is not noise: the fit
// follows much of it, so the residuals do not show it, and no estimate from
// the residuals (a correlation inflation, a sandwich) gives its size. It is a
// known function of the angle and of where the grid lies against it, a
// fraction u of a step that the record cannot tell. So it is computed: with
// the fitted angle theta_i and each phase u of a uniform set over one step,
//   e_i(u) = (floor(theta_i / step + u) - u + 1/2) step - theta_i,
// the score it gives is g(u) = sum_i J_i e_i(u) / sigma, J_i the record's
// whitened Jacobian rows; the score's covariance over u is the encoder's
// part of the sandwich's middle term (fit/secant_covariance.h, SecantSandwich). A
// parameter's error from the counts is then (J^T J)^-1 g(u): linear in e,
// which is a fraction of a step.
#pragma once

#include <span>

#include <Eigen/Core>

namespace impactlab {

// The covariance over the grid's phase u (`phases` evenly spread over one
// step) of the score g(u) = rows^T e(u) / sigma. `rows` are the record's
// rows of the whitened Jacobian (or of its secants; one column per parameter or direction),
// `angle_rad` the fitted angle at its samples, `step_rad` one count, `sigma` the channel's sigma in
// the whitening.
Eigen::MatrixXd QuantisationScoreCovariance(const Eigen::Ref<const Eigen::MatrixXd>& rows,
                                            std::span<const double> angle_rad, double step_rad,
                                            double sigma, int phases = 64);

}  // namespace impactlab
