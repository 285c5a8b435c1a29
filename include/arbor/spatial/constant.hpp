// arbor: products with compile-time constant matrices and vectors, with structurally zero
// terms removed and +-1 factors turned into additions/subtractions by the templates themselves
// (`if constexpr` on the constexpr entries). Without -ffast-math a compiler may not fold x * 0.0
// for doubles, so this is where the generated robot data turns into fewer instructions.
// Cost: one multiplication per entry other than 0 and +-1, one addition per further nonzero
// term of a row; nothing at run time for the rest.
//
// A constant matrix is a type K with `static constexpr double at(int r, int c)`; a constant
// vector is a type V with `static constexpr double at(int i)`. One engine serves the 3x3
// products of the RBD code (dot3, row, mul, mul_rows, mul_cols, mat_cvec, cross) and the K x
// products of any size of the expression layer (row_n, ad/expr/constant_matrix.hpp): scaled and
// add_scaled decide what one term costs (for both), dot3 sums three terms and dot_n any number.
#pragma once

#include <type_traits>
#include <utility>

#include "arbor/core/config.hpp"
#include "arbor/model/types.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::spatial::cst {

/// One entry of a constant matrix, as a type (so it can drive if constexpr).
template <class K, int r, int c>
struct Entry {
  static constexpr double v = K::at(r, c);
};

/// Type-level constant from a constant vector entry.
template <class V, int i>
struct VEntry {
  static constexpr double v = V::at(i);
};

/// The constant zero, as an entry type.
struct ZeroEntry {
  static constexpr double v = 0.0;
};
/// The negated constant of an entry type.
template <class E>
struct Neg {
  static constexpr double v = -E::v;
};

/// x scaled by the constant E::v (x, -x or x * S(k)). S is the type the constant is converted to
/// for the product: the scalar itself (the RBD code), or a coefficient type whose product with x
/// is defined for it (the expression layer's detail::Coefficient: each component of a dual times
/// a plain number).
template <class S, class E, class T>
ARBOR_INLINE T scaled(const T& x) {
  if constexpr (E::v == 1.0)
    return x;
  else if constexpr (E::v == -1.0)
    return T(-x);
  else
    return T(x * S(E::v));
}

/// acc += E::v * x, nothing when E::v == 0.
template <class S, class E, class T>
ARBOR_INLINE void add_scaled(T& acc, const T& x) {
  if constexpr (E::v == 0.0) {
  } else if constexpr (E::v == 1.0) {
    acc += x;
  } else if constexpr (E::v == -1.0) {
    acc -= x;
  } else {
    acc += T(x * S(E::v));
  }
}

/// sum_k E_k::v * x_k over any number of terms (constants E, Es..., values x, xs...), starting
/// from the first nonzero term (no addition to 0); zero() when every constant is zero.
template <class S, class E, class... Es, class Z, class T, class... Xs>
ARBOR_INLINE T dot_n(Z zero, const T& x, const Xs&... xs) {
  static_assert(sizeof...(Es) == sizeof...(Xs), "dot_n: one constant per term");
  if constexpr (E::v != 0.0) {
    T acc = scaled<S, E>(x);
    (add_scaled<S, Es>(acc, xs), ...);
    return acc;
  } else if constexpr (sizeof...(Es) == 0) {
    return zero();
  } else {
    return dot_n<S, Es...>(zero, xs...);
  }
}

/// sum_k E_k::v * x_k over three terms; Zero when all constants are zero. The three-term case of
/// dot_n, written out: routing it through dot_n gives the same operations but changes GCC 12's
/// inlining decisions in the RBD algorithms (different object code), so it stays as tuned.
template <class S, class E0, class E1, class E2, class T, class Z>
ARBOR_INLINE T dot3(const T& x0, const T& x1, const T& x2, Z zero) {
  if constexpr (E0::v != 0.0) {
    T acc = scaled<S, E0>(x0);
    add_scaled<S, E1>(acc, x1);
    add_scaled<S, E2>(acc, x2);
    return acc;
  } else if constexpr (E1::v != 0.0) {
    T acc = scaled<S, E1>(x1);
    add_scaled<S, E2>(acc, x2);
    return acc;
  } else if constexpr (E2::v != 0.0) {
    return scaled<S, E2>(x2);
  } else {
    return zero();
  }
}

/// The zero of a coordinate type: a scalar zero, or a zero Eigen row vector (blocks of columns).
template <class T>
ARBOR_INLINE T zero_of() {
  if constexpr (std::is_base_of_v<Eigen::EigenBase<T>, T>)
    return T(T::Zero());
  else
    return T(0);
}

/// (row r of K) . (x0, x1, x2) for values of one coordinate type T (scalars or row vectors).
template <class S, class K, int r, class T>
ARBOR_INLINE T krow(const T& x0, const T& x1, const T& x2) {
  return dot3<S, Entry<K, r, 0>, Entry<K, r, 1>, Entry<K, r, 2>>(x0, x1, x2,
                                                                 [] { return zero_of<T>(); });
}

/// acc + (row r of K) . (x0, x1, x2) (Sign > 0) or acc - it (Sign < 0), term by term (zeros
/// skipped, +-1 as additions): no row sum is formed first.
template <class S, class K, int r, int Sign, class T>
ARBOR_INLINE T add_krow(T acc, const T& x0, const T& x1, const T& x2) {
  if constexpr (Sign > 0) {
    add_scaled<S, Entry<K, r, 0>>(acc, x0);
    add_scaled<S, Entry<K, r, 1>>(acc, x1);
    add_scaled<S, Entry<K, r, 2>>(acc, x2);
  } else {
    add_scaled<S, Neg<Entry<K, r, 0>>>(acc, x0);
    add_scaled<S, Neg<Entry<K, r, 1>>>(acc, x1);
    add_scaled<S, Neg<Entry<K, r, 2>>>(acc, x2);
  }
  return acc;
}

/// True when every entry of the constant matrix K is zero.
template <class K>
constexpr bool is_zero() {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (K::at(r, c) != 0.0)
        return false;
  return true;
}
/// True when the constant matrix K is the identity.
template <class K>
constexpr bool is_identity() {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (K::at(r, c) != (r == c ? 1.0 : 0.0))
        return false;
  return true;
}
/// True when every entry of the constant vector V is zero.
template <class V>
constexpr bool is_zero_vec() {
  return V::at(0) == 0.0 && V::at(1) == 0.0 && V::at(2) == 0.0;
}

/// Row r of K times the three values x0, x1, x2 (scalars or Eigen row vectors).
template <class S, class K, int r, class T, class Z>
ARBOR_INLINE T row(const T& x0, const T& x1, const T& x2, Z zero) {
  return dot3<S, Entry<K, r, 0>, Entry<K, r, 1>, Entry<K, r, 2>>(x0, x1, x2, zero);
}

/// Row r of a constant matrix K of any size times x[0], ..., x[C - 1] (x indexable by int;
/// C = sizeof...(c)): `row_n<S, K, r>(x, zero, std::make_integer_sequence<int, C>{})`.
template <class S, class K, int r, class X, class Z, int... c>
ARBOR_INLINE auto row_n(const X& x, Z zero, std::integer_sequence<int, c...>) {
  return dot_n<S, Entry<K, r, c>...>(zero, x[c]...);
}

/// K * x for a 3-vector x.
template <class S, class K, class D>
ARBOR_INLINE Vec3<S> mul(const Eigen::MatrixBase<D>& x) {
  if constexpr (is_identity<K>()) {
    return x;
  } else {
    const S x0 = x[0], x1 = x[1], x2 = x[2];
    auto z = [] { return S(0); };
    return Vec3<S>(row<S, K, 0>(x0, x1, x2, z), row<S, K, 1>(x0, x1, x2, z),
                   row<S, K, 2>(x0, x1, x2, z));
  }
}

/// K * M for a 3 x N matrix M (rows combined with constant coefficients).
template <class S, class K, int N>
ARBOR_INLINE Eigen::Matrix<S, 3, N> mul_rows(const Eigen::Matrix<S, 3, N>& M) {
  if constexpr (is_identity<K>()) {
    return M;
  } else {
    using RowT = Eigen::Matrix<S, 1, N>;
    const RowT r0 = M.row(0), r1 = M.row(1), r2 = M.row(2);
    auto z = [] { return RowT::Zero(); };
    Eigen::Matrix<S, 3, N> out;
    out.row(0) = row<S, K, 0>(r0, r1, r2, z);
    out.row(1) = row<S, K, 1>(r0, r1, r2, z);
    out.row(2) = row<S, K, 2>(r0, r1, r2, z);
    return out;
  }
}

/// Transpose of a constant matrix.
template <class K>
struct Transpose {
  static constexpr double at(int r, int c) { return K::at(c, r); }
};

/// M * K for an N x 3 matrix M (columns combined with constant coefficients).
template <class S, class K, int N>
ARBOR_INLINE Eigen::Matrix<S, N, 3> mul_cols(const Eigen::Matrix<S, N, 3>& M) {
  if constexpr (is_identity<K>()) {
    return M;
  } else {
    using ColT = Eigen::Matrix<S, N, 1>;
    using KT = Transpose<K>;
    const ColT c0 = M.col(0), c1 = M.col(1), c2 = M.col(2);
    auto z = [] { return ColT::Zero(); };
    Eigen::Matrix<S, N, 3> out;
    out.col(0) = row<S, KT, 0>(c0, c1, c2, z);
    out.col(1) = row<S, KT, 1>(c0, c1, c2, z);
    out.col(2) = row<S, KT, 2>(c0, c1, c2, z);
    return out;
  }
}

/// M * v for a runtime 3 x 3 matrix M and a constant vector V (columns of M combined).
template <class S, class V>
ARBOR_INLINE Vec3<S> mat_cvec(const Mat3<S>& M) {
  using ColT = Vec3<S>;
  const ColT c0 = M.col(0), c1 = M.col(1), c2 = M.col(2);
  return dot3<S, VEntry<V, 0>, VEntry<V, 1>, VEntry<V, 2>>(c0, c1, c2, [] { return ColT::Zero(); });
}

/// Skew matrix [V] of a constant vector V ([V] x = V cross x).
template <class V>
struct Skew {
  static constexpr double at(int r, int c) {
    // [[0, -v2, v1], [v2, 0, -v0], [-v1, v0, 0]]
    if (r == c)
      return 0.0;
    if (r == 0)
      return c == 1 ? -V::at(2) : V::at(1);
    if (r == 1)
      return c == 0 ? V::at(2) : -V::at(0);
    return c == 0 ? -V::at(1) : V::at(0);
  }
};

/// V cross x for a constant vector V.
template <class S, class V, class D>
ARBOR_INLINE Vec3<S> cross(const Eigen::MatrixBase<D>& x) {
  return mul<S, Skew<V>>(x);
}

/// The rotation of a constant placement P (P::X is a model::Placement).
template <class P>
struct Rot {
  static constexpr double at(int r, int c) { return P::X.R[r][c]; }
};
/// The translation of a constant placement P.
template <class P>
struct Trans {
  static constexpr double at(int i) { return P::X.p[i]; }
};

/// A constant vector from a model::Vec3-valued provider A (A::x).
template <class A>
struct Axis {
  static constexpr double at(int i) { return A::x[i]; }
};

/// Constant placement whose data is a given constexpr model::Placement object.
template <const model::Placement& X_>
struct PlacementRef {
  static constexpr const model::Placement& X = X_;
};

/// The runtime SE3 value of a constant placement, as Eigen objects of Scalar S.
template <class S, class P>
ARBOR_INLINE Mat3<S> rotation_value() {
  Mat3<S> R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      R(r, c) = S(P::X.R[r][c]);
  return R;
}
template <class S, class P>
ARBOR_INLINE Vec3<S> translation_value() {
  return Vec3<S>(S(P::X.p[0]), S(P::X.p[1]), S(P::X.p[2]));
}

}  // namespace arbor::spatial::cst
