// arbor: SecondOrderData, the caller-owned workspace of the contracted second-order derivatives
// (rnea_second_order_derivatives, aba_second_order_derivatives), used together with a Data of the
// same robot and scalar (and, for forward dynamics, a DerivativeData). It holds the 3n x 3n
// Hessian of lambda' ID or lambda' FD, its gradient, and O(n) world-frame work arrays. Fixed size,
// no allocation, default constructible.
#pragma once

#include <Eigen/Core>
#include <array>

#include "arbor/dynamics/data.hpp"
#include "arbor/spatial/inertia.hpp"
#include "arbor/spatial/motion.hpp"

namespace arbor {

/// Contracted second-order derivative work arrays and results for robot R and scalar Scalar_.
/// Body quantities are in the world frame; see derivatives/rnea_second_order.hpp for their meaning.
template <class R, class Scalar_ = double>
struct SecondOrderData {
  static constexpr int nb = R::nb;      ///< bodies
  static constexpr int nv = R::nv;      ///< DoF
  static constexpr int nz = 3 * R::nv;  ///< inputs z = (q, v, a) or x = (q, v, tau)
  using Scalar = Scalar_;
  using Hessian = MatN<Scalar, nz>;
  using Gradient = VecN<Scalar, nz>;
  using RowBlock = typename Data<R, Scalar>::RowBlock;

  Hessian hessian;                      ///< d^2 (lambda' F) / dz^2, full symmetric (F = ID or FD)
  Gradient gradient;                    ///< d (lambda' F) / dz
  VecN<Scalar, nv> mu;                  ///< M^-1 lambda (aba_second_order_derivatives)
  Eigen::Matrix<Scalar, nv, 2 * nv> C;  ///< d2(mu' ID)/dq da times d ddq / d(q, v) (FD only)
  MatN<Scalar, nv> B;                   ///< d2(mu' ID)/dq da times M^-1 (FD only)
  std::array<Motion<Scalar>, nb> ov;    ///< body velocities (joint rates v)
  std::array<Motion<Scalar>, nb> omu;   ///< body velocities for joint rates lambda
  std::array<Motion<Scalar>, nb> oa;    ///< body accelerations, gravity included
  std::array<Motion<Scalar>, nb> dS;    ///< v_parent x S
  std::array<Motion<Scalar>, nb> dM;    ///< mu_parent x S
  std::array<Motion<Scalar>, nb> ddS;   ///< a_parent x S + v_parent x dS
  std::array<Inertia<Scalar>, nb> Y;    ///< composite inertias
  std::array<spatial::InertiaRate<Scalar>, nb> Yd;   ///< sum of v_k x* I_k - I_k v_k x
  std::array<spatial::InertiaRate<Scalar>, nb> Ydm;  ///< sum of mu_k x* I_k - I_k mu_k x
  std::array<Force<Scalar>, nb> h;                   ///< composite momenta sum I_k v_k
  std::array<Force<Scalar>, nb> L;                   ///< sum I_k mu_k
  std::array<Force<Scalar>, nb> N;  ///< sum v_k x* I_k mu_k - mu_k x* I_k v_k - I_k (v_k x mu_k)
  std::array<Force<Scalar>, nb> F;  ///< composite net forces sum I_k a_k + v_k x* I_k v_k
  RowBlock Km;                      ///< per joint j: d psi_j / d mu_parent (psi_j = d phi/d q_j)
  RowBlock Kt;                      ///< per joint j: d psi_j / d v_parent + v_parent x* Ka_j
  RowBlock Ka;                      ///< per joint j: d psi_j / d a_parent
  RowBlock Wm;                      ///< per joint j: d omega_j / d mu_parent (omega = d phi/d v_j)
  RowBlock Wv;                      ///< per joint j: d omega_j / d v_parent
  RowBlock P;                       ///< per joint j: Y_j S_j (d chi_j / d mu_parent)
};

}  // namespace arbor
