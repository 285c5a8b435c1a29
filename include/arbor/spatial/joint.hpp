// arbor: per-body spatial operations specialised at compile time on the robot data.
//
// The placement of body i in its parent is liMi = Pl * J(q): a constant placement Pl (the URDF
// joint origin, constexpr data) followed by the joint motion J(q) (a rotation about, or a
// translation along, the joint axis). Every action of liMi is applied in these two steps:
// the constant step skips structurally zero entries of Pl (cst:: products), and the joint step
// touches only the two coordinates a rotation about a coordinate axis mixes.
#pragma once

#include <array>

#include "arbor/core/config.hpp"
#include "arbor/core/math.hpp"
#include "arbor/model/joint.hpp"
#include "arbor/model/robot.hpp"
#include "arbor/spatial/constant.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/inertia.hpp"
#include "arbor/spatial/motion.hpp"
#include "arbor/spatial/se3.hpp"

namespace arbor::spatial {

/// Joint state of one body: the trigonometric values of its angle (revolute) or its signed
/// displacement (prismatic). For aligned kinds the axis sign is folded in: s = sign * sin(q),
/// d = sign * q, so the joint always turns/slides about/along +e_k.
template <class S>
struct JointState {
  S c;  ///< cos(q) (revolute)
  S s;  ///< sign * sin(q) (revolute; plain sin(q) for unaligned axes)
  S d;  ///< sign * q (prismatic; plain q for unaligned axes)
};

/// Articulated-body inertia (symmetric 6x6, [v; w] -> [f; n]) kept as its 3x3 blocks
/// [[A, B], [B^T, C]] with A and C symmetric.
template <class S>
struct ArticulatedInertia {
  Mat3<S> A;  ///< linear-linear block
  Mat3<S> B;  ///< linear-angular block
  Mat3<S> C;  ///< angular-angular block

  /// The full 6x6 matrix.
  Mat6<S> matrix() const {
    Mat6<S> M;
    M << A, B, B.transpose(), C;
    return M;
  }
  /// From a symmetric 6x6 matrix.
  template <class D>
  static ArticulatedInertia from(const Eigen::MatrixBase<D>& M) {
    return {M.template topLeftCorner<3, 3>(), M.template topRightCorner<3, 3>(),
            M.template bottomRightCorner<3, 3>()};
  }
  /// Y * m.
  Force<S> operator*(const Motion<S>& m) const {
    return {A * m.v + B * m.w, B.transpose() * m.v + C * m.w};
  }
  ArticulatedInertia& operator+=(const ArticulatedInertia& o) {
    A += o.A;
    B += o.B;
    C += o.C;
    return *this;
  }
  /// Y - U Dinv U^T for U = [uf; un].
  void rank1_update(const Vec3<S>& uf, const Vec3<S>& un, const S& Dinv) {
    const Vec3<S> gf = uf * Dinv, gn = un * Dinv;
    A.noalias() -= gf * uf.transpose();
    B.noalias() -= gf * un.transpose();
    C.noalias() -= gn * un.transpose();
  }
};

namespace detail {

/// Rigid inertia of a model::Inertia as (m, h = m c, Io about the frame origin), constexpr.
struct InertiaConst {
  double m;
  double h[3];
  double Io[3][3];
};
constexpr InertiaConst to_origin(const model::Inertia& Y) {
  InertiaConst r{};
  r.m = Y.mass;
  const double* c = Y.com;
  for (int k = 0; k < 3; ++k)
    r.h[k] = Y.mass * c[k];
  // Io = Ic - m [c]^2 = Ic + m (|c|^2 I - c c^T)
  const double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      r.Io[a][b] = Y.I[a][b] + Y.mass * ((a == b ? cc : 0.0) - c[a] * c[b]);
  return r;
}

}  // namespace detail

/// Compile-time facts and sparse spatial operations of body i of robot R, for scalar S.
template <class R, int i, class S>
struct BodyOps {
  static constexpr model::JointKind kind = R::joint_kind[i];
  static constexpr bool revolute = model::is_revolute(kind);
  static constexpr bool aligned = model::is_aligned(kind);
  static constexpr int k = aligned ? model::axis_index(kind) : 0;  ///< axis index
  static constexpr int ia = (k + 1) % 3;                           ///< first mixed coordinate
  static constexpr int ib = (k + 2) % 3;                           ///< second mixed coordinate
  static constexpr double sign = aligned ? R::joint_axis[i][k] : 1.0;
  static constexpr int parent = R::parent[i];

  /// The constant joint placement Pl of body i.
  struct P {
    static constexpr const model::Placement& X = R::joint_placement[i];
  };
  using KR = cst::Rot<P>;
  using KRT = cst::Transpose<KR>;
  using Vp = cst::Trans<P>;
  static constexpr bool rot_identity = cst::is_identity<KR>();
  static constexpr bool p_zero = cst::is_zero_vec<Vp>();

  /// The unit axis as a constant vector (unaligned kinds).
  struct AxisV {
    static constexpr double at(int j) { return R::joint_axis[i][j]; }
  };

  /// Constant inertia of the body in its frame.
  static constexpr detail::InertiaConst Y = detail::to_origin(R::body_inertia[i]);
  static constexpr bool massless = Y.m == 0.0;
  struct HV {
    static constexpr double at(int j) { return Y.h[j]; }
  };
  struct IoK {
    static constexpr double at(int r, int c) { return Y.Io[r][c]; }
  };
  static constexpr bool h_zero = cst::is_zero_vec<HV>();

  // ---- joint state ---------------------------------------------------------------------------
  /// Joint state from the configuration value.
  ARBOR_INLINE static JointState<S> state(const S& q) {
    JointState<S> js;
    if constexpr (revolute) {
      S sn, cs;
      arbor::sincos(q, sn, cs);
      js.c = cs;
      js.s = (sign < 0) ? S(-sn) : sn;
      js.d = S(0);
    } else {
      js.c = S(1);
      js.s = S(0);
      js.d = (sign < 0) ? S(-q) : q;
    }
    return js;
  }

  // ---- joint rotation Rj (revolute) ----------------------------------------------------------
  /// Rj x (rotation by +q about the axis).
  template <bool Transposed = false>
  ARBOR_INLINE static Vec3<S> jrot(const JointState<S>& js, const Vec3<S>& x) {
    if constexpr (!revolute) {
      return x;
    } else if constexpr (aligned) {
      Vec3<S> y;
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
      const Vec3<S> ax = cst::cross<S, AxisV>(x);
      const S adx =
          cst::dot3<S, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
              x[0], x[1], x[2], [] { return S(0); });
      const Vec3<S> a(S(AxisV::at(0)), S(AxisV::at(1)), S(AxisV::at(2)));
      const S t = (S(1) - js.c) * adx;
      if constexpr (!Transposed)
        return x * js.c + ax * js.s + a * t;
      else
        return x * js.c - ax * js.s + a * t;
    }
  }
  template <class D>
  ARBOR_INLINE static Vec3<S> jrotT(const JointState<S>& js, const Eigen::MatrixBase<D>& x) {
    return jrot<true>(js, x);
  }
  /// M Rj for a runtime 3x3 M (columns mixed).
  ARBOR_INLINE static Mat3<S> mat_jrot(const JointState<S>& js, const Mat3<S>& M) {
    if constexpr (!revolute) {
      return M;
    } else if constexpr (aligned) {
      Mat3<S> out;
      out.col(k) = M.col(k);
      out.col(ia) = M.col(ia) * js.c + M.col(ib) * js.s;
      out.col(ib) = M.col(ib) * js.c - M.col(ia) * js.s;
      return out;
    } else {
      return M * rotation_matrix(js);
    }
  }
  /// Pl.R * Rj with the constant entries of Pl.R (zero entries skipped).
  ARBOR_INLINE static Mat3<S> const_rot_jrot(const JointState<S>& js) {
    Mat3<S> out = cst::rotation_value<S, P>();
    if constexpr (revolute && aligned) {
      static_for_3([&](auto RR) {
        constexpr int r = decltype(RR)::value;
        using Ea = cst::Entry<KR, r, ia>;
        using Eb = cst::Entry<KR, r, ib>;
        using Z = cst::ZeroEntry;
        auto z = [] { return S(0); };
        out(r, ia) = cst::dot3<S, Ea, Eb, Z>(js.c, js.s, S(0), z);
        out(r, ib) = cst::dot3<S, Eb, cst::Neg<Ea>, Z>(js.c, js.s, S(0), z);
      });
    } else if constexpr (revolute) {
      out = out * rotation_matrix(js);
    }
    return out;
  }
  /// Rj as a dense matrix.
  static Mat3<S> rotation_matrix(const JointState<S>& js) {
    Mat3<S> Rj;
    for (int c = 0; c < 3; ++c) {
      Vec3<S> e = Vec3<S>::Zero();
      e[c] = S(1);
      Rj.col(c) = jrot(js, e);
    }
    return Rj;
  }
  /// Rj M Rj^T for a runtime 3x3 M.
  ARBOR_INLINE static Mat3<S> rot_mat(const JointState<S>& js, const Mat3<S>& M) {
    if constexpr (!revolute) {
      return M;
    } else if constexpr (aligned) {
      // rows then columns: only ia, ib mix
      Mat3<S> T;
      T.row(k) = M.row(k);
      T.row(ia) = M.row(ia) * js.c - M.row(ib) * js.s;
      T.row(ib) = M.row(ia) * js.s + M.row(ib) * js.c;
      Mat3<S> out;
      out.col(k) = T.col(k);
      out.col(ia) = T.col(ia) * js.c - T.col(ib) * js.s;
      out.col(ib) = T.col(ia) * js.s + T.col(ib) * js.c;
      return out;
    } else {
      const Mat3<S> Rj = rotation_matrix(js);
      return Rj * M * Rj.transpose();
    }
  }
  /// Translation of the joint (prismatic): d = q * axis.
  ARBOR_INLINE static Vec3<S> jtrans(const JointState<S>& js) {
    if constexpr (aligned) {
      Vec3<S> d = Vec3<S>::Zero();
      d[k] = js.d;
      return d;
    } else {
      return Vec3<S>(S(AxisV::at(0)), S(AxisV::at(1)), S(AxisV::at(2))) * js.d;
    }
  }
  /// d x x for the prismatic translation d.
  ARBOR_INLINE static Vec3<S> dcross(const JointState<S>& js, const Vec3<S>& x) {
    if constexpr (aligned) {
      Vec3<S> y;
      y[k] = S(0);
      y[ib] = js.d * x[ia];
      y[ia] = -(js.d * x[ib]);
      return y;
    } else {
      return cst::cross<S, AxisV>(x) * js.d;
    }
  }

  // ---- constant placement Pl -----------------------------------------------------------------
  template <class D>
  ARBOR_INLINE static Vec3<S> R_(const Eigen::MatrixBase<D>& x) {
    return cst::mul<S, KR>(x);
  }
  template <class D>
  ARBOR_INLINE static Vec3<S> RT_(const Eigen::MatrixBase<D>& x) {
    return cst::mul<S, KRT>(x);
  }

  // ---- actions of liMi = Pl * J ----------------------------------------------------------------
  /// Motion in the parent frame -> the same motion in body i's frame (liMi^-1 action).
  ARBOR_INLINE static Motion<S> motion_to_child(const JointState<S>& js, const Motion<S>& m) {
    Vec3<S> t = m.v;
    if constexpr (!p_zero)
      t -= cst::cross<S, Vp>(m.w);
    const Vec3<S> w1 = RT_(m.w);
    const Vec3<S> v1 = RT_(t);
    if constexpr (revolute) {
      return {jrotT(js, v1), jrotT(js, w1)};
    } else {
      return {v1 - dcross(js, w1), w1};
    }
  }
  /// Pure linear motion (w = 0) in the parent frame -> linear part in body i's frame.
  ARBOR_INLINE static Vec3<S> linear_to_child(const JointState<S>& js, const Vec3<S>& v) {
    return jrotT(js, RT_(v));
  }
  /// Motion in body i's frame -> the same motion in the parent frame (liMi action).
  ARBOR_INLINE static Motion<S> motion_to_parent(const JointState<S>& js, const Motion<S>& m) {
    Vec3<S> w1, v1;
    if constexpr (revolute) {
      w1 = jrot(js, m.w);
      v1 = jrot(js, m.v);
    } else {
      w1 = m.w;
      v1 = m.v + dcross(js, m.w);
    }
    const Vec3<S> w2 = R_(w1);
    Vec3<S> v2 = R_(v1);
    if constexpr (!p_zero)
      v2 += cst::cross<S, Vp>(w2);
    return {v2, w2};
  }
  /// Force in body i's frame -> the same force in the parent frame (liMi action).
  ARBOR_INLINE static Force<S> force_to_parent(const JointState<S>& js, const Force<S>& f) {
    Vec3<S> f1, n1;
    if constexpr (revolute) {
      f1 = jrot(js, f.f);
      n1 = jrot(js, f.n);
    } else {
      f1 = f.f;
      n1 = f.n + dcross(js, f.f);
    }
    const Vec3<S> f2 = R_(f1);
    Vec3<S> n2 = R_(n1);
    if constexpr (!p_zero)
      n2 += cst::cross<S, Vp>(f2);
    return {f2, n2};
  }

  /// Rigid inertia in body i's frame -> the same inertia in the parent frame.
  ARBOR_INLINE static Inertia<S> inertia_to_parent(const JointState<S>& js, const Inertia<S>& Yc) {
    Vec3<S> h1;
    Mat3<S> I1;
    if constexpr (revolute) {
      h1 = jrot(js, Yc.h);
      I1 = rot_mat(js, Yc.Io);
    } else {
      const Vec3<S> d = jtrans(js);
      const Mat3<S> Pd = skew(d);
      const Mat3<S> Hd = skew(Yc.h);
      h1 = Yc.h + d * Yc.m;
      I1 = Yc.Io - (Hd * Pd + Pd * Hd) - Yc.m * (Pd * Pd);
    }
    Inertia<S> out;
    out.m = Yc.m;
    Vec3<S> hr = R_(h1);
    Mat3<S> Ir = rot_const(I1);
    if constexpr (!p_zero) {
      // Io' = R Io R^T - ([hr][p] + [p][hr] + m [p]^2)
      //     = R Io R^T - (p hr^T + hr p^T - 2 (hr . p) I + m (p p^T - |p|^2 I))
      const S hp = cst::dot3<S, cst::VEntry<Vp, 0>, cst::VEntry<Vp, 1>, cst::VEntry<Vp, 2>>(
          hr[0], hr[1], hr[2], [] { return S(0); });
      constexpr double pp = Vp::at(0) * Vp::at(0) + Vp::at(1) * Vp::at(1) + Vp::at(2) * Vp::at(2);
      const S diag = S(2) * hp + Yc.m * S(pp);
      static_for_3x3([&](auto RR, auto CC) {
        constexpr int r = decltype(RR)::value, c = decltype(CC)::value;
        constexpr double pr = Vp::at(r), pc = Vp::at(c);
        if constexpr (pr != 0.0)
          Ir(r, c) -= S(pr) * hr[c];
        if constexpr (pc != 0.0)
          Ir(r, c) -= hr[r] * S(pc);
        if constexpr (pr * pc != 0.0)
          Ir(r, c) -= Yc.m * S(pr * pc);
        if constexpr (r == c)
          Ir(r, c) += diag;
      });
      hr += cst::translation_value<S, P>() * Yc.m;
    }
    out.h = hr;
    out.Io = Ir;
    return out;
  }

  /// R M R^T for the constant rotation of Pl.
  ARBOR_INLINE static Mat3<S> rot_const(const Mat3<S>& M) {
    if constexpr (rot_identity) {
      return M;
    } else {
      const Mat3<S> T = cst::mul_cols<S, KRT, 3>(M);  // M R^T
      return cst::mul_rows<S, KR, 3>(T);              // R M R^T
    }
  }
  /// Articulated (6x6, [v; w] -> [f; n]) inertia in body i's frame -> parent frame.
  ARBOR_INLINE static Mat6<S> ainertia_to_parent(const JointState<S>& js, const Mat6<S>& Yc) {
    Mat3<S> A = Yc.template topLeftCorner<3, 3>();
    Mat3<S> B = Yc.template topRightCorner<3, 3>();
    Mat3<S> C = Yc.template bottomRightCorner<3, 3>();
    if constexpr (revolute) {
      A = rot_mat(js, A);
      B = rot_mat(js, B);
      C = rot_mat(js, C);
    } else {
      const Mat3<S> Pd = skew(jtrans(js));
      const Mat3<S> AP = A * Pd;
      const Mat3<S> PB = Pd * B;
      B = B - AP;
      C = C + PB + PB.transpose() - Pd * AP;
    }
    A = rot_const(A);
    B = rot_const(B);
    C = rot_const(C);
    if constexpr (!p_zero) {
      using Kp = cst::Skew<Vp>;
      const Mat3<S> AP = cst::mul_cols<S, Kp, 3>(A);  // A [p]
      const Mat3<S> PB = cst::mul_rows<S, Kp, 3>(B);  // [p] B
      const Mat3<S> PAP = cst::mul_rows<S, Kp, 3>(AP);
      B -= AP;
      C += PB + PB.transpose() - PAP;
    }
    Mat6<S> out;
    out.template topLeftCorner<3, 3>() = A;
    out.template topRightCorner<3, 3>() = B;
    out.template bottomLeftCorner<3, 3>() = B.transpose();
    out.template bottomRightCorner<3, 3>() = C;
    return out;
  }

  /// Rj M Rj^T for a runtime symmetric 3x3 M (only the mixed entries recomputed).
  ARBOR_INLINE static Mat3<S> rot_sym(const JointState<S>& js, const Mat3<S>& M) {
    if constexpr (!revolute) {
      return M;
    } else if constexpr (aligned) {
      constexpr int a = ia, b = ib;
      const S c = js.c, s = js.s;
      const S cc = c * c, ss = s * s, cs = c * s;
      const S maa = M(a, a), mbb = M(b, b), mab = M(a, b);
      const S t = S(2) * cs * mab;
      Mat3<S> out;
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
  /// R M R^T for the constant rotation of Pl, M symmetric (result exactly symmetric).
  ARBOR_INLINE static Mat3<S> rot_const_sym(const Mat3<S>& M) {
    if constexpr (rot_identity) {
      return M;
    } else {
      Mat3<S> out = rot_const(M);
      out(1, 0) = out(0, 1);
      out(2, 0) = out(0, 2);
      out(2, 1) = out(1, 2);
      return out;
    }
  }

  /// The constant body inertia as an articulated inertia.
  ARBOR_INLINE static ArticulatedInertia<S> art_inertia() {
    ArticulatedInertia<S> Ya;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        Ya.A(r, c) = r == c ? S(Y.m) : S(0);
        Ya.C(r, c) = S(Y.Io[r][c]);
      }
    // B = -[h]
    Ya.B(0, 0) = S(0);
    Ya.B(1, 1) = S(0);
    Ya.B(2, 2) = S(0);
    Ya.B(0, 1) = S(Y.h[2]);
    Ya.B(0, 2) = S(-Y.h[1]);
    Ya.B(1, 0) = S(-Y.h[2]);
    Ya.B(1, 2) = S(Y.h[0]);
    Ya.B(2, 0) = S(Y.h[1]);
    Ya.B(2, 1) = S(-Y.h[0]);
    return Ya;
  }
  /// U = Ya S as [uf; un].
  ARBOR_INLINE static void art_S(const ArticulatedInertia<S>& Ya, Vec3<S>& uf, Vec3<S>& un) {
    if constexpr (aligned) {
      if constexpr (revolute) {
        uf = Ya.B.col(k);
        un = Ya.C.col(k);
      } else {
        uf = Ya.A.col(k);
        un = Ya.B.row(k).transpose();
      }
      if constexpr (sign < 0) {
        uf = -uf;
        un = -un;
      }
    } else {
      const Vec3<S> a(S(AxisV::at(0)), S(AxisV::at(1)), S(AxisV::at(2)));
      if constexpr (revolute) {
        uf = Ya.B * a;
        un = Ya.C * a;
      } else {
        uf = Ya.A * a;
        un = Ya.B.transpose() * a;
      }
    }
  }
  /// Articulated inertia in body i's frame -> parent frame.
  ARBOR_INLINE static ArticulatedInertia<S> art_to_parent(const JointState<S>& js,
                                                          const ArticulatedInertia<S>& Yc) {
    Mat3<S> A, B, C;
    if constexpr (revolute) {
      A = rot_sym(js, Yc.A);
      B = rot_mat(js, Yc.B);
      C = rot_sym(js, Yc.C);
    } else {
      const Mat3<S> Pd = skew(jtrans(js));
      const Mat3<S> AP = Yc.A * Pd;
      const Mat3<S> PB = Pd * Yc.B;
      A = Yc.A;
      B = Yc.B - AP;
      C = Yc.C + PB + PB.transpose() - Pd * AP;
    }
    return const_placement_art({A, B, C});
  }

  /// Projected articulated inertia Y - U Dinv U^T (U = Y S), the part of body i's articulated
  /// inertia that its parent sees, expressed in the parent frame. For aligned revolute joints
  /// the projection has an exactly zero row and column for the joint axis (Y_a S = 0), which is
  /// set structurally and skipped by the joint rotation.
  ARBOR_INLINE static ArticulatedInertia<S> art_project_to_parent(const JointState<S>& js,
                                                                  const ArticulatedInertia<S>& Yi,
                                                                  const Force<S>& U,
                                                                  const S& Dinv) {
    if constexpr (revolute && aligned) {
      constexpr int a = ia, b = ib;
      const Vec3<S> gf = U.f * Dinv;
      const S gna = U.n[a] * Dinv, gnb = U.n[b] * Dinv;
      // rank-one update, skipping the zero row/column k of C and column k of B
      Mat3<S> A;
      for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c)
          A(r, c) = Yi.A(r, c) - gf[r] * U.f[c];
      A(1, 0) = A(0, 1);
      A(2, 0) = A(0, 2);
      A(2, 1) = A(1, 2);
      Vec3<S> Ba, Bb;
      for (int r = 0; r < 3; ++r) {
        Ba[r] = Yi.B(r, a) - gf[r] * U.n[a];
        Bb[r] = Yi.B(r, b) - gf[r] * U.n[b];
      }
      const S Caa = Yi.C(a, a) - gna * U.n[a];
      const S Cab = Yi.C(a, b) - gna * U.n[b];
      const S Cbb = Yi.C(b, b) - gnb * U.n[b];
      // joint rotation Rj (.) Rj^T
      const S c = js.c, sn = js.s;
      A = rot_sym(js, A);
      // B Rj^T: columns a, b mixed; then Rj on the left: rows a, b mixed
      const Vec3<S> Ta = Ba * c - Bb * sn;
      const Vec3<S> Tb = Ba * sn + Bb * c;
      Mat3<S> B;
      B.col(k).setZero();
      B(k, a) = Ta[k];
      B(k, b) = Tb[k];
      B(a, a) = c * Ta[a] - sn * Ta[b];
      B(b, a) = sn * Ta[a] + c * Ta[b];
      B(a, b) = c * Tb[a] - sn * Tb[b];
      B(b, b) = sn * Tb[a] + c * Tb[b];
      const S cc = c * c, ss = sn * sn, cs = c * sn;
      const S t = S(2) * cs * Cab;
      Mat3<S> C;
      C.row(k).setZero();
      C.col(k).setZero();
      C(a, a) = cc * Caa + ss * Cbb - t;
      C(b, b) = ss * Caa + cc * Cbb + t;
      C(a, b) = cs * (Caa - Cbb) + (cc - ss) * Cab;
      C(b, a) = C(a, b);
      return const_placement_art({A, B, C});
    } else {
      ArticulatedInertia<S> Ya = Yi;
      Ya.rank1_update(U.f, U.n, Dinv);
      return art_to_parent(js, Ya);
    }
  }
  /// The constant placement Pl applied to an articulated inertia (rotation, then translation).
  ARBOR_INLINE static ArticulatedInertia<S> const_placement_art(const ArticulatedInertia<S>& Yi) {
    Mat3<S> A = rot_const_sym(Yi.A);
    Mat3<S> B = rot_const(Yi.B);
    Mat3<S> C = rot_const_sym(Yi.C);
    if constexpr (!p_zero) {
      using Kp = cst::Skew<Vp>;
      const Mat3<S> AP = cst::mul_cols<S, Kp, 3>(A);  // A [p]
      const Mat3<S> PB = cst::mul_rows<S, Kp, 3>(B);  // [p] B
      const Mat3<S> PAP = cst::mul_rows<S, Kp, 3>(AP);
      B -= AP;
      C += PB + PB.transpose() - PAP;
    }
    return {A, B, C};
  }

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
      return {cst::row<S, K, 0>(x[0], x[1], x[2], z), cst::row<S, K, 1>(x[0], x[1], x[2], z),
              cst::row<S, K, 2>(x[0], x[1], x[2], z)};
    }
  }
  /// Rj x (or Rj^T x) on a triple.
  template <bool Transposed, class T>
  ARBOR_INLINE static Tri<T> jrot_t(const JointState<S>& js, const Tri<T>& x) {
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
          cst::dot3<S, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
              x[0], x[1], x[2], [] { return T(T::Zero()); });
      const T t = adx * (S(1) - js.c);
      const S sg = Transposed ? S(-js.s) : js.s;
      Tri<T> y;
      for (int j = 0; j < 3; ++j)
        y[j] = x[j] * js.c + ax[j] * sg + t * S(AxisV::at(j));
      return y;
    }
  }
  /// d x x on a triple (prismatic translation d).
  template <class T>
  ARBOR_INLINE static Tri<T> dcross_t(const JointState<S>& js, const Tri<T>& x) {
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
  ARBOR_INLINE static void motion_to_child_t(const JointState<S>& js, Tri<T>& v, Tri<T>& w) {
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
  ARBOR_INLINE static void force_to_parent_t(const JointState<S>& js, Tri<T>& f, Tri<T>& n) {
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
      return cst::dot3<S, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
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
          t[j] += x * S(AxisV::at(j));
    }
  }

  // ---- motion subspace S -----------------------------------------------------------------------
  /// S * x as a motion.
  ARBOR_INLINE static Motion<S> S_times(const S& x) {
    Motion<S> m = Motion<S>::Zero();
    add_S(m, x);
    return m;
  }
  /// m += S * x.
  ARBOR_INLINE static void add_S(Motion<S>& m, const S& x) {
    if constexpr (aligned) {
      Vec3<S>& t = revolute ? m.w : m.v;
      if constexpr (sign > 0)
        t[k] += x;
      else
        t[k] -= x;
    } else {
      Vec3<S>& t = revolute ? m.w : m.v;
      static_for_3([&](auto J) {
        constexpr int j = decltype(J)::value;
        if constexpr (AxisV::at(j) != 0.0)
          t[j] += S(AxisV::at(j)) * x;
      });
    }
  }
  /// S^T f (the joint component of a force).
  ARBOR_INLINE static S ST(const Force<S>& f) {
    const Vec3<S>& t = revolute ? f.n : f.f;
    if constexpr (aligned) {
      if constexpr (sign > 0)
        return t[k];
      else
        return S(-t[k]);
    } else {
      return cst::dot3<S, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
          t[0], t[1], t[2], [] { return S(0); });
    }
  }
  /// S^T on a 6-vector in [f; n] or [v; w] layout.
  template <class D>
  ARBOR_INLINE static S ST6(const Eigen::MatrixBase<D>& x) {
    constexpr int off = revolute ? 3 : 0;
    if constexpr (aligned) {
      if constexpr (sign > 0)
        return x[off + k];
      else
        return S(-x[off + k]);
    } else {
      return cst::dot3<S, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
          S(x[off]), S(x[off + 1]), S(x[off + 2]), [] { return S(0); });
    }
  }
  /// Y S for a 6x6 matrix Y (one column when aligned).
  ARBOR_INLINE static Vec6<S> mat_S(const Mat6<S>& Y) {
    constexpr int off = revolute ? 3 : 0;
    if constexpr (aligned) {
      if constexpr (sign > 0)
        return Y.col(off + k);
      else
        return -Y.col(off + k);
    } else {
      using C6 = Vec6<S>;
      const C6 c0 = Y.col(off), c1 = Y.col(off + 1), c2 = Y.col(off + 2);
      return cst::dot3<S, cst::VEntry<AxisV, 0>, cst::VEntry<AxisV, 1>, cst::VEntry<AxisV, 2>>(
          c0, c1, c2, [] { return C6::Zero(); });
    }
  }
  /// m x (S x): the velocity-product term of the joint.
  ARBOR_INLINE static Motion<S> cross_S(const Motion<S>& m, const S& x) {
    if constexpr (aligned) {
      // y x e_k = y_b e_a - y_a e_b (times sign * x)
      const S sx = sign > 0 ? x : S(-x);
      auto cross_e = [&](const Vec3<S>& y) {
        Vec3<S> r;
        r[k] = S(0);
        r[ia] = y[ib] * sx;
        r[ib] = -(y[ia] * sx);
        return r;
      };
      if constexpr (revolute)
        return {cross_e(m.v), cross_e(m.w)};
      else
        return {cross_e(m.w), Vec3<S>::Zero()};
    } else {
      return cross(m, S_times(x));
    }
  }

  // ---- body inertia (constant) -----------------------------------------------------------------
  /// I_i * m with the constant body inertia (zero com and zero inertia entries skipped).
  ARBOR_INLINE static Force<S> inertia_times(const Motion<S>& x) {
    if constexpr (massless) {
      return Force<S>::Zero();
    } else {
      Vec3<S> f = x.v * S(Y.m);
      Vec3<S> n = cst::mul<S, IoK>(x.w);
      if constexpr (!h_zero) {
        f -= cst::cross<S, HV>(x.w);
        n += cst::cross<S, HV>(x.v);
      }
      return {f, n};
    }
  }
  /// The constant body inertia as a runtime Inertia<S>.
  static Inertia<S> inertia() {
    Inertia<S> I;
    I.m = S(Y.m);
    for (int r = 0; r < 3; ++r) {
      I.h[r] = S(Y.h[r]);
      for (int c = 0; c < 3; ++c)
        I.Io(r, c) = S(Y.Io[r][c]);
    }
    return I;
  }

 private:
  template <class F>
  ARBOR_INLINE static void static_for_3(F&& f) {
    f(std::integral_constant<int, 0>{});
    f(std::integral_constant<int, 1>{});
    f(std::integral_constant<int, 2>{});
  }
  template <class F>
  ARBOR_INLINE static void static_for_3x3(F&& f) {
    static_for_3([&](auto r) { static_for_3([&](auto c) { f(r, c); }); });
  }
};

}  // namespace arbor::spatial
