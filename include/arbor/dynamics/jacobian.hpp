// arbor: joint and frame Jacobians (world, local, local-world-aligned).
#pragma once

#include <array>

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/model/topology.hpp"

namespace arbor {

namespace detail {

/// World-frame column oMj S_j of joint j.
template <class R, int j, class Scalar>
ARBOR_INLINE Motion<Scalar> world_column(const Data<R, Scalar>& d) {
  using B = spatial::BodyOps<R, j, Scalar>;
  const SE3<Scalar>& o = d.oMi[j];
  Vec3<Scalar> axis;
  if constexpr (B::aligned)
    axis = (B::sign > 0) ? Vec3<Scalar>(o.R.col(B::k)) : Vec3<Scalar>(-o.R.col(B::k));
  else
    axis = spatial::cst::mat_cvec<Scalar, typename B::AxisV>(o.R);
  if constexpr (B::revolute)
    return {o.p.cross(axis), axis};
  else
    return {axis, Vec3<Scalar>::Zero()};
}

}  // namespace detail

/// Joint Jacobians: every column of data.J (world frame, oMj S_j) and data.oMi from q.
template <Robot R, class Scalar, class Q>
const typename Data<R, Scalar>::Matrix6x& compute_joint_jacobians(Data<R, Scalar>& d,
                                                                  const Eigen::MatrixBase<Q>& q) {
  forward_kinematics<R>(d, q);
  static_for<R::nb>([&](auto J) {
    constexpr int j = decltype(J)::value;
    d.J.col(j) = detail::world_column<R, j>(d).vector();
  });
  return d.J;
}

/// Jacobian of an operational frame from data.J and data.oMf (after compute_joint_jacobians and
/// frame_placement of that frame). Columns of joints that do not move the frame are zero.
template <Robot R, class Scalar, class D>
void frame_jacobian(const Data<R, Scalar>& d, int frame, ReferenceFrame rf,
                    Eigen::MatrixBase<D> const& J_) {
  static_assert(D::RowsAtCompileTime == 6 && D::ColsAtCompileTime == R::nv, "J must be 6 x nv");
  detail::check_frame<R>(frame);
  auto& J = const_cast<Eigen::MatrixBase<D>&>(J_);
  const int b = R::frames[frame].body;
  const SE3<Scalar>& oMf = d.oMf[frame];
  static_for<R::nb>([&](auto I) {
    constexpr int j = decltype(I)::value;
    if (b < 0 || !model::support<R>[b][j]) {
      J.col(j).setZero();
      return;
    }
    const Motion<Scalar> c = Motion<Scalar>::from(d.J.col(j));
    switch (rf) {
      case ReferenceFrame::world:
        J.col(j) = c.vector();
        break;
      case ReferenceFrame::local:
        J.col(j) = oMf.actInv(c).vector();
        break;
      case ReferenceFrame::local_world_aligned:
        J.col(j).template head<3>() = c.v - oMf.p.cross(c.w);
        J.col(j).template tail<3>() = c.w;
        break;
    }
  });
}

/// Jacobian of an operational frame at q: forward kinematics, joint Jacobians, frame placement,
/// then frame_jacobian. J is a 6 x nv matrix (linear rows first).
template <Robot R, class Scalar, class Q, class D>
void compute_frame_jacobian(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q, int frame,
                            ReferenceFrame rf, Eigen::MatrixBase<D> const& J) {
  detail::check_frame<R>(frame);
  compute_joint_jacobians<R>(d, q);
  frame_placement<R>(d, frame);
  frame_jacobian<R>(d, frame, rf, J);
}

}  // namespace arbor
