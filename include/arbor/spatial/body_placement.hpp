// arbor: the placement of body i in its parent, liMi = Pl * J(q), applied in two steps: the
// constant step skips structurally zero entries of Pl (cst:: products, decided at compile time)
// and the joint step (JointMotion) touches only what the joint moves. Motions go to the child,
// forces to the parent, as the recursions need them.
#pragma once

#include "arbor/spatial/joint_motion.hpp"
#include "arbor/spatial/se3.hpp"

namespace arbor::spatial {

/// Placement of body i of robot R in its parent body, and its actions on motions and forces.
template <class R, int i, class Scalar>
struct BodyPlacement : JointMotion<R, i, Scalar> {
  using Joint = JointMotion<R, i, Scalar>;
  using Joint::aligned;
  using Joint::dcross;
  using Joint::ia;
  using Joint::ib;
  using Joint::jrot;
  using Joint::jrotT;
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
  template <class D>
  ARBOR_INLINE static Vec3<Scalar> RT_(const Eigen::MatrixBase<D>& x) {
    return cst::mul<Scalar, KRT>(x);
  }

  // ---- actions of liMi = Pl * J ----------------------------------------------------------------
  /// Motion in the parent frame -> the same motion in body i's frame (liMi^-1 action).
  ARBOR_INLINE static Motion<Scalar> motion_to_child(const JointState<Scalar>& js,
                                                     const Motion<Scalar>& m) {
    Vec3<Scalar> t = m.v;
    if constexpr (!p_zero)
      t -= cst::cross<Scalar, Vp>(m.w);
    const Vec3<Scalar> w1 = RT_(m.w);
    const Vec3<Scalar> v1 = RT_(t);
    if constexpr (revolute) {
      return {jrotT(js, v1), jrotT(js, w1)};
    } else {
      return {v1 - dcross(js, w1), w1};
    }
  }
  /// Pure linear motion (w = 0) in the parent frame -> linear part in body i's frame.
  ARBOR_INLINE static Vec3<Scalar> linear_to_child(const JointState<Scalar>& js,
                                                   const Vec3<Scalar>& v) {
    return jrotT(js, RT_(v));
  }
  /// Force in body i's frame -> the same force in the parent frame (liMi action).
  ARBOR_INLINE static Force<Scalar> force_to_parent(const JointState<Scalar>& js,
                                                    const Force<Scalar>& f) {
    Vec3<Scalar> f1, n1;
    if constexpr (revolute) {
      f1 = jrot(js, f.f);
      n1 = jrot(js, f.n);
    } else {
      f1 = f.f;
      n1 = f.n + dcross(js, f.f);
    }
    const Vec3<Scalar> f2 = R_(f1);
    Vec3<Scalar> n2 = R_(n1);
    if constexpr (!p_zero)
      n2 += cst::cross<Scalar, Vp>(f2);
    return {f2, n2};
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
