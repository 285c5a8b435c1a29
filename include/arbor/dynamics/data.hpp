// arbor: Data, the caller-owned workspace of the rigid-body dynamics algorithms (kinematics,
// Jacobians, rnea, aba, crba, minverse). Fixed size, no allocation, default constructible; one
// per robot and scalar type, reused across calls. The derivative routines need a second
// workspace, DerivativeData (derivatives/derivative_data.hpp), so that firmware which runs only
// the dynamics does not pay for the derivatives' arrays.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cstddef>

#include "arbor/model/robot.hpp"
#include "arbor/spatial/articulated_inertia.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/inertia.hpp"
#include "arbor/spatial/joint_state.hpp"
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
  world,                ///< world frame, at the world origin (spatial velocity)
  local,                ///< the frame itself
  local_world_aligned,  ///< at the frame origin, with world axes
};

/// Short name of a reference frame, for logs and test messages.
constexpr const char* to_string(ReferenceFrame rf) {
  switch (rf) {
    case ReferenceFrame::world:
      return "world";
    case ReferenceFrame::local:
      return "local";
    case ReferenceFrame::local_world_aligned:
      return "local_world_aligned";
  }
  return "unknown";
}

/// A payload attached to an operational frame at run time (dynamics/payload.hpp: set_payload,
/// clear_payload): its spatial inertia in the frame's body frame, which the inertia-dependent
/// algorithms add to that body's constant inertia. Inactive by default.
template <class Scalar>
struct Payload {
  bool active = false;  ///< set by set_payload on a moving body; the algorithms test only this
  int frame = -1;       ///< operational frame it is attached to
  int body = -1;        ///< the frame's body (-1: the fixed base)
  Inertia<Scalar> Y = Inertia<Scalar>::Zero();  ///< spatial inertia in the body frame (Y.m: mass)
};

/// External forces on robot R, one per body, each in its body frame.
template <class R, class Scalar>
using ForceArray = std::array<Force<Scalar>, std::size_t(R::nb)>;

/// Workspace of the dynamics algorithms for robot R and scalar type Scalar_. Body quantities are
/// in body frames (as in Pinocchio's local convention) unless named o* (world).
template <class R, class Scalar_ = double>
struct Data {
  static constexpr int nb = R::nb;  ///< bodies
  static constexpr int nv = R::nv;  ///< DoF
  static constexpr int nf = R::nf;  ///< operational frames
  using Scalar = Scalar_;
  using Vector = VecN<Scalar, nv>;
  using Matrix = MatN<Scalar, nv>;
  using Matrix6x = Mat6N<Scalar, nv>;
  /// External forces, one per body, in the body frame.
  using ForceArray = arbor::ForceArray<R, Scalar>;
  /// 6 x nv work block, row-major when nv > 1 (rows contiguous: sweeps run along rows).
  using RowBlock = Eigen::Matrix<Scalar, 6, nv, (nv == 1 ? Eigen::ColMajor : Eigen::RowMajor)>;

  std::array<JointState<Scalar>, nb> joint;  ///< cos/sin or displacement of each joint
  std::array<SE3<Scalar>, nb> liMi;          ///< placement of body i in its parent body
  std::array<SE3<Scalar>, nb> oMi;           ///< placement of body i in the world
  std::array<SE3<Scalar>, nf> oMf;           ///< placement of each operational frame in the world
  std::array<Motion<Scalar>, nb> v;          ///< body spatial velocities (body frame)
  std::array<Motion<Scalar>, nb> a;  ///< body spatial accelerations (body frame; rnea: + gravity)
  std::array<Force<Scalar>, nb> f;   ///< forces transmitted by each joint (body frame)
  Vector tau;                        ///< joint torques (rnea, gravity, nle)
  Vector ddq;                        ///< joint accelerations (aba)
  Matrix M;                          ///< joint-space inertia matrix (crba), full symmetric
  Matrix Minv;                       ///< inverse of M (minverse), full symmetric
  Matrix6x J;                        ///< joint Jacobians in the world frame (columns = oMi S)
  std::array<Inertia<Scalar>, nb> Ycrb;  ///< composite rigid-body inertias (crba, body frame)
  std::array<spatial::ArticulatedInertia<Scalar>, nb> Yaba;  ///< articulated inertias (aba)
  std::array<Force<Scalar>, nb> pA;                          ///< articulated bias forces (aba)
  std::array<Force<Scalar>, nb> U;  ///< Yaba S of each joint (aba, minverse)
  std::array<Scalar, nb> Dinv;      ///< 1 / (S^T Yaba S) (aba, minverse)
  std::array<Scalar, nb> u;         ///< tau - S^T pA (aba)
  std::array<RowBlock, nb> Fminv;   ///< per-body 6 x nv work blocks of crba and minverse
  Eigen::LLT<Matrix> llt;           ///< Cholesky factor of M (cholesky_factor)
  Payload<Scalar> payload;          ///< run-time payload (set_payload); inactive by default
};

}  // namespace arbor
