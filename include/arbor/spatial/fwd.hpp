// arbor: fixed-size Eigen aliases shared by the spatial and dynamics modules.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arbor {

/// Fixed-size Eigen aliases; Scalar is double, float or an AD/op-counting type.
template <class S>
using Vec3 = Eigen::Matrix<S, 3, 1>;
template <class S>
using Mat3 = Eigen::Matrix<S, 3, 3>;
template <class S>
using Vec6 = Eigen::Matrix<S, 6, 1>;
template <class S>
using Mat6 = Eigen::Matrix<S, 6, 6>;
template <class S, int N>
using VecN = Eigen::Matrix<S, N, 1>;
/// Square N x N matrix (row-major storage is never used; column-major like Eigen's default).
template <class S, int N>
using MatN = Eigen::Matrix<S, N, N>;
/// 6 x N matrix (Jacobians), linear rows first, then angular rows.
template <class S, int N>
using Mat6N = Eigen::Matrix<S, 6, N>;

}  // namespace arbor
