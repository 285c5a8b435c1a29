// arbor: dense Cholesky solve with M (for comparison with minverse/aba), fixed size.
#pragma once

#include "arbor/dynamics/data.hpp"

namespace arbor {

/// Factorizes data.M (call crba first) into data.llt.
template <Robot R, class Scalar>
void cholesky_factor(Data<R, Scalar>& d) {
  d.llt.compute(d.M);
}

/// Solves M x = b with the factor from cholesky_factor.
template <Robot R, class Scalar, class B>
typename Data<R, Scalar>::Vector cholesky_solve(const Data<R, Scalar>& d,
                                                const Eigen::MatrixBase<B>& b) {
  typename Data<R, Scalar>::Vector x = b;
  d.llt.solveInPlace(x);
  return x;
}

}  // namespace arbor
