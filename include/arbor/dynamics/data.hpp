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
  world,                ///< world frame, at the world origin (spatial velocity)
  local,                ///< the frame itself
  local_world_aligned,  ///< at the frame origin, with world axes
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

  // ---- first-order derivatives (include/arbor/derivatives) -----------------------------------
  /// 6 x nv work block, row-major (rows contiguous; the derivative sweeps run along rows).
  using RowBlock = Eigen::Matrix<S, 6, nv, (nv == 1 ? Eigen::ColMajor : Eigen::RowMajor)>;
  Matrix dtau_dq;                    ///< d tau / d q (rnea_derivatives)
  Matrix dtau_dv;                    ///< d tau / d v (rnea_derivatives; d tau / d a is M)
  Matrix ddq_dq;                     ///< d ddq / d q (aba_derivatives)
  Matrix ddq_dv;                     ///< d ddq / d v (aba_derivatives; d ddq / d tau is Minv)
  std::array<Motion<S>, nb> ov;      ///< body spatial velocities (world frame)
  std::array<Motion<S>, nb> oa;      ///< body spatial accelerations + gravity (world frame)
  std::array<Motion<S>, nb> dS;      ///< v_parent x S: d/dt of each joint's world column
  std::array<Motion<S>, nb> ddS;     ///< a_parent x S + v_parent x dS (world frame)
  std::array<Inertia<S>, nb> oYcrb;  ///< composite inertias (world frame)
  std::array<spatial::InertiaRate<S>, nb> oYdot;  ///< their time derivatives (world frame)
  std::array<Force<S>, nb> oh;                    ///< composite momenta (world frame)
  std::array<Force<S>, nb> of;  ///< composite forces: subtree's net force (world frame)
  RowBlock dP;                  ///< column j: Ycrb_j S_j (world; column j of M)
  RowBlock dQ;                  ///< column j: 2 B_j^T S_j (world; Coriolis-like term)
  RowBlock dG;                  ///< column j: d f_j / d q_j for the ancestors' rows
  RowBlock dH;                  ///< column j: d f_j / d v_j for the ancestors' rows
};

}  // namespace arbor
