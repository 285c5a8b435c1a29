// arbor: 3x3 matrices whose structurally zero entries are known at compile time (SMat: nine
// scalars and a mask), and their products with constant 3x3 matrices (K M, M K^T) over the
// nonzero entries only: the articulated-inertia transport of a joint about a coordinate axis
// (ArticulatedOps::add_art_projection) costs what its nonzero entries cost, nothing more.
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/spatial/constant.hpp"

namespace arbor::spatial::detail {

/// A 3x3 matrix as nine scalars whose structurally zero entries are known at compile time: bit
/// 3 r + c of Nz clear means entry (r, c) is zero (never written, never read).
template <class S, unsigned Nz>
struct SMat {
  static constexpr unsigned nz = Nz;
  static constexpr bool at(int r, int c) { return (Nz >> (3 * r + c)) & 1u; }
  S e[3][3];
};
constexpr bool nz_bit(unsigned nz, int r, int c) {
  return (nz >> (3 * r + c)) & 1u;
}

/// Entry types for K M (left) and M K^T (right) over the nonzero entries of M only.
template <class K, unsigned Nz, int r, int c, int j>
struct LeftEntry {  // K(r, j) M(j, c)
  static constexpr double v = nz_bit(Nz, j, c) ? K::at(r, j) : 0.0;
};
template <class K, unsigned Nz, int r, int c, int j>
struct RightEntry {  // M(r, j) K(c, j)
  static constexpr double v = nz_bit(Nz, r, j) ? K::at(c, j) : 0.0;
};
template <class K>
constexpr unsigned left_nz(unsigned nz) {
  unsigned out = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j)
        if (K::at(r, j) != 0.0 && nz_bit(nz, j, c))
          out |= 1u << (3 * r + c);
  return out;
}
template <class K>
constexpr unsigned right_nz(unsigned nz) {
  unsigned out = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j)
        if (K::at(c, j) != 0.0 && nz_bit(nz, r, j))
          out |= 1u << (3 * r + c);
  return out;
}
/// The transpose of a mask, and a mask made symmetric.
constexpr unsigned transpose_nz(unsigned nz) {
  unsigned out = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (nz_bit(nz, c, r))
        out |= 1u << (3 * r + c);
  return out;
}

/// K M for a constant K; Sym: the result is known symmetric, entries r > c copied.
template <class K, bool Sym = false, class S, unsigned Nz>
ARBOR_INLINE SMat<S, left_nz<K>(Nz)> kl(const SMat<S, Nz>& M) {
  namespace c_ = cst;
  SMat<S, left_nz<K>(Nz)> out;
  static_for<9>([&](auto RC) {
    constexpr int r = decltype(RC)::value / 3, c = decltype(RC)::value % 3;
    if constexpr (nz_bit(left_nz<K>(Nz), r, c) && (!Sym || r <= c))
      out.e[r][c] =
          c_::dot3<S, LeftEntry<K, Nz, r, c, 0>, LeftEntry<K, Nz, r, c, 1>,
                   LeftEntry<K, Nz, r, c, 2>>(M.e[0][c], M.e[1][c], M.e[2][c], [] { return S(0); });
  });
  if constexpr (Sym)
    static_for<9>([&](auto RC) {
      constexpr int r = decltype(RC)::value / 3, c = decltype(RC)::value % 3;
      if constexpr (nz_bit(left_nz<K>(Nz), r, c) && r > c)
        out.e[r][c] = out.e[c][r];
    });
  return out;
}
/// M K^T for a constant K.
template <class K, class S, unsigned Nz>
ARBOR_INLINE SMat<S, right_nz<K>(Nz)> kr(const SMat<S, Nz>& M) {
  namespace c_ = cst;
  SMat<S, right_nz<K>(Nz)> out;
  static_for<9>([&](auto RC) {
    constexpr int r = decltype(RC)::value / 3, c = decltype(RC)::value % 3;
    if constexpr (nz_bit(right_nz<K>(Nz), r, c))
      out.e[r][c] = c_::dot3<S, RightEntry<K, Nz, r, c, 0>, RightEntry<K, Nz, r, c, 1>,
                             RightEntry<K, Nz, r, c, 2>>(M.e[r][0], M.e[r][1], M.e[r][2],
                                                         [] { return S(0); });
  });
  return out;
}

}  // namespace arbor::spatial::detail
