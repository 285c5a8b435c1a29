// arbor::nmpc: the NLP's KKT residuals at a linearisation point, read off the delta-form QP built
// there (ocp/linearize.hpp) and multipliers in the QP's flat layout (qp/problem.hpp). At d = 0
// the QP's gradient is grad f, its constraint matrix the NLP's constraint Jacobian and its row
// bounds the constraints' distances to their bounds, so
//   stationarity     |g + A' lam_a + lam_x|_inf              (grad_w of the NLP Lagrangian)
//   primal residual  max(|b_k|, max(0, lb, -ub) of every bound and row)
//   complementarity  max |lam * distance to the bound its sign names|
// Cost: one pass over the stage matrices, O(N (nx + nu)(nx + ng)).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "arbor/qp/problem.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::nmpc {

/// The three KKT residuals (infinity norms).
template <class T>
struct KktResiduals {
  T stationarity = T(0);     ///< |grad_w L|_inf
  T primal = T(0);           ///< max violation of dynamics, bounds and constraints
  T complementarity = T(0);  ///< max |lambda * gap|
};

namespace detail {
/// Violation and complementarity of bounds lb <= 0 <= ub (delta form) with multipliers lam.
/// Plain comparisons, no libm calls: a multiplier times an infinite gap is infinite (the
/// multiplier of an absent bound), and so is one on a NaN bound (the user's variable bounds are
/// not checked before the residuals are recorded).
template <class T, class L, class U, class M>
void bound_residuals(const L& lb, const U& ub, const M& lam, KktResiduals<T>& r) {
  T primal = r.primal, comp = r.complementarity;
  for (int i = 0; i < lb.size(); ++i) {
    const T l = lb[i], u = ub[i], m = lam[i];
    primal = l > primal ? l : primal;  // (primal >= 0: max(0, lb, -ub))
    primal = -u > primal ? -u : primal;
    if (m == T(0) || l == u)
      continue;                                     // inactive, or an equality: no complementarity
    const T c = std::fabs(m * (m > T(0) ? u : l));  // |lam * distance to the bound it names|
    if (!(c <= comp))
      comp = c == c ? c : std::numeric_limits<T>::infinity();
  }
  r.primal = primal;
  r.complementarity = comp;
}
}  // namespace detail

/// KKT residuals of the NLP at the point where `qp` was built, with multipliers lam_x, lam_a in
/// the QP's flat layout (the variable bounds of `qp` must be set, in delta form).
template <class T, int N, int NX, int NU, int NG, int NGN, class LX, class LA>
KktResiduals<T> kkt_residuals(const qp::OcpQp<T, N, NX, NU, NG, NGN>& qp, const LX& lam_x,
                              const LA& lam_a) {
  using Qp = qp::OcpQp<T, N, NX, NU, NG, NGN>;
  KktResiduals<T> r;
  for (int k = 0; k <= N; ++k) {
    const auto lx = lam_x.template segment<NX>(Qp::state_offset(k));
    VecN<T, NX> gx = lx;
    if (k > 0)
      gx += lam_a.template segment<NX>(Qp::dynamics_offset(k - 1));
    if (k < N) {
      const auto& st = qp.stage[std::size_t(k)];
      const auto ld = lam_a.template segment<NX>(Qp::dynamics_offset(k));
      const auto lg = lam_a.template segment<NG>(Qp::constraint_offset(k));
      const auto lu = lam_x.template segment<NU>(Qp::input_offset(k));
      gx += st.q - st.A.transpose() * ld;
      VecN<T, NU> gu = st.r + lu - st.B.transpose() * ld;
      if constexpr (NG > 0) {  // (Eigen mis-sizes products with an empty inner dimension)
        gx += st.C.transpose() * lg;
        gu += st.D.transpose() * lg;
      }
      r.stationarity = std::fmax(r.stationarity, gu.cwiseAbs().maxCoeff());
      r.primal = std::fmax(r.primal, st.b.cwiseAbs().maxCoeff());
      detail::bound_residuals(st.lbx, st.ubx, lx, r);
      detail::bound_residuals(st.lbu, st.ubu, lu, r);
      detail::bound_residuals(st.lg, st.ug, lg, r);
    } else {
      const auto& t = qp.terminal;
      const auto lg = lam_a.template tail<NGN>();
      gx += t.q;
      if constexpr (NGN > 0)
        gx += t.C.transpose() * lg;
      detail::bound_residuals(t.lbx, t.ubx, lx, r);
      detail::bound_residuals(t.lg, t.ug, lg, r);
    }
    r.stationarity = std::fmax(r.stationarity, gx.cwiseAbs().maxCoeff());
  }
  return r;
}

/// The scale of the relative tolerances at the point where `qp` was built:
/// 1 + max(|grad f|_inf, |lambda|_inf), with multipliers lam_x, lam_a as in kkt_residuals.
template <class T, int N, int NX, int NU, int NG, int NGN, class LX, class LA>
T kkt_scale(const qp::OcpQp<T, N, NX, NU, NG, NGN>& qp, const LX& lam_x, const LA& lam_a) {
  T g = std::fmax(lam_x.cwiseAbs().maxCoeff(), lam_a.cwiseAbs().maxCoeff());
  for (const auto& st : qp.stage)
    g = std::fmax(g, std::fmax(st.q.cwiseAbs().maxCoeff(), st.r.cwiseAbs().maxCoeff()));
  return T(1) + std::fmax(g, qp.terminal.q.cwiseAbs().maxCoeff());
}

}  // namespace arbor::nmpc
