// arbor::qp::detail: kernels on packed lower triangles (kernels::packed_col: column j holds rows
// j..n-1, n (n+1) / 2 scalars) for the OCP backend's factor (ocp_riccati_backend.hpp): the
// triangular solves L y = b and L' y = b (four columns at a time, ~n^2 / 2 multiply-adds each),
// one column step of a rank-one update or downdate (Givens-free hyperbolic rotation: ~3 (n - j + m)
// multiply-adds), and the packing of a full lower triangle. Plain loops over compile-time sizes
// on raw pointers; they assume no alignment (loads and stores through unaligned Maps or scalar
// accesses, docs/qp.md "Alignment"): the packed columns start at any scalar offset.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <type_traits>
#include <utility>

#include "arbor/qp/kernels.hpp"

namespace arbor::qp::detail {

/// Solves L y = b in place, L lower of order n packed (kernels::packed_col): four columns at a
/// time, the 4 x 4 diagonal block first, then one pass over the rows below it; on a local copy
/// of b (no aliasing with l: the row passes vectorise without a runtime overlap test). The
/// pivots' inverses depend on l only, so the out-of-order core computes them ahead and the
/// chain through b carries multiplications, not divisions (~13 cycles of latency each on the
/// host; bench/qp/RESULTS.md: -5 % CPU time of a warm solve). Same for the back substitution.
template <int n, typename Scalar>
void solve_lower_packed(const Scalar* l, Scalar* bout) {
  Scalar b[n];
  for (int r = 0; r < n; ++r)
    b[r] = bout[r];
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    // c_i[r] = L(r, j + i), r >= j + i
    const Scalar* c0 = l + kernels::packed_col(n, j) - j;
    const Scalar* c1 = l + kernels::packed_col(n, j + 1) - (j + 1);
    const Scalar* c2 = l + kernels::packed_col(n, j + 2) - (j + 2);
    const Scalar* c3 = l + kernels::packed_col(n, j + 3) - (j + 3);
    const Scalar i0 = Scalar(1) / c0[j], i1 = Scalar(1) / c1[j + 1];
    const Scalar i2 = Scalar(1) / c2[j + 2], i3 = Scalar(1) / c3[j + 3];
    const Scalar y0 = b[j] * i0;
    const Scalar y1 = (b[j + 1] - c0[j + 1] * y0) * i1;
    const Scalar y2 = (b[j + 2] - c0[j + 2] * y0 - c1[j + 2] * y1) * i2;
    const Scalar y3 = (b[j + 3] - c0[j + 3] * y0 - c1[j + 3] * y1 - c2[j + 3] * y2) * i3;
    b[j] = y0;
    b[j + 1] = y1;
    b[j + 2] = y2;
    b[j + 3] = y3;
    for (int r = j + 4; r < n; ++r)
      b[r] -= c0[r] * y0 + c1[r] * y1 + c2[r] * y2 + c3[r] * y3;
  }
  for (; j < n; ++j) {
    const Scalar* cj = l + kernels::packed_col(n, j) - j;
    const Scalar yj = b[j] * (Scalar(1) / cj[j]);
    b[j] = yj;
    for (int r = j + 1; r < n; ++r)
      b[r] -= yj * cj[r];
  }
  for (int r = 0; r < n; ++r)
    bout[r] = b[r];
}

/// Back substitution L' y = b for the first m unknowns of b (in place), L lower of order n
/// packed, the last n - m unknowns (already final) given: blocks of four columns whose dot
/// products with the solved part share its loads. m = n: the whole solve L' y = b.
template <int n, int m, typename Scalar>
void solve_lower_transposed_head(const Scalar* l, Scalar* b) {
  static_assert(0 <= m && m <= n);
  constexpr int tail = m % 4;
  for (int j = m - 1; j >= m - tail; --j) {
    const Scalar* cj = l + kernels::packed_col(n, j) - j;
    Scalar s = b[j];
    for (int r = j + 1; r < n; ++r)
      s -= cj[r] * b[r];
    b[j] = s * (Scalar(1) / cj[j]);
  }
  for (int j = m - tail - 4; j >= 0; j -= 4) {
    const Scalar* c0 = l + kernels::packed_col(n, j) - j;
    const Scalar* c1 = l + kernels::packed_col(n, j + 1) - (j + 1);
    const Scalar* c2 = l + kernels::packed_col(n, j + 2) - (j + 2);
    const Scalar* c3 = l + kernels::packed_col(n, j + 3) - (j + 3);
    Scalar s0 = b[j], s1 = b[j + 1], s2 = b[j + 2], s3 = b[j + 3];
    for (int r = j + 4; r < n; ++r) {
      const Scalar y = b[r];
      s0 -= c0[r] * y;
      s1 -= c1[r] * y;
      s2 -= c2[r] * y;
      s3 -= c3[r] * y;
    }
    const Scalar i0 = Scalar(1) / c0[j], i1 = Scalar(1) / c1[j + 1];
    const Scalar i2 = Scalar(1) / c2[j + 2], i3 = Scalar(1) / c3[j + 3];
    const Scalar y3 = s3 * i3;
    const Scalar y2 = (s2 - c2[j + 3] * y3) * i2;
    const Scalar y1 = (s1 - c1[j + 2] * y2 - c1[j + 3] * y3) * i1;
    const Scalar y0 = (s0 - c0[j + 1] * y1 - c0[j + 2] * y2 - c0[j + 3] * y3) * i0;
    b[j] = y0;
    b[j + 1] = y1;
    b[j + 2] = y2;
    b[j + 3] = y3;
  }
}

/// Solves L' y = b in place, L lower of order n packed.
template <int n, typename Scalar>
void solve_lower_transposed_packed(const Scalar* l, Scalar* b) {
  solve_lower_transposed_head<n, n>(l, b);
}

/// One column step of a rank-one update (sigma = +1) or downdate (-1) of L L' by v v': column j
/// of the packed lower block ld (order n) and of the m rows below it, lo (may be null when m is
/// 0), with the parts v (n) and vo (m) of the vector. False when a downdate is unsafe:
/// r^2 <= tol L_jj^2 (tol = sqrt(eps): more than half the digits of the pivot would be lost).
template <int n, int m, typename Scalar>
bool rotate_packed_column(Scalar* ld, std::type_identity_t<Scalar>* lo, Scalar* v,
                          std::type_identity_t<Scalar>* vo, int j, Scalar sigma, Scalar tol) {
  const Scalar vj = v[j];
  if (vj == Scalar(0))
    return true;
  Scalar* cj = ld + kernels::packed_col(n, j) - j;  // cj[i] = L(i, j), i >= j
  const Scalar ljj = cj[j];
  const Scalar l2 = ljj * ljj;
  const Scalar r2 = l2 + sigma * vj * vj;
  if (!(r2 > tol * l2) || !std::isfinite(r2))
    return false;
  const Scalar r = std::sqrt(r2);
  const Scalar c = r / ljj, sn = vj / ljj, ic = ljj / r;
  cj[j] = r;
  v[j] = 0;
  for (int i = j + 1; i < n; ++i) {
    const Scalar li = (cj[i] + sigma * sn * v[i]) * ic;
    cj[i] = li;
    v[i] = c * v[i] - sn * li;
  }
  for (int i = 0; i < m; ++i) {
    const Scalar li = (lo[i] + sigma * sn * vo[i]) * ic;
    lo[i] = li;
    vo[i] = c * vo[i] - sn * li;
  }
  return true;
}

/// Packs the lower triangle of a (order n, column-major, leading dimension n) into l.
template <int n, typename Scalar>
void pack_lower(const Scalar* a, Scalar* l) {
  // one copy of compile-time length per column (unrolled, vectorised; a runtime-bounded loop
  // per column cost ~4 instructions per scalar)
  [&]<int... J>(std::integer_sequence<int, J...>) {
    ((Eigen::Map<Eigen::Matrix<Scalar, n - J, 1>>(l + kernels::packed_col(n, J)) =
          Eigen::Map<const Eigen::Matrix<Scalar, n - J, 1>>(a + J * (n + 1))),
     ...);
  }
  (std::make_integer_sequence<int, n>{});
}

}  // namespace arbor::qp::detail
