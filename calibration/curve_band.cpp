#include "calibration/curve_band.h"

#include <algorithm>

namespace impactlab::curve_band {

Eigen::MatrixXd BlockJackknifeCovariance(const Eigen::MatrixXd& weighted_basis,
                                         const Eigen::VectorXd& weighted_values, int blocks) {
  const Eigen::Index n = weighted_basis.rows(), terms = weighted_basis.cols();
  Eigen::MatrixXd refits(blocks, terms);
  for (int k = 0; k < blocks; ++k) {
    const Eigen::Index from = n * k / blocks, to = n * (k + 1) / blocks;
    const Eigen::Index kept = n - (to - from);
    Eigen::MatrixXd a(kept, terms);
    Eigen::VectorXd b(kept);
    a << weighted_basis.topRows(from), weighted_basis.bottomRows(n - to);
    b << weighted_values.head(from), weighted_values.tail(n - to);
    refits.row(k) = a.colPivHouseholderQr().solve(b).transpose();
  }
  const Eigen::MatrixXd centred = refits.rowwise() - refits.colwise().mean();
  return (static_cast<double>(blocks - 1) / blocks) * centred.transpose() * centred;
}

Eigen::MatrixXd Covering(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(b - a);
  const Eigen::VectorXd positive = eigen.eigenvalues().cwiseMax(0.0);
  return a + eigen.eigenvectors() * positive.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace impactlab::curve_band
