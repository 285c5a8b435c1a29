// arbor: the constant inertia of body i as compile-time data: its product with a motion skips a
// zero centre of mass and zero inertia entries, and its transport to the parent frame (crba's
// composite inertias) goes through the sparse placement of BodyPlacement.
#pragma once

#include "arbor/model/types.hpp"
#include "arbor/spatial/body_placement.hpp"
#include "arbor/spatial/inertia.hpp"

namespace arbor::spatial {

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

/// Constant inertia of body i of robot R and the rigid-inertia actions of its placement.
template <class R, int i, class Scalar>
struct BodyInertia : BodyPlacement<R, i, Scalar> {
  using Placement = BodyPlacement<R, i, Scalar>;
  using Placement::jrot;
  using Placement::jtrans;
  using Placement::p_zero;
  using Placement::R_;
  using Placement::revolute;
  using Placement::rot_const;
  using Placement::rot_mat;
  using typename Placement::P;
  using typename Placement::Vp;

  /// Constant inertia of the body in its frame.
  static constexpr detail::InertiaConst Y = detail::to_origin(R::body_inertia[i]);
  static constexpr bool massless = Y.m == 0.0;
  struct HV {
    static constexpr double at(int j) { return Y.h[j]; }
  };
  struct IoK {
    static constexpr double at(int r, int c) { return Y.Io[r][c]; }
  };

  // ---- body inertia (constant) -----------------------------------------------------------------
  /// The constant body inertia times a motion x: [m v - h x w; Io w + h x v], each coordinate one
  /// chain of multiply-adds over the nonzero constant entries (zero com and inertia entries
  /// skipped).
  ARBOR_INLINE static Force<Scalar> inertia_times(const Motion<Scalar>& x) {
    if constexpr (massless) {
      return Force<Scalar>::Zero();
    } else {
      using Kh = cst::Skew<HV>;
      const Scalar m = Scalar(Y.m);
      const Scalar v0 = x.v[0], v1 = x.v[1], v2 = x.v[2], w0 = x.w[0], w1 = x.w[1], w2 = x.w[2];
      Force<Scalar> F;
      F.f[0] = cst::add_krow<Scalar, Kh, 0, -1>(Scalar(v0 * m), w0, w1, w2);
      F.f[1] = cst::add_krow<Scalar, Kh, 1, -1>(Scalar(v1 * m), w0, w1, w2);
      F.f[2] = cst::add_krow<Scalar, Kh, 2, -1>(Scalar(v2 * m), w0, w1, w2);
      F.n[0] = cst::add_krow<Scalar, Kh, 0, 1>(cst::krow<Scalar, IoK, 0>(w0, w1, w2), v0, v1, v2);
      F.n[1] = cst::add_krow<Scalar, Kh, 1, 1>(cst::krow<Scalar, IoK, 1>(w0, w1, w2), v0, v1, v2);
      F.n[2] = cst::add_krow<Scalar, Kh, 2, 1>(cst::krow<Scalar, IoK, 2>(w0, w1, w2), v0, v1, v2);
      return F;
    }
  }
  /// The constant body inertia as a runtime Inertia<S>.
  static Inertia<Scalar> inertia() {
    Inertia<Scalar> I;
    I.m = Scalar(Y.m);
    for (int r = 0; r < 3; ++r) {
      I.h[r] = Scalar(Y.h[r]);
      for (int c = 0; c < 3; ++c)
        I.Io(r, c) = Scalar(Y.Io[r][c]);
    }
    return I;
  }

  /// Rigid inertia in body i's frame -> the same inertia in the parent frame.
  ARBOR_INLINE static Inertia<Scalar> inertia_to_parent(const JointState<Scalar>& js,
                                                        const Inertia<Scalar>& Yc) {
    Vec3<Scalar> h1;
    Mat3<Scalar> I1;
    if constexpr (revolute) {
      h1 = jrot(js, Yc.h);
      I1 = rot_mat(js, Yc.Io);
    } else {
      const Vec3<Scalar> d = jtrans(js);
      const Mat3<Scalar> Pd = skew(d);
      const Mat3<Scalar> Hd = skew(Yc.h);
      h1 = Yc.h + d * Yc.m;
      I1 = Yc.Io - (Hd * Pd + Pd * Hd) - Yc.m * (Pd * Pd);
    }
    Inertia<Scalar> out;
    out.m = Yc.m;
    Vec3<Scalar> hr = R_(h1);
    Mat3<Scalar> Ir = rot_const(I1);
    if constexpr (!p_zero) {
      // Io' = R Io R^T - ([hr][p] + [p][hr] + m [p]^2)
      //     = R Io R^T - (p hr^T + hr p^T - 2 (hr . p) I + m (p p^T - |p|^2 I))
      const Scalar hp =
          cst::dot3<Scalar, cst::VEntry<Vp, 0>, cst::VEntry<Vp, 1>, cst::VEntry<Vp, 2>>(
              hr[0], hr[1], hr[2], [] { return Scalar(0); });
      constexpr double pp = Vp::at(0) * Vp::at(0) + Vp::at(1) * Vp::at(1) + Vp::at(2) * Vp::at(2);
      const Scalar diag = Scalar(2) * hp + Yc.m * Scalar(pp);
      static_for<3 * 3>([&](auto RC) {
        constexpr int r = decltype(RC)::value / 3, c = decltype(RC)::value % 3;
        constexpr double pr = Vp::at(r), pc = Vp::at(c);
        if constexpr (pr != 0.0)
          Ir(r, c) -= Scalar(pr) * hr[c];
        if constexpr (pc != 0.0)
          Ir(r, c) -= hr[r] * Scalar(pc);
        if constexpr (pr * pc != 0.0)
          Ir(r, c) -= Yc.m * Scalar(pr * pc);
        if constexpr (r == c)
          Ir(r, c) += diag;
      });
      hr += cst::translation_value<Scalar, P>() * Yc.m;
    }
    out.h = hr;
    out.Io = Ir;
    return out;
  }
};

}  // namespace arbor::spatial
