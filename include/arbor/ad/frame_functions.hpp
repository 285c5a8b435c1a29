// arbor: the task-space RBD function objects every manipulator task needs, beside
// ad::FramePosition (rbd_functions.hpp), with the same interface (bind<F>(ws), call<Tag>):
//   FramePose<R, F>                    q -> [p (3), R.col(0), R.col(1), R.col(2)] (12)
//   FrameOrientationError<R, F, Form>  [q, r_ref (9)] -> e (3), the orientation error of frame F
//                                      against a reference rotation R_ref (its columns r_ref_c):
//       LogMap    e = log(R_ref' R) (the rotation vector taking R_ref to R, in R_ref's axes;
//                 |e| = the angle in [0, pi]; careful branches near 0 and pi);
//       CrossSum  e = 1/2 sum_c r_ref_c x r_c (world axes; the paper's task code: = the rotation
//                 vector to first order, |e| = sin(angle) for a rotation about one axis, cheap).
//   FrameVelocity<R, F>                [q, qd] -> [v (3), w (3)] = J(q) qd, the frame's linear
//                                      and angular velocity (LocalWorldAligned: world axes, at
//                                      the frame's origin)
// and PoseCache / WithPoseCache: a workspace that also keeps the last analytical FramePose
// position Jacobian, which an ad::FramePosition of the same frame at the same q then reuses.
//
// Jacobians (provider Analytical), from one frame Jacobian J_F = [J_v; J_w] (LocalWorldAligned):
//   FramePose       [J_v; w_j x r_c per column j and c]   (dR/dq_j = [w_j]x R)
//   LogMap          d e/d q = Jl^-1(e) R_ref' J_w (Jl the left Jacobian of SO(3); exact on
//                   SO(3), finite at pi); d e/d r_ref by forward mode (Dual<T, 9>) through the
//                   3 x 3 log of R_ref' R (a reference is a constant or a parameter: its columns
//                   are rarely differentiated)
//   CrossSum        d e/d q = 1/2 (tr(R_ref' R) I - R R_ref') J_w; d e/d r_ref_c = -1/2 [r_c]x
//   FrameVelocity   [d (J qd)/d q, J] (frame_jacobian_times_vector_derivative)
// R_ref must be a rotation (orthonormal): LogMap's q-columns use the SO(3) identity.
// AutoDiff: Dual<T, nin> through the value code, as for every function object. Generated:
// arbor-adgen generates ForwardDynamics, InverseDynamics and FramePosition only; under the
// Generated tag these functions fall back to AutoDiff (`generated_fallback`, ProviderOf in
// rbd_functions.hpp), so one tag serves a whole problem.
//
// Cost per call (n = R::nv): value = one forward-kinematics pass (FrameVelocity: and the joint
// Jacobians); Analytical = one frame-Jacobian pass plus O(n) 3-vector products (FrameVelocity:
// plus the O(depth) Jacobian-times-vector derivative); LogMap's value adds a 3 x 3 product, a
// square root and an atan2, its reference columns about ten times that.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/rbd_functions.hpp"
#include "arbor/core/math.hpp"
#include "arbor/derivatives/frame_derivatives.hpp"
#include "arbor/dynamics/jacobian.hpp"
#include "arbor/dynamics/kinematics.hpp"

namespace arbor::ad {

/// Orientation-error form tag: e = log(R_ref' R).
struct LogMap {};
/// Orientation-error form tag: e = 1/2 sum_c r_ref_c x r_c.
struct CrossSum {};

namespace detail {

/// atan2 for plain and (nested) dual scalars: d atan2(y, x) = (x dy - y dx) / (x^2 + y^2).
template <class S>
S atan2_any(const S& y, const S& x) {
  if constexpr (is_dual_v<S>) {
    S r(atan2_any(y.v, x.v));
    const auto den = x.v * x.v + y.v * y.v;
    const auto a = x.v / den, b = y.v / den;
    for (int k = 0; k < S::directions; ++k)
      r.d[k] = a * y.d[k] - b * x.d[k];
    return r;
  } else {
    using std::atan2;
    return S(atan2(y, x));
  }
}

/// e = log(M) for M = R_ref' R (a rotation), as a function of M's nine entries (generic scalar:
/// AutoDiff differentiates it). With s = vee(M - M') / 2 and c = (tr M - 1) / 2 (sin and cos of the
/// angle on SO(3)):
///   |s|^2 < 1e-6, c > 0  e = g s, g = atan(n / c) / n by its series 1/c - n^2/(3c^3) + n^4/(5c^5)
///                        (no square root at 0; truncation n^6 < 1e-18)
///   |s|^2 < 1e-4, c < 0  near pi, where s / |s| loses its digits: the axis a from the symmetric
///                        part (M + M')/2 - c I = (1 - c) a a' (its largest diagonal's column),
///                        signed by s; e = atan2(a's, c) a
///   otherwise            e = atan2(|s|, c) s / |s|
template <class S, class M>
VecN<S, 3> log_rotation(const M& m) {
  using V = std::remove_cvref_t<decltype(value_of(S()))>;
  VecN<S, 3> s;
  s[0] = S(0.5) * (m(2, 1) - m(1, 2));
  s[1] = S(0.5) * (m(0, 2) - m(2, 0));
  s[2] = S(0.5) * (m(1, 0) - m(0, 1));
  const S c = S(0.5) * (m(0, 0) + m(1, 1) + m(2, 2) - S(1));
  const S n2 = s.dot(s);
  const V n2v = value_of(n2), cv = value_of(c);
  if (n2v < V(1e-6) && cv > V(0)) {
    const S ic = S(1) / c, ic2 = ic * ic;
    const S g = ic * (S(1) - n2 * ic2 * (S(1) / S(3) - n2 * ic2 / S(5)));
    return s * g;
  }
  if (n2v < V(1e-4) && cv < V(0)) {
    int i = 0;
    for (int k = 1; k < 3; ++k)
      if (value_of(m(k, k)) > value_of(m(i, i)))
        i = k;
    VecN<S, 3> a;
    for (int r = 0; r < 3; ++r)
      a[r] = S(0.5) * (m(r, i) + m(i, r)) - (r == i ? c : S(0));
    a = a / arbor::sqrt(a[i] * (S(1) - c));
    if (value_of(a.dot(s)) < V(0))
      a = -a;
    return a * atan2_any(S(a.dot(s)), c);
  }
  const S n = arbor::sqrt(n2);
  return s * (atan2_any(n, c) / n);
}

/// The inverse left Jacobian of SO(3) at the rotation vector e: I - [e]x/2 + beta [e]x^2,
/// beta = 1/t^2 - sin t / (2 t (1 - cos t)) (t = |e|; its series 1/12 + t^2/720 + t^4/30240 below
/// t = 1e-2; finite at pi).
template <class T>
Eigen::Matrix<T, 3, 3> inverse_left_jacobian(const VecN<T, 3>& e) {
  using V = std::remove_cvref_t<decltype(value_of(T()))>;
  const T t2 = e.dot(e);
  T beta;
  if (value_of(t2) < V(1e-4)) {
    beta = T(1.0 / 12) + t2 * (T(1.0 / 720) + t2 * T(1.0 / 30240));
  } else {
    const T t = arbor::sqrt(t2);
    T st, ct;
    arbor::sincos(t, st, ct);
    beta = T(1) / t2 - st / (T(2) * t * (T(1) - ct));
  }
  Eigen::Matrix<T, 3, 3> E;
  E << T(0), -e[2], e[1], e[2], T(0), -e[0], -e[1], e[0], T(0);
  Eigen::Matrix<T, 3, 3> out = E * T(-0.5) + (E * E) * beta;
  for (int i = 0; i < 3; ++i)
    out(i, i) += T(1);
  return out;
}

/// The frame's placement and its LocalWorldAligned Jacobian at q (one pass).
template <class R, int F, class T, class Q>
const SE3<T>& frame_pose_and_jacobian(Data<R, T>& d, const Q& q, Eigen::Matrix<T, 6, R::nv>& Jf) {
  Jf.setZero();  // (set by the call; zero for GCC's may-be-uninitialised analysis)
  compute_frame_jacobian<R>(d, q, F, ReferenceFrame::local_world_aligned, Jf);
  return d.oMf[F];
}

}  // namespace detail

/// The position rows of the last analytical FramePose Jacobian of robot R at scalar T and the q it
/// was taken at. A workspace with a member `pose_cache` of this type (WithPoseCache) makes
/// FramePose store there, and ad::FramePosition of the same frame at bitwise the same q take its
/// analytical value and Jacobian from there instead of a second kinematics sweep (the same
/// quantity up to round-off: the linear rows of the frame Jacobian). A stage whose cost evaluates
/// the pose and whose constraint the position at the same q profits; NaN never matches.
template <class R, class T>
struct PoseCache {
  using Scalar = T;              ///< the scalar the cache serves
  int frame = -1;                ///< the frame of p and J (-1: none stored yet)
  VecN<T, R::nv> q;              ///< where p and J were taken
  VecN<T, 3> p;                  ///< frame position
  Eigen::Matrix<T, 3, R::nv> J;  ///< its Jacobian (the pose Jacobian's first 3 rows)
  /// Store p and J of frame f at q.
  template <class Q, class Jp, class P>
  void store(int f, const Q& q_, const Jp& J_, const P& p_) {
    frame = f;
    q = q_;
    J = J_;
    p = p_;
  }
  /// p and J of frame f at q_ if they were stored for f at exactly q_.
  bool lookup(int f, const VecN<T, R::nv>& q_, VecN<T, 3>& p_,
              Eigen::Matrix<T, 3, R::nv>& J_) const {
    if (frame != f)
      return false;
    for (int i = 0; i < R::nv; ++i)
      if (!known_equal(q_[i], q[i]))  // (a tracing scalar: the same node)
        return false;
    p_ = p;
    J_ = J;
    return true;
  }
};

/// Workspace W with a PoseCache at scalar T (W's robot).
template <class W, class T = double>
struct WithPoseCache : W {
  PoseCache<typename W::Robot, T> pose_cache;  ///< the last FramePose position Jacobian at T
};

/// Position and rotation of operational frame F of robot R (pass R::frame_id::<link>):
/// x = q -> [p (3), R.col(0), R.col(1), R.col(2)] (world).
template <Robot R, int F>
struct FramePose {
  static_assert(F >= 0 && F < R::nf, "operational frame index out of range");
  using Robot = R;
  static constexpr int nin = R::nv;                     ///< inputs (q)
  static constexpr int nout = 12;                       ///< position, rotation columns
  static constexpr bool needs_derivative_data = false;  ///< J^a needs Data only
  static constexpr bool generated_fallback = true;      ///< Generated: AutoDiff

  /// y = [p, columns of R] at q.
  template <class T, class W>
  static void value(W& ws, const VecN<T, nin>& q, VecN<T, nout>& y) {
    auto& d = ws.template data<T>();
    forward_kinematics<R>(d, q);
    const auto& M = frame_placement<R>(d, F);
    y.template head<3>() = M.p;
    for (int c = 0; c < 3; ++c)
      y.template segment<3>(3 + 3 * c) = M.R.col(c);
  }

  /// y and J^a: the frame Jacobian's linear rows, dR/dq_j = [w_j]x R; stores the position rows
  /// in ws.pose_cache when ws has one at scalar T.
  template <class T, class W>
  static void analytical(W& ws, const VecN<T, nin>& q, VecN<T, nout>& y,
                         Eigen::Matrix<T, nout, nin>& J) {
    auto& d = ws.template data<T>();
    Eigen::Matrix<T, 6, nin> Jf;
    const auto& M = detail::frame_pose_and_jacobian<R, F>(d, q, Jf);
    y.template head<3>() = M.p;
    for (int c = 0; c < 3; ++c)
      y.template segment<3>(3 + 3 * c) = M.R.col(c);
    J.template topRows<3>() = Jf.template topRows<3>();
    for (int j = 0; j < nin; ++j) {
      const VecN<T, 3> w = Jf.col(j).template tail<3>();
      for (int c = 0; c < 3; ++c)
        J.template block<3, 1>(3 + 3 * c, j) = w.cross(VecN<T, 3>(M.R.col(c)));
    }
    if constexpr (requires { ws.pose_cache; })
      if constexpr (std::is_same_v<T, typename decltype(ws.pose_cache)::Scalar>)
        ws.pose_cache.store(F, q, J.template topRows<3>(), M.p);
  }
};

/// Orientation error of operational frame F of robot R against a reference rotation:
/// x = [q (nv), r_ref (9): the columns of R_ref] -> e (3); Form LogMap (e = log(R_ref' R), R_ref's
/// axes) or CrossSum (e = 1/2 sum_c r_ref_c x r_c, world axes). Pass the reference as a constant
/// (ad::constant of the 9 numbers) or as stage parameters (a segment of D::p).
template <Robot R, int F, class Form = LogMap>
struct FrameOrientationError {
  static_assert(F >= 0 && F < R::nf, "operational frame index out of range");
  static_assert(std::is_same_v<Form, LogMap> || std::is_same_v<Form, CrossSum>,
                "Form must be ad::LogMap or ad::CrossSum");
  using Robot = R;
  static constexpr int nv = R::nv;                      ///< DoF
  static constexpr int nin = nv + 9;                    ///< inputs (q, columns of R_ref)
  static constexpr int nout = 3;                        ///< outputs (e)
  static constexpr bool needs_derivative_data = false;  ///< J^a needs Data only
  static constexpr bool generated_fallback = true;      ///< Generated: AutoDiff

  /// e from the frame rotation Rf and the reference columns in x (generic scalar).
  template <class T, class X, class M>
  static VecN<T, 3> error(const X& x, const M& Rf) {
    Eigen::Matrix<T, 3, 3> Rr;
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i)
        Rr(i, c) = x[nv + 3 * c + i];
    if constexpr (std::is_same_v<Form, LogMap>) {
      const Eigen::Matrix<T, 3, 3> Me = Rr.transpose() * Rf;
      return detail::log_rotation<T>(Me);
    } else {
      VecN<T, 3> e = VecN<T, 3>::Zero();
      for (int c = 0; c < 3; ++c)
        e += VecN<T, 3>(Rr.col(c)).cross(VecN<T, 3>(Rf.col(c)));
      return e * T(0.5);
    }
  }

  /// y = e at x.
  template <class T, class W>
  static void value(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = ws.template data<T>();
    forward_kinematics<R>(d, x.template head<nv>());
    y = error<T>(x, frame_placement<R>(d, F).R);
  }

  /// y and J^a (see the header's table).
  template <class T, class W>
  static void analytical(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y,
                         Eigen::Matrix<T, nout, nin>& J) {
    auto& d = ws.template data<T>();
    Eigen::Matrix<T, 6, nv> Jf;
    const Eigen::Matrix<T, 3, 3> Rf =
        detail::frame_pose_and_jacobian<R, F>(d, x.template head<nv>(), Jf).R;
    Eigen::Matrix<T, 3, 3> Rr;
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i)
        Rr(i, c) = x[nv + 3 * c + i];
    if constexpr (std::is_same_v<Form, LogMap>) {
      // value and reference columns: forward mode over the nine reference entries
      using D9 = Dual<T, 9>;
      VecN<D9, nin> xd;
      for (int k = 0; k < nv; ++k)
        xd[k] = D9(x[k]);
      for (int k = 0; k < 9; ++k)
        xd[nv + k] = D9::variable(x[nv + k], k);
      const VecN<D9, 3> ed = error<D9>(xd, Rf.template cast<D9>().eval());
      for (int i = 0; i < 3; ++i) {
        y[i] = ed[i].v;
        for (int k = 0; k < 9; ++k)
          J(i, nv + k) = ed[i].d[k];
      }
      J.template leftCols<nv>() =
          detail::inverse_left_jacobian<T>(y) * (Rr.transpose() * Jf.template bottomRows<3>());
    } else {
      y = error<T>(x, Rf);
      Eigen::Matrix<T, 3, 3> A = Rf * Rr.transpose() * T(-0.5);
      const T tr = (Rr.transpose() * Rf).trace() * T(0.5);
      for (int i = 0; i < 3; ++i)
        A(i, i) += tr;
      J.template leftCols<nv>() = A * Jf.template bottomRows<3>();
      for (int c = 0; c < 3; ++c) {  // -1/2 [r_c]x
        const VecN<T, 3> r = Rf.col(c) * T(0.5);
        auto B = J.template block<3, 3>(0, nv + 3 * c);
        B << T(0), r[2], -r[1], -r[2], T(0), r[0], r[1], -r[0], T(0);
      }
    }
  }
};

/// Velocity of operational frame F of robot R: x = [q, qd] -> [v (3), w (3)] = J_F(q) qd,
/// LocalWorldAligned (world axes, at the frame's origin).
template <Robot R, int F>
struct FrameVelocity {
  static_assert(F >= 0 && F < R::nf, "operational frame index out of range");
  using Robot = R;
  static constexpr int nv = R::nv;                      ///< DoF
  static constexpr int nin = 2 * nv;                    ///< inputs (q, qd)
  static constexpr int nout = 6;                        ///< outputs (linear, angular velocity)
  static constexpr bool needs_derivative_data = false;  ///< J^a needs Data only
  static constexpr bool generated_fallback = true;      ///< Generated: AutoDiff

  /// y = J_F(q) qd.
  template <class T, class W>
  static void value(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = ws.template data<T>();
    Eigen::Matrix<T, 6, nv> Jf;
    detail::frame_pose_and_jacobian<R, F>(d, x.template head<nv>(), Jf);
    y = Jf * x.template tail<nv>();
  }

  /// y and J^a = [d (J_F qd)/d q, J_F].
  template <class T, class W>
  static void analytical(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y,
                         Eigen::Matrix<T, nout, nin>& J) {
    auto& d = ws.template data<T>();
    const VecN<T, nv> qd = x.template tail<nv>();
    Eigen::Matrix<T, 6, nv> dq = Eigen::Matrix<T, 6, nv>::Zero();  // (set by the call)
    compute_frame_jacobian_times_vector_derivative<R>(d, x.template head<nv>(), F, qd, dq);
    Eigen::Matrix<T, 6, nv> Jf;
    Jf.setZero();
    frame_jacobian<R>(d, F, ReferenceFrame::local_world_aligned, Jf);
    y = Jf * qd;
    J.template leftCols<nv>() = dq;
    J.template rightCols<nv>() = Jf;
  }
};

}  // namespace arbor::ad
