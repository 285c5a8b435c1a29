// arbor: forward kinematics (placements, optionally velocities and accelerations) and frame
// placements/velocities, unrolled over the tree.
#pragma once

#include "arbor/core/sincos_batch.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/spatial/body_ops.hpp"
#include "arbor/spatial/constant.hpp"

namespace arbor {

namespace detail {

/// Compile-time check of the sizes of (q, v, x) for robot R.
template <class R, class Q, class V, class X>
constexpr void check_sizes() {
  static_assert(Q::RowsAtCompileTime == R::nq && Q::ColsAtCompileTime == 1,
                "q must be a column vector of R::nq entries");
  static_assert(V::RowsAtCompileTime == R::nv && V::ColsAtCompileTime == 1,
                "v must be a column vector of R::nv entries");
  static_assert(X::RowsAtCompileTime == R::nv && X::ColsAtCompileTime == 1,
                "a, tau and ddq must be column vectors of R::nv entries");
}

/// Checks a runtime operational-frame index (use R::frame_id::<link> names, not numbers).
template <class R>
ARBOR_INLINE void check_frame(int frame) {
  ARBOR_ASSERT(frame >= 0 && frame < R::nf, "operational frame index out of range");
  (void)frame;
}

/// Number of revolute joints of R, and the slot of revolute joint i among them.
template <class R>
constexpr int revolute_before(int i) {
  int n = 0;
  for (int j = 0; j < i; ++j)
    n += model::is_revolute(R::joint_kind[j]) ? 1 : 0;
  return n;
}

/// Joint states of every body from q. In double, the sines and cosines of all revolute joints
/// in one batch (sincos_batch.hpp: the same values, across SIMD lanes).
template <class R, class Scalar, class Q>
ARBOR_INLINE void joint_states(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q) {
  constexpr int nr = revolute_before<R>(R::nb);
  if constexpr (std::is_same_v<Scalar, double> && nr > 1) {
    constexpr int np = (nr + kSincosLanes - 1) / kSincosLanes * kSincosLanes;
    double x[np], s[np], c[np];
    static_for<R::nb>([&](auto I) {
      constexpr int i = decltype(I)::value;
      if constexpr (model::is_revolute(R::joint_kind[i]))
        x[revolute_before<R>(i)] = q[i];
    });
    for (int j = nr; j < np; ++j)
      x[j] = 1.0;  // padding, not an argument treated apart
    sincos_double_batch<np>(x, s, c);
    static_for<R::nb>([&](auto I) {
      constexpr int i = decltype(I)::value;
      using B = spatial::BodyOps<R, i, Scalar>;
      if constexpr (B::revolute) {
        constexpr int r = revolute_before<R>(i);
        JointState<Scalar>& js = d.joint[i];
        js.c = c[r];
        js.s = (B::sign < 0) ? -s[r] : s[r];
        js.d = 0.0;
      } else {
        d.joint[i] = B::state(Scalar(q[i]));
      }
    });
  } else {
    static_for<R::nb>([&](auto I) {
      constexpr int i = decltype(I)::value;
      d.joint[i] = spatial::BodyOps<R, i, Scalar>::state(Scalar(q[i]));
    });
  }
}

/// liMi and oMi of body i (its parent's oMi already computed).
template <class R, int i, class Scalar>
ARBOR_INLINE void body_placement(Data<R, Scalar>& d) {
  using B = spatial::BodyOps<R, i, Scalar>;
  const JointState<Scalar>& js = d.joint[i];
  // liMi = Pl * J(q)
  SE3<Scalar>& l = d.liMi[i];
  l.R = B::const_rot_jrot(js);
  l.p = spatial::cst::translation_value<Scalar, typename B::P>();
  if constexpr (!B::revolute)
    l.p += B::R_(B::jtrans(js));
  if constexpr (B::parent < 0) {
    d.oMi[i] = l;
  } else if constexpr (B::aligned) {
    // scalar by scalar: A = oRp Pl.R (constant entries), oRi = A Rj, oPi = oPp + oRp Pl.p (+ A d)
    using KRT = typename B::KRT;
    using Vp = typename B::Vp;
    constexpr int k = B::k, ia = B::ia, ib = B::ib;
    const SE3<Scalar>& op = d.oMi[B::parent];
    SE3<Scalar>& o = d.oMi[i];
    Scalar A[3][3];
    for (int r = 0; r < 3; ++r) {
      const Scalar x0 = op.R(r, 0), x1 = op.R(r, 1), x2 = op.R(r, 2);
      A[r][0] = spatial::cst::krow<Scalar, KRT, 0>(x0, x1, x2);
      A[r][1] = spatial::cst::krow<Scalar, KRT, 1>(x0, x1, x2);
      A[r][2] = spatial::cst::krow<Scalar, KRT, 2>(x0, x1, x2);
      Scalar p = op.p[r];
      if constexpr (!B::p_zero) {
        namespace c = spatial::cst;
        c::add_scaled<Scalar, c::VEntry<Vp, 0>>(p, x0);
        c::add_scaled<Scalar, c::VEntry<Vp, 1>>(p, x1);
        c::add_scaled<Scalar, c::VEntry<Vp, 2>>(p, x2);
      }
      if constexpr (!B::revolute)
        p += A[r][k] * js.d;
      o.p[r] = p;
    }
    for (int r = 0; r < 3; ++r) {
      o.R(r, k) = A[r][k];
      if constexpr (B::revolute) {
        o.R(r, ia) = A[r][ia] * js.c + A[r][ib] * js.s;
        o.R(r, ib) = A[r][ib] * js.c - A[r][ia] * js.s;
      } else {
        o.R(r, ia) = A[r][ia];
        o.R(r, ib) = A[r][ib];
      }
    }
  } else {
    const SE3<Scalar>& op = d.oMi[B::parent];
    SE3<Scalar>& o = d.oMi[i];
    const Mat3<Scalar> A = spatial::cst::mul_cols<Scalar, typename B::KR, 3>(op.R);  // oRp * Pl.R
    o.R = B::mat_jrot(js, A);
    o.p = op.p;
    if constexpr (!B::p_zero)
      o.p += spatial::cst::mat_cvec<Scalar, typename B::Vp>(op.R);
    if constexpr (!B::revolute)
      o.p += A * B::jtrans(js);
  }
}

}  // namespace detail

/// Forward kinematics: data.joint, data.liMi and data.oMi from q.
template <Robot R, class Scalar, class Q>
void forward_kinematics(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q) {
  static_assert(Q::RowsAtCompileTime == R::nq, "q has the wrong size");
  detail::joint_states(d, q);
  static_for<R::nb>([&](auto I) { detail::body_placement<R, decltype(I)::value, Scalar>(d); });
}

/// Forward kinematics with velocities: also data.v (body frame spatial velocities).
template <Robot R, class Scalar, class Q, class V>
void forward_kinematics(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q,
                        const Eigen::MatrixBase<V>& v) {
  forward_kinematics<R>(d, q);
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    if constexpr (B::parent < 0)
      d.v[i] = B::S_times(Scalar(v[i]));
    else {
      d.v[i] = B::motion_to_child(d.joint[i], d.v[B::parent]);
      B::add_S(d.v[i], Scalar(v[i]));
    }
  });
}

/// Forward kinematics with velocities and accelerations: also data.a (body frame, no gravity).
template <Robot R, class Scalar, class Q, class V, class A>
void forward_kinematics(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q,
                        const Eigen::MatrixBase<V>& v, const Eigen::MatrixBase<A>& a) {
  forward_kinematics<R>(d, q);
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    const Scalar vi = Scalar(v[i]);
    if constexpr (B::parent < 0) {
      d.v[i] = B::S_times(vi);
      d.a[i] = B::S_times(Scalar(a[i]));
    } else {
      d.v[i] = B::motion_to_child(d.joint[i], d.v[B::parent]);
      B::add_S(d.v[i], vi);
      d.a[i] = B::motion_to_child(d.joint[i], d.a[B::parent]);
      B::add_cross_S(d.a[i], d.v[i], vi);
      B::add_S(d.a[i], Scalar(a[i]));
    }
  });
}

namespace detail {
template <class R, int fr>
struct FramePl {
  static constexpr const model::Placement& X = R::frames[fr].placement;
};

template <class R, int fr, class Scalar>
ARBOR_INLINE void frame_placement_ct(Data<R, Scalar>& d) {
  using P = FramePl<R, fr>;
  using KR = spatial::cst::Rot<P>;
  using Vp = spatial::cst::Trans<P>;
  constexpr int b = R::frames[fr].body;
  if constexpr (b < 0) {
    d.oMf[fr].R = spatial::cst::rotation_value<Scalar, P>();
    d.oMf[fr].p = spatial::cst::translation_value<Scalar, P>();
  } else {
    const SE3<Scalar>& o = d.oMi[b];
    d.oMf[fr].R = spatial::cst::mul_cols<Scalar, KR, 3>(o.R);
    d.oMf[fr].p = o.p;
    if constexpr (!spatial::cst::is_zero_vec<Vp>())
      d.oMf[fr].p += spatial::cst::mat_cvec<Scalar, Vp>(o.R);
  }
}
}  // namespace detail

/// data.oMf of every operational frame (after forward_kinematics).
template <Robot R, class Scalar>
void update_frame_placements(Data<R, Scalar>& d) {
  static_for<R::nf>([&](auto F) { detail::frame_placement_ct<R, decltype(F)::value, Scalar>(d); });
}

/// data.oMf[frame] of one operational frame (after forward_kinematics); returns it.
template <Robot R, class Scalar>
const SE3<Scalar>& frame_placement(Data<R, Scalar>& d, int frame) {
  detail::check_frame<R>(frame);
  static_for<R::nf>([&](auto F) {
    if (decltype(F)::value == frame)
      detail::frame_placement_ct<R, decltype(F)::value, Scalar>(d);
  });
  return d.oMf[frame];
}

/// Placement of an operational frame in its body frame, as a runtime SE3<S>.
template <Robot R, class Scalar = double>
SE3<Scalar> frame_in_body(int frame) {
  detail::check_frame<R>(frame);
  SE3<Scalar> X;
  const model::Placement& P = R::frames[frame].placement;
  for (int r = 0; r < 3; ++r) {
    X.p[r] = Scalar(P.p[r]);
    for (int c = 0; c < 3; ++c)
      X.R(r, c) = Scalar(P.R[r][c]);
  }
  return X;
}

/// Spatial velocity of an operational frame (after forward_kinematics with v, and frame_placement
/// of that frame for World/LocalWorldAligned).
template <Robot R, class Scalar>
Motion<Scalar> frame_velocity(const Data<R, Scalar>& d, int frame, ReferenceFrame rf) {
  detail::check_frame<R>(frame);
  const int b = R::frames[frame].body;
  if (b < 0)
    return Motion<Scalar>::Zero();
  const SE3<Scalar> iMf = frame_in_body<R, Scalar>(frame);
  const Motion<Scalar> local = iMf.actInv(d.v[b]);
  switch (rf) {
    case ReferenceFrame::local:
      return local;
    case ReferenceFrame::world:
      return d.oMi[b].act(d.v[b]);
    case ReferenceFrame::local_world_aligned:
    default:
      return {d.oMf[frame].R * local.v, d.oMf[frame].R * local.w};
  }
}

}  // namespace arbor
