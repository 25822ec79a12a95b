#include "fit/quantisation_covariance.h"

#include <cmath>
#include <cstddef>

namespace impactlab {

Eigen::MatrixXd QuantisationScoreCovariance(const Eigen::Ref<const Eigen::MatrixXd>& rows,
                                            std::span<const double> angle_rad, double step_rad,
                                            double sigma, int phases) {
  const Eigen::Index p = rows.cols();
  Eigen::MatrixXd scores(p, phases);
  Eigen::VectorXd error(rows.rows());
  for (int k = 0; k < phases; ++k) {
    const double u = (k + 0.5) / phases;
    for (Eigen::Index i = 0; i < rows.rows(); ++i) {
      const double theta = angle_rad[static_cast<std::size_t>(i)];
      error(i) = ((std::floor(theta / step_rad + u) - u + 0.5) * step_rad - theta) / sigma;
    }
    scores.col(k) = rows.transpose() * error;
  }
  const Eigen::VectorXd mean = scores.rowwise().mean();
  const Eigen::MatrixXd centred = scores.colwise() - mean;
  return centred * centred.transpose() / phases;
}

}  // namespace impactlab
