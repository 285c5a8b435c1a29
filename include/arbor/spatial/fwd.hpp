// arbor: fixed-size Eigen aliases shared by the spatial and dynamics modules.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arbor {

/// Fixed-size Eigen aliases; Scalar is double, float or an AD/op-counting type.
template <class Scalar>
using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
template <class Scalar>
using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
template <class Scalar>
using Vec6 = Eigen::Matrix<Scalar, 6, 1>;
template <class Scalar>
using Mat6 = Eigen::Matrix<Scalar, 6, 6>;
template <class Scalar, int N>
using VecN = Eigen::Matrix<Scalar, N, 1>;
/// Square N x N matrix (row-major storage is never used; column-major like Eigen's default).
template <class Scalar, int N>
using MatN = Eigen::Matrix<Scalar, N, N>;
/// 6 x N matrix (Jacobians), linear rows first, then angular rows.
template <class Scalar, int N>
using Mat6N = Eigen::Matrix<Scalar, 6, N>;

}  // namespace arbor
