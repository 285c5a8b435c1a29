// arbor::qp::detail: small dense Cholesky kernels on fixed-size Eigen matrices.
//
// M = U' U with U upper triangular, computed in place in the upper triangle (the strictly lower
// part is left untouched and never read). Column-oriented loops, so with Eigen's default
// column-major storage all inner loops run over contiguous memory. No allocation, no pivoting:
// used only on matrices that are positive definite by construction (regularised KKT blocks);
// a non-positive pivot is reported, never hidden.
#pragma once

#include <cmath>

namespace arbor::qp::detail {

/// Factorizes the symmetric matrix a (upper triangle read) as U'U in place; false when a pivot is
/// not positive (a not positive definite to working precision) or not finite.
template <typename Mat>
bool cholesky_upper_in_place(Mat& a) {
  using Scalar = typename Mat::Scalar;
  constexpr int n = Mat::RowsAtCompileTime;
  static_assert(n == Mat::ColsAtCompileTime, "square matrix expected");
  for (int j = 0; j < n; ++j) {
    for (int k = 0; k < j; ++k) {
      Scalar s = a(k, j);
      for (int i = 0; i < k; ++i)
        s -= a(i, k) * a(i, j);
      a(k, j) = s / a(k, k);
    }
    Scalar d = a(j, j);
    for (int i = 0; i < j; ++i)
      d -= a(i, j) * a(i, j);
    if (!(d > Scalar(0)) || !std::isfinite(d))
      return false;
    a(j, j) = std::sqrt(d);
  }
  return true;
}

/// Solves U' y = b in place (forward substitution); U from cholesky_upper_in_place; b a vector.
template <typename MatU, typename Vec>
void solve_upper_transposed(const MatU& u, Vec& b) {
  using Scalar = typename MatU::Scalar;
  constexpr int n = MatU::RowsAtCompileTime;
  for (int j = 0; j < n; ++j) {
    Scalar s = b(j);
    for (int i = 0; i < j; ++i)
      s -= u(i, j) * b(i);
    b(j) = s / u(j, j);
  }
}

/// Solves U y = b in place (back substitution); U from cholesky_upper_in_place; b a vector.
template <typename MatU, typename Vec>
void solve_upper(const MatU& u, Vec& b) {
  using Scalar = typename MatU::Scalar;
  constexpr int n = MatU::RowsAtCompileTime;
  for (int j = n - 1; j >= 0; --j) {
    const Scalar yj = b(j) / u(j, j);
    b(j) = yj;
    for (int i = 0; i < j; ++i)
      b(i) -= u(i, j) * yj;
  }
}

/// Solves U' X = B in place for every column of the matrix B (n rows).
template <typename MatU, typename MatB>
void solve_upper_transposed_columns(const MatU& u, MatB& b) {
  using Scalar = typename MatU::Scalar;
  constexpr int n = MatU::RowsAtCompileTime;
  static_assert(MatB::RowsAtCompileTime == n, "row count mismatch");
  for (int c = 0; c < MatB::ColsAtCompileTime; ++c) {
    for (int j = 0; j < n; ++j) {
      Scalar s = b(j, c);
      for (int i = 0; i < j; ++i)
        s -= u(i, j) * b(i, c);
      b(j, c) = s / u(j, j);
    }
  }
}

}  // namespace arbor::qp::detail
