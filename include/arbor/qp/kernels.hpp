// arbor::qp::detail::kernels: small dense kernels with compile-time sizes for the OCP
// factorization (ocp_riccati_backend.hpp; packed_kernels.hpp holds the kernels on packed
// triangles). Plain loops over fixed sizes, written so that the compiler
// keeps a 4 x 4 block of the result in registers and vectorises over its rows without
// reassociating any sum (no -ffast-math needed); every function works for any size (the last
// row and column blocks are narrower, also fixed at compile time).
//
// Storage: column-major with a compile-time leading dimension. What they compute, in
// multiply-adds (n x n lower triangles, blocks of 4):
//   gemm_nt_block<R, C>   C_blk +-= P Q' for an R x C block, k terms           R C k
//   gemm_nt_lower<M, NC>  lower part of C(M x NC) +-= P Q', k terms           ~(M-NC/2) NC k
//   potrf_lower<n>        A = L L' in place (lower triangle), left-looking     ~n^3/6
//   trsm_rlt<m, n>        X <- X L^-T (X m x n, L lower n x n)                 ~m n^2/2
//   transpose<M, N>       B = A' (copy by 4 x 4 tiles)                         -
// The triangular solves by a 4 x 4 diagonal block (Cholesky panel, X L^-T) follow the block
// update, one pass over the rows per column. Diagonal blocks of the lower-triangle kernels are
// computed whole. Cost measured with GCC 12 -O3, SSE2 only (bench/qp/RESULTS.md): the 4 x 4 block
// loop takes ~2.3 instructions per multiply-add in double (per term: two row loads, four
// broadcasts, eight vector multiplies and adds, and the register copies of two-operand SSE); the
// whole stage factorization, with its panels, assembly and packing, ~3.1 (the column-axpy code it
// replaced: 3.8). Packed lower triangles (packed_col): column j holds rows j..n-1, n (n+1)/2
// scalars.
#pragma once

#include <cmath>

namespace arbor::qp::detail::kernels {

/// Block edge of the register-blocked kernels (columns of a block; rows where mb is not).
inline constexpr int nb = 4;
/// Rows of a block in the bulk of gemm_nt_cols: 8 with AVX (two 256-bit registers of double per
/// column: 8 accumulators of 16, fewer loads and broadcasts per multiply-add), nb otherwise (SSE2
/// has 16 registers of 2 doubles and the Cortex-M FPUs none: a 4 x 4 block fills them).
#if defined(__AVX__)
inline constexpr int mb = 2 * nb;
#else
inline constexpr int mb = nb;
#endif

/// Offset of column j in a packed lower triangle of order n (the position of entry (j, j)).
constexpr int packed_col(int n, int j) {
  return j * n - j * (j - 1) / 2;
}
/// Scalars of a packed lower triangle of order n.
constexpr int packed_size(int n) {
  return n * (n + 1) / 2;
}

/// What the register-blocked kernels do with c: c -= P Q', c += P Q', or c = P Q' (c not read).
enum class Update { subtract, add, assign };

/// c(r, j) (+ or -)= sum_{i<k} p(r, i) q(j, i) for r < R, j < C, with p(r, i) = p[r + i PI],
/// q(j, i) = q[j QC + i QI], c(r, j) = c[r + j LDC] (or = with Update::assign). The R x C sums are
/// accumulated in registers and added to c once.
template <int R, int C, int PI, int QI, int QC, int LDC, Update U, typename Scalar>
inline void gemm_nt_block(Scalar* c, const Scalar* p, const Scalar* q, int k) {
  Scalar acc[C][R];
  for (int j = 0; j < C; ++j)
    for (int r = 0; r < R; ++r)
      acc[j][r] = Scalar(0);
  for (int i = 0; i < k; ++i) {
    const Scalar* pi = p + i * PI;
    const Scalar* qi = q + i * QI;
    for (int j = 0; j < C; ++j) {
      const Scalar b = qi[j * QC];
      for (int r = 0; r < R; ++r)
        acc[j][r] += pi[r] * b;
    }
  }
  for (int j = 0; j < C; ++j) {
    for (int r = 0; r < R; ++r) {
      if constexpr (U == Update::assign)
        c[r + j * LDC] = acc[j][r];
      else if constexpr (U == Update::add)
        c[r + j * LDC] += acc[j][r];
      else
        c[r + j * LDC] -= acc[j][r];
    }
  }
}

/// b(j, i) = a(i, j) for i < M, j < N: a transposed copy (a and b column-major, leading
/// dimensions LDA and LDB), by 4 x 4 tiles of fixed size, which GCC unrolls (scalar loads, vector
/// stores): ~1.5 instructions per scalar with AVX2, against ~3.3 for a plain double loop or Eigen's
/// transposed assignment (bench/qp/RESULTS.md).
template <int M, int N, int LDA, int LDB, typename Scalar>
inline void transpose(const Scalar* a, Scalar* b) {
  constexpr int m4 = M - M % 4, n4 = N - N % 4;
  for (int i0 = 0; i0 < m4; i0 += 4) {
    for (int j0 = 0; j0 < n4; j0 += 4) {
      const Scalar* at = a + i0 + j0 * LDA;
      Scalar* bt = b + j0 + i0 * LDB;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          bt[j + i * LDB] = at[i + j * LDA];
    }
    for (int j = n4; j < N; ++j)
      for (int i = i0; i < i0 + 4; ++i)
        b[j + i * LDB] = a[i + j * LDA];
  }
  for (int i = m4; i < M; ++i)
    for (int j = 0; j < N; ++j)
      b[j + i * LDB] = a[i + j * LDA];
}

/// Columns j0..j0+C-1 of c, rows r0..M-1 (r0 a multiple of nb; blocks of mb rows, then of nb,
/// the last one M % nb): c(r, j) +-= sum_{i<k} p(r, i) q(j, i), with the strides of gemm_nt_block
/// and absolute indices (c, p and q point at entry (0, 0)). With r0 = j0 on a square c the entries
/// above the diagonal of the diagonal block are written too (scratch values).
template <int M, int C, int PI, int QI, int QC, int LDC, Update U, typename Scalar>
inline void gemm_nt_cols(Scalar* c, const Scalar* p, const Scalar* q, int j0, int r0, int k) {
  constexpr int tail = (M % nb);
  int r = r0;
  if constexpr (mb > nb) {
    for (; r + mb <= M; r += mb)
      gemm_nt_block<mb, C, PI, QI, QC, LDC, U>(c + r + j0 * LDC, p + r, q + j0 * QC, k);
  }
  for (; r + nb <= M; r += nb)
    gemm_nt_block<nb, C, PI, QI, QC, LDC, U>(c + r + j0 * LDC, p + r, q + j0 * QC, k);
  if constexpr (tail > 0) {
    if (r < M)
      gemm_nt_block<tail, C, PI, QI, QC, LDC, U>(c + r + j0 * LDC, p + r, q + j0 * QC, k);
  }
}

/// Lower part of the columns 0..NC-1 of c (rows j..M-1 of column j, M >= NC; the diagonal
/// blocks also above the diagonal): c(r, j) +-= sum_{i<k} p(r, i) q(j, i), strides as in
/// gemm_nt_block.
template <int M, int NC, int PI, int QI, int QC, int LDC, Update U, typename Scalar>
void gemm_nt_lower(Scalar* c, const Scalar* p, const Scalar* q, int k) {
  constexpr int tail = NC % nb;
  int j = 0;
  for (; j + nb <= NC; j += nb)
    gemm_nt_cols<M, nb, PI, QI, QC, LDC, U>(c, p, q, j, j, k);
  if constexpr (tail > 0)
    gemm_nt_cols<M, tail, PI, QI, QC, LDC, U>(c, p, q, j, j, k);
}

/// Column j0+c of the left-looking Cholesky after its update by the columns before j0: the
/// pivot, then one pass over the rows below it (the c earlier columns of the block and the
/// scaling applied together). False on a pivot that is not positive and finite.
template <int n, int c, typename Scalar>
inline bool potrf_panel_col(Scalar* a, int j0) {
  const int jc = j0 + c;
  Scalar* cj = a + jc * n;
  const Scalar* c0 = a + j0 * n;  // column j0 + i at c0 + i n
  Scalar s[c > 0 ? c : 1];
  Scalar pv = cj[jc];
  for (int i = 0; i < c; ++i) {
    s[i] = c0[i * n + jc];
    pv -= s[i] * s[i];
  }
  if (!(pv > Scalar(0)) || !std::isfinite(pv))
    return false;
  const Scalar l = std::sqrt(pv);
  cj[jc] = l;
  const Scalar inv = Scalar(1) / l;
  for (int r = jc + 1; r < n; ++r) {
    Scalar t = cj[r];
    for (int i = 0; i < c; ++i)
      t -= s[i] * c0[i * n + r];
    cj[r] = t * inv;
  }
  return true;
}

/// Factors the C x C diagonal block at (j0, j0) of the lower triangle a (order n, leading
/// dimension n, already updated by the columns before j0) and solves the rows below it:
/// a(r, j0+c) for r >= j0+C. False on a pivot that is not positive and finite.
template <int n, int C, typename Scalar>
inline bool potrf_panel(Scalar* a, int j0) {
  static_assert(C <= 4, "panel wider than the block edge");
  if (!potrf_panel_col<n, 0>(a, j0))
    return false;
  if constexpr (C > 1) {
    if (!potrf_panel_col<n, 1>(a, j0))
      return false;
  }
  if constexpr (C > 2) {
    if (!potrf_panel_col<n, 2>(a, j0))
      return false;
  }
  if constexpr (C > 3) {
    if (!potrf_panel_col<n, 3>(a, j0))
      return false;
  }
  return true;
}

/// Lower Cholesky A = L L' in place (column-major, leading dimension n; the lower triangle is
/// read and written, the upper one of each nb x nb diagonal block is overwritten with scratch
/// values). Left-looking by column blocks of nb: the block columns are updated by the ones
/// before them (gemm_nt_cols), then factored by potrf_panel. False on a pivot that is not
/// positive and finite.
template <int n, typename Scalar>
bool potrf_lower(Scalar* a) {
  constexpr int tail = n % nb;
  int j = 0;
  for (; j + nb <= n; j += nb) {
    gemm_nt_cols<n, nb, n, n, 1, n, Update::subtract>(a, a, a, j, j, j);
    if (!potrf_panel<n, nb>(a, j))
      return false;
  }
  if constexpr (tail > 0) {
    gemm_nt_cols<n, tail, n, n, 1, n, Update::subtract>(a, a, a, j, j, j);
    if (!potrf_panel<n, tail>(a, j))
      return false;
  }
  return true;
}

/// Column j0+c of X <- X L^-T after its update by the columns before j0: one pass over the rows
/// (the c earlier columns of the block and the scaling applied together).
template <int m, int n, int c, typename Scalar>
inline void trsm_panel_col(Scalar* x, const Scalar* l, int j0) {
  Scalar* xj = x + (j0 + c) * m;
  Scalar s[c > 0 ? c : 1];
  for (int i = 0; i < c; ++i)
    s[i] = l[(j0 + c) + (j0 + i) * n];
  const Scalar inv = Scalar(1) / l[(j0 + c) * (n + 1)];
  const Scalar* x0 = x + j0 * m;
  for (int r = 0; r < m; ++r) {
    Scalar t = xj[r];
    for (int i = 0; i < c; ++i)
      t -= s[i] * x0[i * m + r];
    xj[r] = t * inv;
  }
}

/// Columns j0..j0+C-1 of X <- X L^-T after their update by the columns before j0.
template <int m, int n, int C, typename Scalar>
inline void trsm_panel(Scalar* x, const Scalar* l, int j0) {
  static_assert(C <= 4, "panel wider than the block edge");
  trsm_panel_col<m, n, 0>(x, l, j0);
  if constexpr (C > 1)
    trsm_panel_col<m, n, 1>(x, l, j0);
  if constexpr (C > 2)
    trsm_panel_col<m, n, 2>(x, l, j0);
  if constexpr (C > 3)
    trsm_panel_col<m, n, 3>(x, l, j0);
}

/// X <- X L^-T: X m x n (leading dimension m), L lower n x n (leading dimension n, from
/// potrf_lower). Column blocks of nb: X(:, J) -= X(:, <J) L(J, <J)', then the nb x nb solve.
template <int m, int n, typename Scalar>
void trsm_rlt(Scalar* x, const Scalar* l) {
  constexpr int tail = n % nb;
  int j = 0;
  for (; j + nb <= n; j += nb) {
    gemm_nt_cols<m, nb, m, n, 1, m, Update::subtract>(x, x, l, j, 0, j);
    trsm_panel<m, n, nb>(x, l, j);
  }
  if constexpr (tail > 0) {
    gemm_nt_cols<m, tail, m, n, 1, m, Update::subtract>(x, x, l, j, 0, j);
    trsm_panel<m, n, tail>(x, l, j);
  }
}

}  // namespace arbor::qp::detail::kernels
