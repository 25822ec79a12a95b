#include "signal/qr_compressed_cost.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <stdexcept>
#include <utility>

#include <Eigen/Dense>

namespace impactlab {

QrCompressedCost::QrCompressedCost(int rows, const std::vector<int>& block_sizes,
                                   TallResiduals residuals)
    : rows_(rows), full_(std::move(residuals)) {
  for (int size : block_sizes) {
    mutable_parameter_block_sizes()->push_back(size);
    parameters_ += size;
  }
  if (rows_ < parameters_ + 1) {
    throw std::invalid_argument("QrCompressedCost: fewer rows than parameters plus one");
  }
  set_num_residuals(parameters_ + 1);
  const auto columns = static_cast<std::size_t>(parameters_ + 1);
  scratch_.resize(static_cast<std::size_t>(rows_) * columns);
  kept_parameters_.resize(static_cast<std::size_t>(parameters_));
  kept_triangle_.resize(columns * columns);
}

bool QrCompressedCost::IsKept(double const* const* parameters) const {
  if (!kept_) return false;
  std::size_t k = 0;
  for (std::size_t block = 0; block < parameter_block_sizes().size(); ++block) {
    for (int j = 0; j < parameter_block_sizes()[block]; ++j, ++k) {
      if (std::bit_cast<std::uint64_t>(parameters[block][j]) !=
          std::bit_cast<std::uint64_t>(kept_parameters_[k])) {
        return false;
      }
    }
  }
  return true;
}

void QrCompressedCost::Keep(double const* const* parameters) const {
  std::size_t k = 0;
  for (std::size_t block = 0; block < parameter_block_sizes().size(); ++block) {
    for (int j = 0; j < parameter_block_sizes()[block]; ++j, ++k) {
      kept_parameters_[k] = parameters[block][j];
    }
  }
  kept_ = true;
}

void QrCompressedCost::Answer(double* residuals, double** jacobians) const {
  const Eigen::Index p = parameters_;
  const Eigen::Map<const Eigen::MatrixXd> triangle(kept_triangle_.data(), p + 1, p + 1);
  for (Eigen::Index i = 0; i <= p; ++i) residuals[i] = triangle(i, p);
  if (jacobians == nullptr) return;
  Eigen::Index column = 0;
  for (std::size_t block = 0; block < parameter_block_sizes().size(); ++block) {
    const Eigen::Index width = parameter_block_sizes()[block];
    if (jacobians[block] != nullptr) {
      // Ceres's blocks are row-major, (p + 1) x width.
      double* out = jacobians[block];
      for (Eigen::Index i = 0; i <= p; ++i) {
        for (Eigen::Index j = 0; j < width; ++j) out[i * width + j] = triangle(i, column + j);
      }
    }
    column += width;
  }
}

bool QrCompressedCost::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  if (IsKept(parameters)) {
    Answer(residuals, jacobians);
    return true;
  }
  const Eigen::Index n = rows_, p = parameters_;
  double* r = scratch_.data() + n * p;  // the last column
  if (jacobians == nullptr) {
    if (!full_(parameters, r, nullptr)) return false;
    std::fill_n(residuals, p, 0.0);
    residuals[p] = Eigen::Map<const Eigen::VectorXd>(r, n).norm();
    return true;
  }
  kept_ = false;
  if (!full_(parameters, r, scratch_.data())) return false;
  Eigen::Map<Eigen::MatrixXd> augmented(scratch_.data(), n, p + 1);
  // In place: the upper triangle becomes [R Q^T r; 0 +-rho], the Householder
  // vectors below it are not kept.
  const Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(augmented);
  Eigen::Map<Eigen::MatrixXd>(kept_triangle_.data(), p + 1, p + 1) =
      augmented.topRows(p + 1).triangularView<Eigen::Upper>();
  Keep(parameters);
  Answer(residuals, jacobians);
  return true;
}

}  // namespace impactlab
