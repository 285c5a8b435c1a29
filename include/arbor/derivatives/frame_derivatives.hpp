// arbor: kinematic derivatives the NMPC needs for path constraints and their Gauss-Newton terms:
// the derivative of an operational frame's position, and the derivative with respect to q of its
// (LocalWorldAligned) Jacobian times a vector.
//
// With world joint columns S_j (data.J) and the frame origin p on body b, the LocalWorldAligned
// Jacobian times x is u(q, x) = [V_v + V_w x p; V_w] for V = sum_{j on the path to b} S_j x_j.
// Moving joint k (on the path) turns every S_j after it: d S_j / d q_k = S_k x S_j, so
//   d V / d q_k = S_k x V_k,  V_k = sum over path joints after k of S_j x_j,
//   d p / d q_k = S_k,v + S_k,w x p,
//   d u / d q_k = [dV_v + dV_w x p + V_w x dp; dV_w],
// O(depth) per frame. Joints off the path give zero columns.
#pragma once

#include "arbor/dynamics/jacobian.hpp"

namespace arbor {

/// d p / d q (3 x nv) of the origin p of an operational frame, world coordinates (the linear rows
/// of its LocalWorldAligned Jacobian). Needs data.J and data.oMf[frame]: call after
/// compute_joint_jacobians (or rnea_derivatives) and frame_placement.
template <Robot R, class Scalar, class D>
void frame_position_derivative(const Data<R, Scalar>& d, int frame,
                               Eigen::MatrixBase<D> const& out_) {
  static_assert(D::RowsAtCompileTime == 3 && D::ColsAtCompileTime == R::nv, "out must be 3 x nv");
  detail::check_frame<R>(frame);
  auto& out = const_cast<Eigen::MatrixBase<D>&>(out_);
  const int b = R::frames[frame].body;
  const Vec3<Scalar>& p = d.oMf[frame].p;
  for (int k = 0; k < R::nv; ++k) {
    if (b < 0 || !model::support<R>[b][k]) {
      out.col(k).setZero();
      continue;
    }
    const Vec3<Scalar> Sv = d.J.col(k).template head<3>(), Sw = d.J.col(k).template tail<3>();
    out.col(k) = Sv + Sw.cross(p);
  }
}

/// d (J(q) x) / d q (6 x nv, linear rows first) for the LocalWorldAligned Jacobian J of an
/// operational frame and a fixed vector x (nv). Needs data.J and data.oMf[frame] as
/// frame_position_derivative does. O(depth of the frame's body).
template <Robot R, class Scalar, class X, class D>
void frame_jacobian_times_vector_derivative(const Data<R, Scalar>& d, int frame,
                                            const Eigen::MatrixBase<X>& x,
                                            Eigen::MatrixBase<D> const& out_) {
  static_assert(X::RowsAtCompileTime == R::nv, "x must have nv entries");
  static_assert(D::RowsAtCompileTime == 6 && D::ColsAtCompileTime == R::nv, "out must be 6 x nv");
  detail::check_frame<R>(frame);
  auto& out = const_cast<Eigen::MatrixBase<D>&>(out_);
  const int b = R::frames[frame].body;
  out.setZero();
  if (b < 0)
    return;
  const Vec3<Scalar>& p = d.oMf[frame].p;
  auto col = [&](int k) { return Motion<Scalar>::from(d.J.col(k)); };
  Motion<Scalar> V = Motion<Scalar>::Zero();
  for (int j = b; j >= 0; j = R::parent[j])
    V += col(j) * Scalar(x[j]);
  Motion<Scalar> Vk = Motion<Scalar>::Zero();  // sum over the path after k
  for (int k = b; k >= 0; k = R::parent[k]) {
    const Motion<Scalar> Sk = col(k);
    const Motion<Scalar> dV = spatial::cross(Sk, Vk);
    const Vec3<Scalar> dp = Sk.v + Sk.w.cross(p);
    out.col(k).template head<3>() = dV.v + dV.w.cross(p) + V.w.cross(dp);
    out.col(k).template tail<3>() = dV.w;
    Vk += Sk * Scalar(x[k]);
  }
}

/// compute_joint_jacobians and frame_placement at q, then frame_position_derivative.
template <Robot R, class Scalar, class Q, class D>
void compute_frame_position_derivative(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q, int frame,
                                       Eigen::MatrixBase<D> const& out) {
  detail::check_frame<R>(frame);
  compute_joint_jacobians<R>(d, q);
  frame_placement<R>(d, frame);
  frame_position_derivative<R>(d, frame, out);
}

/// compute_joint_jacobians and frame_placement at q, then frame_jacobian_times_vector_derivative.
template <Robot R, class Scalar, class Q, class X, class D>
void compute_frame_jacobian_times_vector_derivative(Data<R, Scalar>& d,
                                                    const Eigen::MatrixBase<Q>& q, int frame,
                                                    const Eigen::MatrixBase<X>& x,
                                                    Eigen::MatrixBase<D> const& out) {
  detail::check_frame<R>(frame);
  compute_joint_jacobians<R>(d, q);
  frame_placement<R>(d, frame);
  frame_jacobian_times_vector_derivative<R>(d, frame, x, out);
}

}  // namespace arbor
