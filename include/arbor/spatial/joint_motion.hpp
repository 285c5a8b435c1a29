// arbor: the joint of body i of a robot as compile-time facts and sparse operations: its state
// from q, the joint rotation Rj (or translation) applied to vectors and matrices, and the motion
// subspace S (S x, S^T f, m x S x), the vector actions on coordinate triples (spatial/coords.hpp:
// one 3-vector, or the rows of a block of columns). For a joint about a coordinate axis a
// rotation touches only the two coordinates it mixes (4 multiplications, 2 additions) and S
// selects one coordinate (no arithmetic); unaligned axes use Rodrigues' form.
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/core/math.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/model/joint.hpp"
#include "arbor/spatial/constant.hpp"
#include "arbor/spatial/coords.hpp"
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

  // ---- joint rotation Rj (revolute), on triples (spatial/coords.hpp) ------------------------
  /// y = Rj x (Transposed: Rj^T x) for the coordinates x0, x1, x2 of one type T (scalars or
  /// rows of a block); the identity for prismatic joints. y is written entry by entry and must
  /// not alias x. Aligned: 4 multiplications and 2 additions per vector; unaligned: Rodrigues,
  /// Rx = c x + s (a x x) + (1 - c)(a . x) a.
  template <bool Transposed, class T, class Y>
  ARBOR_INLINE static void jrot_into(const JointState<Scalar>& js, const T& x0, const T& x1,
                                     const T& x2, Y&& y) {
    const T* x[3] = {&x0, &x1, &x2};
    if constexpr (!revolute) {
      y[0] = x0;
      y[1] = x1;
      y[2] = x2;
    } else if constexpr (aligned) {
      y[k] = *x[k];
      if constexpr (!Transposed) {
        y[ia] = *x[ia] * js.c - *x[ib] * js.s;
        y[ib] = *x[ia] * js.s + *x[ib] * js.c;
      } else {
        y[ia] = *x[ia] * js.c + *x[ib] * js.s;
        y[ib] = *x[ib] * js.c - *x[ia] * js.s;
      }
    } else {
      using Ka = cst::Skew<AxisV>;
      const T t =
          cst::dot3<Scalar, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
              x0, x1, x2, [] { return cst::zero_of<T>(); }) *
          (Scalar(1) - js.c);
      const Scalar sg = Transposed ? Scalar(-js.s) : js.s;
      const T ax[3] = {cst::krow<Scalar, Ka, 0>(x0, x1, x2), cst::krow<Scalar, Ka, 1>(x0, x1, x2),
                       cst::krow<Scalar, Ka, 2>(x0, x1, x2)};
      static_for<3>([&](auto J) {
        constexpr int j = decltype(J)::value;
        T e = *x[j] * js.c + ax[j] * sg;
        cst::add_scaled<Scalar, cst::VEntry<AxisV, j>>(e, t);
        y[j] = e;
      });
    }
  }
  /// Rj x (Transposed: Rj^T x) for a 3-vector.
  template <bool Transposed = false, class D>
  ARBOR_INLINE static Vec3<Scalar> jrot(const JointState<Scalar>& js,
                                        const Eigen::MatrixBase<D>& x) {
    const Scalar x0 = x[0], x1 = x[1], x2 = x[2];
    Vec3<Scalar> y;
    jrot_into<Transposed>(js, x0, x1, x2, y);
    return y;
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
  /// y += d x x (Sign > 0) or y -= d x x (Sign < 0) for the prismatic translation d, on
  /// triples (y must not alias x).
  template <int Sign, class X, class Y>
  ARBOR_INLINE static void add_dcross(const JointState<Scalar>& js, const X& x, Y&& y) {
    using T = Coord<X>;
    if constexpr (aligned) {  // d x x = d (-x_b e_a + x_a e_b)
      if constexpr (Sign > 0) {
        y[ia] -= T(x[ib]) * js.d;
        y[ib] += T(x[ia]) * js.d;
      } else {
        y[ia] += T(x[ib]) * js.d;
        y[ib] -= T(x[ia]) * js.d;
      }
    } else {
      using Ka = cst::Skew<AxisV>;
      const T x0 = x[0], x1 = x[1], x2 = x[2];
      const T ax[3] = {cst::krow<Scalar, Ka, 0>(x0, x1, x2), cst::krow<Scalar, Ka, 1>(x0, x1, x2),
                       cst::krow<Scalar, Ka, 2>(x0, x1, x2)};
      for (int j = 0; j < 3; ++j) {
        if constexpr (Sign > 0)
          y[j] += ax[j] * js.d;
        else
          y[j] -= ax[j] * js.d;
      }
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

  // ---- motion subspace S, on triples -----------------------------------------------------------
  /// Which of the six entries (v then w) of m x (S x) can be nonzero (bit j: entry j): m x e_k
  /// has no k component; a prismatic joint's has no angular part.
  static constexpr unsigned cross_S_nz = !aligned   ? 0x3fu
                                         : revolute ? (0x3fu & ~((1u << k) | (1u << (3 + k))))
                                                    : (0x7u & ~(1u << k));

  /// The joint's sign applied to x (aligned kinds).
  template <class T>
  ARBOR_INLINE static T signed_(const T& x) {
    if constexpr (sign > 0)
      return x;
    else
      return T(-x);
  }
  /// (v, w) += S x, x one coordinate value (a scalar, or a row: one value per column).
  template <class V, class W, class T>
  ARBOR_INLINE static void add_S(V&& v, W&& w, const T& x) {
    auto&& t = [&]() -> auto&& {
      if constexpr (revolute)
        return w;
      else
        return v;
    }
    ();
    if constexpr (aligned) {
      if constexpr (sign > 0)
        t[k] += x;
      else
        t[k] -= x;
    } else {
      static_for<3>([&](auto J) {
        constexpr int j = decltype(J)::value;
        if constexpr (AxisV::at(j) != 0.0)
          t[j] += x * Scalar(AxisV::at(j));
      });
    }
  }
  /// m += S x.
  ARBOR_INLINE static void add_S(Motion<Scalar>& m, const Scalar& x) { add_S(m.v, m.w, x); }
  /// S x as a motion.
  ARBOR_INLINE static Motion<Scalar> S_times(const Scalar& x) {
    Motion<Scalar> m = Motion<Scalar>::Zero();
    add_S(m, x);
    return m;
  }
  /// S^T (f, n), the joint component of the force (or of each column of a block).
  template <class F, class N>
  ARBOR_INLINE static auto ST(const F& f, const N& n) {
    using T = Coord<F>;
    const auto& t = [&]() -> const auto& {
      if constexpr (revolute)
        return n;
      else
        return f;
    }
    ();
    if constexpr (aligned) {
      return signed_(T(t[k]));
    } else {
      const T t0 = t[0], t1 = t[1], t2 = t[2];
      return cst::dot3<Scalar, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
          t0, t1, t2, [] { return cst::zero_of<T>(); });
    }
  }
  ARBOR_INLINE static Scalar ST(const Force<Scalar>& f) { return ST(f.f, f.n); }
  /// a += m x (S x): the velocity-product term of the joint.
  ARBOR_INLINE static void add_cross_S(Motion<Scalar>& a, const Motion<Scalar>& m,
                                       const Scalar& x) {
    if constexpr (aligned) {  // y x e_k = y_b e_a - y_a e_b (times sign x)
      const Scalar sx = signed_(x);
      if constexpr (revolute) {
        a.v[ia] += m.v[ib] * sx;
        a.v[ib] -= m.v[ia] * sx;
        a.w[ia] += m.w[ib] * sx;
        a.w[ib] -= m.w[ia] * sx;
      } else {
        a.v[ia] += m.w[ib] * sx;
        a.v[ib] -= m.w[ia] * sx;
      }
    } else {
      a += cross(m, S_times(x));
    }
  }
  /// m x (S x).
  ARBOR_INLINE static Motion<Scalar> cross_S(const Motion<Scalar>& m, const Scalar& x) {
    Motion<Scalar> a = Motion<Scalar>::Zero();
    add_cross_S(a, m, x);
    return a;
  }
};

}  // namespace arbor::spatial
