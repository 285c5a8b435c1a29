// arbor: the fixed-size workspace of the rigid-body algorithms. No allocation, default
// constructible; one Data per robot and scalar type, reused across calls.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>

#include "arbor/model/robot.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/inertia.hpp"
#include "arbor/spatial/joint.hpp"
#include "arbor/spatial/motion.hpp"
#include "arbor/spatial/se3.hpp"

namespace arbor {

using spatial::Force;
using spatial::Inertia;
using spatial::JointState;
using spatial::Motion;
using spatial::SE3;

/// Frame in which a Jacobian or a frame velocity is expressed (Pinocchio's ReferenceFrame).
enum class ReferenceFrame {
  World,              ///< world frame, at the world origin (spatial velocity)
  Local,              ///< the frame itself
  LocalWorldAligned,  ///< at the frame origin, with world axes
};

/// Workspace of every algorithm for robot R and scalar S. Body quantities are in body frames
/// (as in Pinocchio's local convention) unless named o* (world).
template <class R, class S = double>
struct Data {
  static constexpr int nb = R::nb;  ///< bodies
  static constexpr int nv = R::nv;  ///< DoF
  static constexpr int nf = R::nf;  ///< operational frames
  using Scalar = S;
  using Vector = VecN<S, nv>;
  using Matrix = MatN<S, nv>;
  using Matrix6x = Mat6N<S, nv>;
  /// External forces, one per body, in the body frame.
  using ForceArray = std::array<Force<S>, std::size_t(nb)>;

  std::array<JointState<S>, nb> joint;  ///< cos/sin or displacement of each joint
  std::array<SE3<S>, nb> liMi;          ///< placement of body i in its parent body
  std::array<SE3<S>, nb> oMi;           ///< placement of body i in the world
  std::array<SE3<S>, nf> oMf;           ///< placement of each operational frame in the world
  std::array<Motion<S>, nb> v;          ///< body spatial velocities (body frame)
  std::array<Motion<S>, nb> a;      ///< body spatial accelerations (body frame; rnea: + gravity)
  std::array<Force<S>, nb> f;       ///< forces transmitted by each joint (body frame)
  Vector tau;                       ///< joint torques (rnea, gravity, nle)
  Vector ddq;                       ///< joint accelerations (aba)
  Matrix M;                         ///< joint-space inertia matrix (crba), full symmetric
  Matrix Minv;                      ///< inverse of M (minverse), full symmetric
  Matrix6x J;                       ///< joint Jacobians in the world frame (columns = oMi S)
  std::array<Inertia<S>, nb> Ycrb;  ///< composite rigid-body inertias (crba, body frame)
  std::array<spatial::ArticulatedInertia<S>, nb> Yaba;  ///< articulated inertias (aba, minverse)
  std::array<Force<S>, nb> pA;                          ///< articulated bias forces (aba)
  std::array<Force<S>, nb> U;                           ///< Yaba S of each joint (aba, minverse)
  std::array<S, nb> Dinv;                               ///< 1 / (S^T Yaba S) (aba, minverse)
  std::array<S, nb> u;                                  ///< tau - S^T pA (aba)
  /// Per-body 6 x nv work blocks of crba and minverse (row-major: rows are contiguous).
  std::array<Eigen::Matrix<S, 6, nv, (nv == 1 ? Eigen::ColMajor : Eigen::RowMajor)>, nb> Fminv;
  Eigen::LLT<Matrix> llt;  ///< Cholesky factor of M (cholesky_solve)
};

}  // namespace arbor
