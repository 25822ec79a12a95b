// The leading right singular vectors of a dense matrix, by Eigen's
// divide-and-conquer SVD: the matrix pencil's signal subspace
// (signal/damped_modes.cpp).
//
// A file of its own for compile time: instantiating Eigen::BDCSVD costs about
// as much as everything else in damped_modes.cpp together (~35 s of CPU each
// with GCC 12 at -O3), so apart the two compile in parallel. Cheaper-to-compile
// substitutes cost more elsewhere: JacobiSVD makes the pencil 3x slower at its
// default size (7x at 1000 samples), and the eigenvectors of H^T H square the
// condition number, which moves the weak and spurious poles.
// Internal to signal/: Eigen is a private dependency of impactlab_signal.
#pragma once

#include <Eigen/Core>

namespace impactlab {

// The right singular vectors of `matrix` for its `count` largest singular
// values, by decreasing singular value (count <= matrix.cols()).
Eigen::MatrixXd LeadingRightSingularVectors(const Eigen::MatrixXd& matrix, Eigen::Index count);

}  // namespace impactlab
