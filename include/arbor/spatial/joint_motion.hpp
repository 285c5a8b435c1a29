// arbor: the joint of body i of a robot as compile-time facts and sparse operations: its state
// from q, the joint rotation Rj (or translation) applied to vectors and matrices, and the motion
// subspace S (S x, S^T f, m x S x). For a joint about a coordinate axis a rotation touches only
// the two coordinates it mixes and S selects one coordinate; unaligned axes use Rodrigues' form.
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/core/math.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/model/joint.hpp"
#include "arbor/spatial/constant.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/joint_state.hpp"
#include "arbor/spatial/motion.hpp"

namespace arbor::spatial {

/// Joint of body i of robot R: compile-time facts and the joint's own (placement-free) actions.
template <class R, int i, class Scalar>
struct JointMotion {
  static constexpr model::JointKind kind = R::joint_kind[i];
  static constexpr bool revolute = model::is_revolute(kind);
  static constexpr bool aligned = model::is_aligned(kind);
  static constexpr int k = aligned ? model::axis_index(kind) : 0;  ///< axis index
  static constexpr int ia = (k + 1) % 3;                           ///< first mixed coordinate
  static constexpr int ib = (k + 2) % 3;                           ///< second mixed coordinate
  static constexpr double sign = aligned ? R::joint_axis[i][k] : 1.0;
  static constexpr int parent = R::parent[i];

  /// The unit axis as a constant vector (unaligned kinds).
  struct AxisV {
    static constexpr double at(int j) { return R::joint_axis[i][j]; }
  };

  // ---- joint state ---------------------------------------------------------------------------
  /// Joint state from the configuration value.
  ARBOR_INLINE static JointState<Scalar> state(const Scalar& q) {
    JointState<Scalar> js;
    if constexpr (revolute) {
      Scalar sn, cs;
      arbor::sincos(q, sn, cs);
      js.c = cs;
      js.s = (sign < 0) ? Scalar(-sn) : sn;
      js.d = Scalar(0);
    } else {
      js.c = Scalar(1);
      js.s = Scalar(0);
      js.d = (sign < 0) ? Scalar(-q) : q;
    }
    return js;
  }

  // ---- joint rotation Rj (revolute) ----------------------------------------------------------
  /// Rj x (rotation by +q about the axis).
  template <bool Transposed = false>
  ARBOR_INLINE static Vec3<Scalar> jrot(const JointState<Scalar>& js, const Vec3<Scalar>& x) {
    if constexpr (!revolute) {
      return x;
    } else if constexpr (aligned) {
      Vec3<Scalar> y;
      y[k] = x[k];
      if constexpr (!Transposed) {
        y[ia] = js.c * x[ia] - js.s * x[ib];
        y[ib] = js.s * x[ia] + js.c * x[ib];
      } else {
        y[ia] = js.c * x[ia] + js.s * x[ib];
        y[ib] = js.c * x[ib] - js.s * x[ia];
      }
      return y;
    } else {
      // Rodrigues: Rx = c x + s (a x x) + (1 - c)(a . x) a
      const Vec3<Scalar> ax = cst::cross<Scalar, AxisV>(x);
      const Scalar adx =
          cst::dot3<Scalar, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
              x[0], x[1], x[2], [] { return Scalar(0); });
      const Vec3<Scalar> a(Scalar(AxisV::at(0)), Scalar(AxisV::at(1)), Scalar(AxisV::at(2)));
      const Scalar t = (Scalar(1) - js.c) * adx;
      if constexpr (!Transposed)
        return x * js.c + ax * js.s + a * t;
      else
        return x * js.c - ax * js.s + a * t;
    }
  }
  template <class D>
  ARBOR_INLINE static Vec3<Scalar> jrotT(const JointState<Scalar>& js,
                                         const Eigen::MatrixBase<D>& x) {
    return jrot<true>(js, x);
  }
  /// M Rj for a runtime 3x3 M (columns mixed).
  ARBOR_INLINE static Mat3<Scalar> mat_jrot(const JointState<Scalar>& js, const Mat3<Scalar>& M) {
    if constexpr (!revolute) {
      return M;
    } else if constexpr (aligned) {
      Mat3<Scalar> out;
      out.col(k) = M.col(k);
      out.col(ia) = M.col(ia) * js.c + M.col(ib) * js.s;
      out.col(ib) = M.col(ib) * js.c - M.col(ia) * js.s;
      return out;
    } else {
      return M * rotation_matrix(js);
    }
  }
  /// Rj as a dense matrix.
  static Mat3<Scalar> rotation_matrix(const JointState<Scalar>& js) {
    Mat3<Scalar> Rj;
    for (int c = 0; c < 3; ++c) {
      Vec3<Scalar> e = Vec3<Scalar>::Zero();
      e[c] = Scalar(1);
      Rj.col(c) = jrot(js, e);
    }
    return Rj;
  }
  /// Rj M Rj^T for a runtime 3x3 M.
  ARBOR_INLINE static Mat3<Scalar> rot_mat(const JointState<Scalar>& js, const Mat3<Scalar>& M) {
    if constexpr (!revolute) {
      return M;
    } else if constexpr (aligned) {
      // rows then columns: only ia, ib mix
      Mat3<Scalar> T;
      T.row(k) = M.row(k);
      T.row(ia) = M.row(ia) * js.c - M.row(ib) * js.s;
      T.row(ib) = M.row(ia) * js.s + M.row(ib) * js.c;
      Mat3<Scalar> out;
      out.col(k) = T.col(k);
      out.col(ia) = T.col(ia) * js.c - T.col(ib) * js.s;
      out.col(ib) = T.col(ia) * js.s + T.col(ib) * js.c;
      return out;
    } else {
      const Mat3<Scalar> Rj = rotation_matrix(js);
      return Rj * M * Rj.transpose();
    }
  }
  /// Translation of the joint (prismatic): d = q * axis.
  ARBOR_INLINE static Vec3<Scalar> jtrans(const JointState<Scalar>& js) {
    if constexpr (aligned) {
      Vec3<Scalar> d = Vec3<Scalar>::Zero();
      d[k] = js.d;
      return d;
    } else {
      return Vec3<Scalar>(Scalar(AxisV::at(0)), Scalar(AxisV::at(1)), Scalar(AxisV::at(2))) * js.d;
    }
  }
  /// d x x for the prismatic translation d.
  ARBOR_INLINE static Vec3<Scalar> dcross(const JointState<Scalar>& js, const Vec3<Scalar>& x) {
    if constexpr (aligned) {
      Vec3<Scalar> y;
      y[k] = Scalar(0);
      y[ib] = js.d * x[ia];
      y[ia] = -(js.d * x[ib]);
      return y;
    } else {
      return cst::cross<Scalar, AxisV>(x) * js.d;
    }
  }

  /// Rj M Rj^T for a runtime symmetric 3x3 M (only the mixed entries recomputed).
  ARBOR_INLINE static Mat3<Scalar> rot_sym(const JointState<Scalar>& js, const Mat3<Scalar>& M) {
    if constexpr (!revolute) {
      return M;
    } else if constexpr (aligned) {
      constexpr int a = ia, b = ib;
      const Scalar c = js.c, s = js.s;
      const Scalar cc = c * c, ss = s * s, cs = c * s;
      const Scalar maa = M(a, a), mbb = M(b, b), mab = M(a, b);
      const Scalar t = Scalar(2) * cs * mab;
      Mat3<Scalar> out;
      out(k, k) = M(k, k);
      out(a, k) = c * M(a, k) - s * M(b, k);
      out(b, k) = s * M(a, k) + c * M(b, k);
      out(k, a) = out(a, k);
      out(k, b) = out(b, k);
      out(a, a) = cc * maa + ss * mbb - t;
      out(b, b) = ss * maa + cc * mbb + t;
      out(a, b) = cs * (maa - mbb) + (cc - ss) * mab;
      out(b, a) = out(a, b);
      return out;
    } else {
      return rot_mat(js, M);
    }
  }

  // ---- motion subspace S -----------------------------------------------------------------------
  /// S * x as a motion.
  ARBOR_INLINE static Motion<Scalar> S_times(const Scalar& x) {
    Motion<Scalar> m = Motion<Scalar>::Zero();
    add_S(m, x);
    return m;
  }
  /// m += S * x.
  ARBOR_INLINE static void add_S(Motion<Scalar>& m, const Scalar& x) {
    if constexpr (aligned) {
      Vec3<Scalar>& t = revolute ? m.w : m.v;
      if constexpr (sign > 0)
        t[k] += x;
      else
        t[k] -= x;
    } else {
      Vec3<Scalar>& t = revolute ? m.w : m.v;
      static_for<3>([&](auto J) {
        constexpr int j = decltype(J)::value;
        if constexpr (AxisV::at(j) != 0.0)
          t[j] += Scalar(AxisV::at(j)) * x;
      });
    }
  }
  /// S^T f (the joint component of a force).
  ARBOR_INLINE static Scalar ST(const Force<Scalar>& f) {
    const Vec3<Scalar>& t = revolute ? f.n : f.f;
    if constexpr (aligned) {
      if constexpr (sign > 0)
        return t[k];
      else
        return Scalar(-t[k]);
    } else {
      return cst::dot3<Scalar, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
          t[0], t[1], t[2], [] { return Scalar(0); });
    }
  }
  /// m x (S x): the velocity-product term of the joint.
  ARBOR_INLINE static Motion<Scalar> cross_S(const Motion<Scalar>& m, const Scalar& x) {
    if constexpr (aligned) {
      // y x e_k = y_b e_a - y_a e_b (times sign * x)
      const Scalar sx = sign > 0 ? x : Scalar(-x);
      auto cross_e = [&](const Vec3<Scalar>& y) {
        Vec3<Scalar> r;
        r[k] = Scalar(0);
        r[ia] = y[ib] * sx;
        r[ib] = -(y[ia] * sx);
        return r;
      };
      if constexpr (revolute)
        return {cross_e(m.v), cross_e(m.w)};
      else
        return {cross_e(m.w), Vec3<Scalar>::Zero()};
    } else {
      return cross(m, S_times(x));
    }
  }
};

}  // namespace arbor::spatial
