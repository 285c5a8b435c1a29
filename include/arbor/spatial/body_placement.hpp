// arbor: the placement of body i in its parent, liMi = Pl * J(q), applied in two steps: the
// constant step skips structurally zero entries of Pl (cst:: products, decided at compile time)
// and the joint step (JointMotion) touches only what the joint moves. Motions go to the child,
// forces to the parent, as the recursions need them, each written once on coordinate triples
// (spatial/coords.hpp: one 3-vector, or the rows of a block of columns). Cost per 3-vector for a
// revolute joint about a coordinate axis: the joint's 4 multiplications and 2 additions, one
// multiply-add per entry of Pl other than 0 and +-1 (an addition for +-1).
#pragma once

#include "arbor/spatial/joint_motion.hpp"
#include "arbor/spatial/se3.hpp"

namespace arbor::spatial {

/// Placement of body i of robot R in its parent body, and its actions on motions and forces.
template <class R, int i, class Scalar>
struct BodyPlacement : JointMotion<R, i, Scalar> {
  using Joint = JointMotion<R, i, Scalar>;
  using Joint::aligned;
  using Joint::ia;
  using Joint::ib;
  using Joint::jrot;
  using Joint::jtrans;
  using Joint::k;
  using Joint::revolute;
  using Joint::rotation_matrix;

  /// The constant joint placement Pl of body i.
  struct P {
    static constexpr const model::Placement& X = R::joint_placement[i];
  };
  using KR = cst::Rot<P>;
  using KRT = cst::Transpose<KR>;
  using Vp = cst::Trans<P>;
  using Kp = cst::Skew<Vp>;  ///< [p] of the joint placement
  static constexpr bool rot_identity = cst::is_identity<KR>();
  static constexpr bool p_zero = cst::is_zero_vec<Vp>();

  /// Pl.R * Rj with the constant entries of Pl.R (zero entries skipped).
  ARBOR_INLINE static Mat3<Scalar> const_rot_jrot(const JointState<Scalar>& js) {
    Mat3<Scalar> out = cst::rotation_value<Scalar, P>();
    if constexpr (revolute && aligned) {
      static_for<3>([&](auto RR) {
        constexpr int r = decltype(RR)::value;
        using Ea = cst::Entry<KR, r, ia>;
        using Eb = cst::Entry<KR, r, ib>;
        using Z = cst::ZeroEntry;
        auto z = [] { return Scalar(0); };
        out(r, ia) = cst::dot3<Scalar, Ea, Eb, Z>(js.c, js.s, Scalar(0), z);
        out(r, ib) = cst::dot3<Scalar, Eb, cst::Neg<Ea>, Z>(js.c, js.s, Scalar(0), z);
      });
    } else if constexpr (revolute) {
      out = out * rotation_matrix(js);
    }
    return out;
  }

  // ---- constant placement Pl -----------------------------------------------------------------
  template <class D>
  ARBOR_INLINE static Vec3<Scalar> R_(const Eigen::MatrixBase<D>& x) {
    return cst::mul<Scalar, KR>(x);
  }

  // ---- actions of liMi = Pl * J, on triples (spatial/coords.hpp) -----------------------------
  // Each output coordinate is one chain of multiply-adds over the constant entries of Pl
  // (cst::krow / add_krow skip zeros and +-1) and the joint's 2 x 2 mix (JointMotion::jrot_into).
  // The outputs must not alias the inputs.

  /// Motion (v, w) in the parent frame -> the same motion (vo, wo) in body i's frame (liMi^-1
  /// action): wo = Rj^T R^T w, vo = Rj^T R^T (v - p x w) (- d x wo for a prismatic joint).
  template <class X, class W, class Yv, class Yw>
  ARBOR_INLINE static void motion_to_child(const JointState<Scalar>& js, const X& v, const W& w,
                                           Yv&& vo, Yw&& wo) {
    using T = Coord<X>;
    const T w0 = w[0], w1 = w[1], w2 = w[2];
    T t0 = v[0], t1 = v[1], t2 = v[2];
    if constexpr (!p_zero) {  // t = v - p x w
      t0 = cst::add_krow<Scalar, Kp, 0, -1>(t0, w0, w1, w2);
      t1 = cst::add_krow<Scalar, Kp, 1, -1>(t1, w0, w1, w2);
      t2 = cst::add_krow<Scalar, Kp, 2, -1>(t2, w0, w1, w2);
    }
    Joint::template jrot_into<true>(js, cst::krow<Scalar, KRT, 0>(w0, w1, w2),
                                    cst::krow<Scalar, KRT, 1>(w0, w1, w2),
                                    cst::krow<Scalar, KRT, 2>(w0, w1, w2), wo);
    Joint::template jrot_into<true>(js, cst::krow<Scalar, KRT, 0>(t0, t1, t2),
                                    cst::krow<Scalar, KRT, 1>(t0, t1, t2),
                                    cst::krow<Scalar, KRT, 2>(t0, t1, t2), vo);
    if constexpr (!revolute)
      Joint::template add_dcross<-1>(js, wo, vo);
  }
  ARBOR_INLINE static Motion<Scalar> motion_to_child(const JointState<Scalar>& js,
                                                     const Motion<Scalar>& m) {
    Motion<Scalar> out;
    motion_to_child(js, m.v, m.w, out.v, out.w);
    return out;
  }
  /// Pure linear motion v (w = 0) in the parent frame -> its linear part vo in body i's frame.
  template <class X, class Y>
  ARBOR_INLINE static void linear_to_child(const JointState<Scalar>& js, const X& v, Y&& vo) {
    using T = Coord<X>;
    const T v0 = v[0], v1 = v[1], v2 = v[2];
    Joint::template jrot_into<true>(js, cst::krow<Scalar, KRT, 0>(v0, v1, v2),
                                    cst::krow<Scalar, KRT, 1>(v0, v1, v2),
                                    cst::krow<Scalar, KRT, 2>(v0, v1, v2), vo);
  }
  template <class D>
  ARBOR_INLINE static Vec3<Scalar> linear_to_child(const JointState<Scalar>& js,
                                                   const Eigen::MatrixBase<D>& v) {
    Vec3<Scalar> out;
    linear_to_child(js, v.derived(), out);
    return out;
  }
  /// Force (f, n) in body i's frame -> the same force in the parent frame (liMi action), written
  /// to (fo, no) (Accumulate: added to them): fo = R Rj f, no = R Rj n (+ R d x f for a prismatic
  /// joint) + p x fo.
  template <bool Accumulate, class F, class N, class Yf, class Yn>
  ARBOR_INLINE static void force_to_parent(const JointState<Scalar>& js, const F& f, const N& n,
                                           Yf&& fo, Yn&& no) {
    using T = Coord<F>;
    T f1[3], n1[3];
    Joint::template jrot_into<false>(js, T(f[0]), T(f[1]), T(f[2]), f1);
    Joint::template jrot_into<false>(js, T(n[0]), T(n[1]), T(n[2]), n1);
    if constexpr (!revolute)  // n + d x f
      Joint::template add_dcross<1>(js, f, n1);
    const T f2[3] = {cst::krow<Scalar, KR, 0>(f1[0], f1[1], f1[2]),
                     cst::krow<Scalar, KR, 1>(f1[0], f1[1], f1[2]),
                     cst::krow<Scalar, KR, 2>(f1[0], f1[1], f1[2])};
    for (int r = 0; r < 3; ++r)
      put<Accumulate>(fo[r], f2[r]);
    T n2[3] = {cst::krow<Scalar, KR, 0>(n1[0], n1[1], n1[2]),
               cst::krow<Scalar, KR, 1>(n1[0], n1[1], n1[2]),
               cst::krow<Scalar, KR, 2>(n1[0], n1[1], n1[2])};
    if constexpr (!p_zero) {  // + p x fo
      n2[0] = cst::add_krow<Scalar, Kp, 0, 1>(n2[0], f2[0], f2[1], f2[2]);
      n2[1] = cst::add_krow<Scalar, Kp, 1, 1>(n2[1], f2[0], f2[1], f2[2]);
      n2[2] = cst::add_krow<Scalar, Kp, 2, 1>(n2[2], f2[0], f2[1], f2[2]);
    }
    for (int r = 0; r < 3; ++r)
      put<Accumulate>(no[r], n2[r]);
  }
  ARBOR_INLINE static Force<Scalar> force_to_parent(const JointState<Scalar>& js,
                                                    const Force<Scalar>& f) {
    Force<Scalar> out;
    force_to_parent<false>(js, f.f, f.n, out.f, out.n);
    return out;
  }
  /// fp += the force f of body i carried to the parent frame.
  ARBOR_INLINE static void add_force_to_parent(const JointState<Scalar>& js, const Force<Scalar>& f,
                                               Force<Scalar>& fp) {
    force_to_parent<true>(js, f.f, f.n, fp.f, fp.n);
  }

  /// R M R^T for the constant rotation of Pl.
  ARBOR_INLINE static Mat3<Scalar> rot_const(const Mat3<Scalar>& M) {
    if constexpr (rot_identity) {
      return M;
    } else {
      const Mat3<Scalar> T = cst::mul_cols<Scalar, KRT, 3>(M);  // M R^T
      return cst::mul_rows<Scalar, KR, 3>(T);                   // R M R^T
    }
  }

  /// R M R^T for the constant rotation of Pl, M symmetric (result exactly symmetric).
  ARBOR_INLINE static Mat3<Scalar> rot_const_sym(const Mat3<Scalar>& M) {
    if constexpr (rot_identity) {
      return M;
    } else {
      Mat3<Scalar> out = rot_const(M);
      out(1, 0) = out(0, 1);
      out(2, 0) = out(0, 2);
      out(2, 1) = out(1, 2);
      return out;
    }
  }
};

}  // namespace arbor::spatial
