// arbor: DerivativeData, the caller-owned workspace of the first-order analytical derivatives
// (rnea_derivatives, aba_derivatives), used together with a Data of the same robot and scalar:
// the derivative sweeps also fill Data's placements, joint Jacobians, M and M^-1. Fixed size, no
// allocation, default constructible.
#pragma once

#include <Eigen/Core>
#include <array>

#include "arbor/dynamics/data.hpp"
#include "arbor/spatial/inertia.hpp"
#include "arbor/spatial/motion.hpp"

namespace arbor {

/// Derivative work arrays and results for robot R and scalar type Scalar_ (world frame).
template <class R, class Scalar_ = double>
struct DerivativeData {
  static constexpr int nb = R::nb;  ///< bodies
  static constexpr int nv = R::nv;  ///< DoF
  using Scalar = Scalar_;
  using Matrix = MatN<Scalar, nv>;
  using RowBlock = typename Data<R, Scalar>::RowBlock;

  Matrix dtau_dq;                         ///< d tau / d q (rnea_derivatives)
  Matrix dtau_dv;                         ///< d tau / d v (rnea_derivatives; d tau / d a is M)
  Matrix ddq_dq;                          ///< d ddq / d q (aba_derivatives)
  Matrix ddq_dv;                          ///< d ddq / d v (aba_derivatives; d ddq / d tau is Minv)
  std::array<Motion<Scalar>, nb> ov;      ///< body spatial velocities (world frame)
  std::array<Motion<Scalar>, nb> oa;      ///< body spatial accelerations + gravity (world frame)
  std::array<Motion<Scalar>, nb> dS;      ///< v_parent x S: d/dt of each joint's world column
  std::array<Motion<Scalar>, nb> ddS;     ///< a_parent x S + v_parent x dS (world frame)
  std::array<Inertia<Scalar>, nb> oYcrb;  ///< composite inertias (world frame)
  std::array<spatial::InertiaRate<Scalar>, nb> oYdot;  ///< their time derivatives (world frame)
  std::array<Force<Scalar>, nb> oh;                    ///< composite momenta (world frame)
  std::array<Force<Scalar>, nb> of;  ///< composite forces: subtree's net force (world frame)
  RowBlock dP;                       ///< column j: Ycrb_j S_j (world; column j of M)
  RowBlock dQ;                       ///< column j: 2 B_j^T S_j (world; Coriolis-like term)
  RowBlock dG;                       ///< column j: d f_j / d q_j for the ancestors' rows
  RowBlock dH;                       ///< column j: d f_j / d v_j for the ancestors' rows
};

}  // namespace arbor
