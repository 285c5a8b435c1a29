// arbor: the placement and subspace actions of body i on blocks of L columns at once (crba and
// M^-1 carry whole blocks of columns up and down the tree): each coordinate row of a 3 x L block
// is one Eigen row vector, so one sparse action transforms all L columns and vectorizes.
#pragma once

#include <array>

#include "arbor/spatial/articulated_ops.hpp"

namespace arbor::spatial {

/// Column-block actions of body i of robot R (the last link of the BodyOps chain).
template <class R, int i, class Scalar>
struct ColumnOps : ArticulatedOps<R, i, Scalar> {
  using Base = ArticulatedOps<R, i, Scalar>;
  using Base::aligned;
  using Base::ia;
  using Base::ib;
  using Base::k;
  using Base::p_zero;
  using Base::revolute;
  using Base::sign;
  using typename Base::AxisV;
  using typename Base::KR;
  using typename Base::KRT;
  using typename Base::Vp;

  // ---- the same actions on blocks of columns ------------------------------------------------
  // A "triple" holds the three coordinate rows (x, y, z) of a 3 x L block of column vectors,
  // each row an Eigen row vector T; one call transforms all L columns.
  template <class T>
  using Tri = std::array<T, 3>;

  /// K x for a constant 3x3 K on a triple.
  template <class K, class T>
  ARBOR_INLINE static Tri<T> kmul(const Tri<T>& x) {
    if constexpr (cst::is_identity<K>()) {
      return x;
    } else {
      auto z = [] { return T(T::Zero()); };
      return {cst::row<Scalar, K, 0>(x[0], x[1], x[2], z),
              cst::row<Scalar, K, 1>(x[0], x[1], x[2], z),
              cst::row<Scalar, K, 2>(x[0], x[1], x[2], z)};
    }
  }
  /// Rj x (or Rj^T x) on a triple.
  template <bool Transposed, class T>
  ARBOR_INLINE static Tri<T> jrot_t(const JointState<Scalar>& js, const Tri<T>& x) {
    if constexpr (!revolute) {
      return x;
    } else if constexpr (aligned) {
      Tri<T> y;
      y[k] = x[k];
      if constexpr (!Transposed) {
        y[ia] = x[ia] * js.c - x[ib] * js.s;
        y[ib] = x[ia] * js.s + x[ib] * js.c;
      } else {
        y[ia] = x[ia] * js.c + x[ib] * js.s;
        y[ib] = x[ib] * js.c - x[ia] * js.s;
      }
      return y;
    } else {
      const Tri<T> ax = kmul<cst::Skew<AxisV>>(x);
      const T adx =
          cst::dot3<Scalar, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
              x[0], x[1], x[2], [] { return T(T::Zero()); });
      const T t = adx * (Scalar(1) - js.c);
      const Scalar sg = Transposed ? Scalar(-js.s) : js.s;
      Tri<T> y;
      for (int j = 0; j < 3; ++j)
        y[j] = x[j] * js.c + ax[j] * sg + t * Scalar(AxisV::at(j));
      return y;
    }
  }
  /// d x x on a triple (prismatic translation d).
  template <class T>
  ARBOR_INLINE static Tri<T> dcross_t(const JointState<Scalar>& js, const Tri<T>& x) {
    if constexpr (aligned) {
      Tri<T> y;
      y[k] = T::Zero();
      y[ib] = x[ia] * js.d;
      y[ia] = -(x[ib] * js.d);
      return y;
    } else {
      Tri<T> y = kmul<cst::Skew<AxisV>>(x);
      for (int j = 0; j < 3; ++j)
        y[j] *= js.d;
      return y;
    }
  }
  /// motion_to_child on the columns of (v, w) triples, in place.
  template <class T>
  ARBOR_INLINE static void motion_to_child_t(const JointState<Scalar>& js, Tri<T>& v, Tri<T>& w) {
    Tri<T> t = v;
    if constexpr (!p_zero) {
      const Tri<T> pw = kmul<cst::Skew<Vp>>(w);
      for (int j = 0; j < 3; ++j)
        t[j] -= pw[j];
    }
    const Tri<T> w1 = kmul<KRT>(w);
    const Tri<T> v1 = kmul<KRT>(t);
    if constexpr (revolute) {
      v = jrot_t<true>(js, v1);
      w = jrot_t<true>(js, w1);
    } else {
      const Tri<T> dw = dcross_t(js, w1);
      for (int j = 0; j < 3; ++j)
        v[j] = v1[j] - dw[j];
      w = w1;
    }
  }
  /// force_to_parent on the columns of (f, n) triples, in place.
  template <class T>
  ARBOR_INLINE static void force_to_parent_t(const JointState<Scalar>& js, Tri<T>& f, Tri<T>& n) {
    Tri<T> f1, n1;
    if constexpr (revolute) {
      f1 = jrot_t<false>(js, f);
      n1 = jrot_t<false>(js, n);
    } else {
      f1 = f;
      n1 = n;
      const Tri<T> df = dcross_t(js, f);
      for (int j = 0; j < 3; ++j)
        n1[j] += df[j];
    }
    f = kmul<KR>(f1);
    n = kmul<KR>(n1);
    if constexpr (!p_zero) {
      const Tri<T> pf = kmul<cst::Skew<Vp>>(f);
      for (int j = 0; j < 3; ++j)
        n[j] += pf[j];
    }
  }
  /// S^T on the columns of (f, n) triples.
  template <class T>
  ARBOR_INLINE static T ST_t(const Tri<T>& f, const Tri<T>& n) {
    const Tri<T>& t = revolute ? n : f;
    if constexpr (aligned) {
      if constexpr (sign > 0)
        return t[k];
      else
        return T(-t[k]);
    } else {
      return cst::dot3<Scalar, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
          t[0], t[1], t[2], [] { return T(T::Zero()); });
    }
  }
  /// (v, w) += S x on the columns of triples (x one value per column).
  template <class T>
  ARBOR_INLINE static void add_S_t(Tri<T>& v, Tri<T>& w, const T& x) {
    Tri<T>& t = revolute ? w : v;
    if constexpr (aligned) {
      if constexpr (sign > 0)
        t[k] += x;
      else
        t[k] -= x;
    } else {
      for (int j = 0; j < 3; ++j)
        if (AxisV::at(j) != 0.0)
          t[j] += x * Scalar(AxisV::at(j));
    }
  }
};

}  // namespace arbor::spatial
