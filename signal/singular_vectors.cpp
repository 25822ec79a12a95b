#include "signal/singular_vectors.h"

#include <Eigen/SVD>

namespace impactlab {

Eigen::MatrixXd LeadingRightSingularVectors(const Eigen::MatrixXd& matrix, Eigen::Index count) {
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(matrix, Eigen::ComputeThinV);
  return svd.matrixV().leftCols(count);
}

}  // namespace impactlab
