// arbor::qp::detail: the checks setup() and update() run on QP data: finite entries, ordered
// bounds, and (unless the caller assumes it) convexity of a Hessian block. Cost: one pass over
// each checked vector or matrix; the convexity check is one Cholesky of the block (n^3 / 6
// multiply-adds) on a copy.
#pragma once

#include <cmath>
#include <limits>

#include "arbor/qp/cholesky.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp::detail {

/// True when every entry of every argument (Eigen objects) is finite.
template <typename... Mats>
bool all_finite(const Mats&... m) {
  return (m.allFinite() && ...);
}

/// Checks bounds: no NaN, lb <= ub, lb < +inf, ub > -inf. Returns accepted, non_finite or
/// invalid_bounds.
template <typename Vec>
[[nodiscard]] QpStatus check_bounds(const Vec& lb, const Vec& ub) {
  using Scalar = typename Vec::Scalar;
  constexpr Scalar inf = std::numeric_limits<Scalar>::infinity();
  for (int i = 0; i < lb.size(); ++i) {
    if (std::isnan(lb(i)) || std::isnan(ub(i)))
      return QpStatus::non_finite;
    if (lb(i) > ub(i) || lb(i) == inf || ub(i) == -inf)
      return QpStatus::invalid_bounds;
  }
  return QpStatus::accepted;
}

/// True when a symmetric matrix (upper triangle read) is positive semidefinite up to a relative
/// slack: the Cholesky of h + slack (1 + |h|_max) n I succeeds.
template <typename Mat>
bool is_psd(const Mat& h, typename Mat::Scalar slack) {
  using Scalar = typename Mat::Scalar;
  Mat m = h;
  const Scalar scale = Scalar(1) + (h.size() > 0 ? h.cwiseAbs().maxCoeff() : Scalar(0));
  m.diagonal().array() += slack * scale * Scalar(h.rows());
  return cholesky_upper_in_place(m);
}

}  // namespace arbor::qp::detail
