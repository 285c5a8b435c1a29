// arbor: joint and frame Jacobians (world, local, local-world-aligned).
#pragma once

#include <array>

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"

namespace arbor {

namespace detail {

/// support<R>[i][j]: body j is body i or one of its ancestors.
template <class R>
constexpr std::array<std::array<bool, R::nb>, R::nb> support_table() {
  std::array<std::array<bool, R::nb>, R::nb> t{};
  for (int i = 0; i < R::nb; ++i)
    for (int j = i; j >= 0; j = R::parent[j])
      t[i][j] = true;
  return t;
}
template <class R>
inline constexpr std::array<std::array<bool, R::nb>, R::nb> support = support_table<R>();

/// World-frame column oMj S_j of joint j.
template <class R, int j, class S>
ARBOR_INLINE Motion<S> world_column(const Data<R, S>& d) {
  using B = spatial::BodyOps<R, j, S>;
  const SE3<S>& o = d.oMi[j];
  Vec3<S> axis;
  if constexpr (B::aligned)
    axis = (B::sign > 0) ? Vec3<S>(o.R.col(B::k)) : Vec3<S>(-o.R.col(B::k));
  else
    axis = spatial::cst::mat_cvec<S, typename B::AxisV>(o.R);
  if constexpr (B::revolute)
    return {o.p.cross(axis), axis};
  else
    return {axis, Vec3<S>::Zero()};
}

}  // namespace detail

/// Joint Jacobians: every column of data.J (world frame, oMj S_j) and data.oMi from q.
template <Robot R, class S, class Q>
const typename Data<R, S>::Matrix6x& compute_joint_jacobians(Data<R, S>& d,
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
template <Robot R, class S, class D>
void frame_jacobian(const Data<R, S>& d, int frame, ReferenceFrame rf,
                    Eigen::MatrixBase<D> const& J_) {
  static_assert(D::RowsAtCompileTime == 6 && D::ColsAtCompileTime == R::nv, "J must be 6 x nv");
  auto& J = const_cast<Eigen::MatrixBase<D>&>(J_);
  const int b = R::frames[frame].body;
  const SE3<S>& oMf = d.oMf[frame];
  static_for<R::nb>([&](auto I) {
    constexpr int j = decltype(I)::value;
    if (b < 0 || !detail::support<R>[b][j]) {
      J.col(j).setZero();
      return;
    }
    const Motion<S> c = Motion<S>::from(d.J.col(j));
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
template <Robot R, class S, class Q, class D>
void compute_frame_jacobian(Data<R, S>& d, const Eigen::MatrixBase<Q>& q, int frame,
                            ReferenceFrame rf, Eigen::MatrixBase<D> const& J) {
  ARBOR_ASSERT(frame >= 0 && frame < R::nf, "frame index out of range");
  compute_joint_jacobians<R>(d, q);
  frame_placement<R>(d, frame);
  frame_jacobian<R>(d, frame, rf, J);
}

}  // namespace arbor
