#include "calibration/curve_band.h"

#include <algorithm>

namespace impactlab::curve_band {

Eigen::MatrixXd BlockJackknifeCovariance(const Eigen::MatrixXd& weighted_basis,
                                         const Eigen::VectorXd& weighted_values, int blocks) {
  const Eigen::Index n = weighted_basis.rows(), terms = weighted_basis.cols();
  // The first and last blocks stay: without them the refit extrapolates over
  // the curve's ends, and its scatter there says how far a polynomial wanders
  // beyond its data (tens of percent of X0 at X = 0 for an order 9), not how
  // much the curve depends on a stretch that is there.
  const int interior = blocks - 2;
  Eigen::MatrixXd refits(interior, terms);
  for (int k = 1; k <= interior; ++k) {
    const Eigen::Index from = n * k / blocks, to = n * (k + 1) / blocks;
    const Eigen::Index kept = n - (to - from);
    Eigen::MatrixXd a(kept, terms);
    Eigen::VectorXd b(kept);
    a << weighted_basis.topRows(from), weighted_basis.bottomRows(n - to);
    b << weighted_values.head(from), weighted_values.tail(n - to);
    refits.row(k - 1) = a.colPivHouseholderQr().solve(b).transpose();
  }
  // (blocks - 1) / blocks times the sum over all blocks, that sum estimated
  // from the interior ones' (blocks / interior times theirs).
  const Eigen::MatrixXd centred = refits.rowwise() - refits.colwise().mean();
  return (static_cast<double>(blocks - 1) / interior) * centred.transpose() * centred;
}

Eigen::MatrixXd Widened(const Eigen::MatrixXd& least_squares, const Eigen::MatrixXd& jackknife) {
  constexpr double kSignificant = 2.0;  // above the 1.88 that chance reaches 1 time in 20
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jackknife -
                                                             kSignificant * least_squares);
  const Eigen::VectorXd excess = eigen.eigenvalues().cwiseMax(0.0);
  return least_squares +
         eigen.eigenvectors() * excess.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace impactlab::curve_band
