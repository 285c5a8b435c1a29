// arbor::qp::detail: the start of a solve (begin(): working set from the multipliers, row
// weights) and the residuals of the termination test (evaluate(): the products A x, H x and the
// stationarity residual, then one pass over the constraints), active_set.hpp's method.
// O(NV + NA) per evaluation plus the products with H and A when computed from scratch.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "arbor/qp/active_set_core.hpp"
#include "arbor/qp/backend.hpp"
#include "arbor/qp/prepared_start.hpp"
#include "arbor/qp/residual_scan.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp::detail {

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::begin(Backend& be, const QpSettings<Scalar>& s) {
  ARBOR_ASSERT(s.reg_primal > 0 && s.reg_dual > 0, "regularisations must be positive");
  // a non-finite entry anywhere in the iterate: a cold start (v 0 is NaN exactly for +-inf and
  // NaN: one vectorised sum instead of a test per entry)
  const Scalar zero = (x.array() * Scalar(0)).sum() + (lam_x.array() * Scalar(0)).sum() +
                      (lam_a.array() * Scalar(0)).sum();
  if (!(zero == zero))
    cold_start();
  working_set_from_multipliers();
  delta_ = s.reg_primal;
  // with relative_regularisation, epsilon relative to the curvature: w = h / reg_dual with h the
  // largest |H_ii| (1 for an LP), so that the weights dominate H by the same factor whatever the
  // cost's scale (with an absolute epsilon, float solves of a cost scaled by 100 stall); else
  // h = 1 (see settings.hpp for why it is not the default)
  h_ = s.relative_regularisation ? be.hessian_scale() : Scalar(1);
  if (!(h_ > 0) || !std::isfinite(h_))
    h_ = Scalar(1);
  w_ = h_ / s.reg_dual;
  // a prefactorization (prefactorize()) of this very working set and weights is reused once,
  // with the row weights it computed (same matrices: same norms)
  note_change();  // (the working set and the factorization are this solve's now)
  const bool reuse = factor_ == Factor::prepared && w_ == pre_w_ && ws == pre_ws_;
  factor_ = reuse ? Factor::current : Factor::out_of_date;
  if (reuse)
    return reset_loop();
  be.mark_all();
  // row weights h / (eps |a_j|^2): the regularisation acts on normalised rows, so rows with
  // small coefficients (a linearised path constraint) converge as fast as bounds
  be.row_norms_sq(wa_);
  for (int j = 0; j < NA; ++j) {
    rn_(j) = wa_(j) > 0 ? std::sqrt(wa_(j)) : Scalar(1);
    wa_(j) = wa_(j) > 0 ? w_ / wa_(j) : w_;
  }
  reset_loop();
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::reset_loop() {
  pending_ = -1;
  pending_ws_ = State::inactive;
  best_ = inf();
  unbounded_candidate_ = false;
  certificate_count_ = 0;
  farkas_pending_ = false;
  stall_count_ = 0;
  stall_ref_ = inf();
  singular_drops_.fill(-1);
  next_drop_ = 0;
  cycles_ = 0;
  pr_prev_ = inf();
  next_products_ = Products::from_scratch;
  since_exact_ = 0;
  bool warm = false;
  for (int i = 0; i < nz && !warm; ++i)
    warm = one_sided(i);
  previous_ = warm ? PreviousStep::none_warm : PreviousStep::none;
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::working_set_from_multipliers() {
  // one body for the bounds and the rows, through pointers (the working set is int8_t, which
  // may alias the members): no branch on i < NV per constraint
  const auto pass = [](int n, const Scalar* lo, const Scalar* hi, Scalar* lam, State* w) {
    for (int i = 0; i < n; ++i) {
      const Scalar l = lo[i], u = hi[i], m = lam[i];
      if (l == u) {
        w[i] = State::equality;
      } else if (m > 0 && u < inf()) {
        w[i] = State::upper;
      } else if (m < 0 && l > -inf()) {
        w[i] = State::lower;
      } else {
        w[i] = State::inactive;
        lam[i] = 0;
      }
    }
  };
  pass(NV, lbx.data(), ubx.data(), lam_x.data(), ws.data());
  pass(NA, lba.data(), uba.data(), lam_a.data(), ws.data() + NV);
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::evaluate(const Backend& be, bool exact, Prepared* kept) {
  if (exact) {
    // A x and H x vanish at x = 0 (the NMPC's QP starts every sample there): no product (the
    // matrices are finite: update() checked them, or its caller, Finiteness::assumed; a sum of
    // magnitudes is 0 only when every entry is, NaN and infinities included)
    if (x.cwiseAbs().sum() == Scalar(0)) {
      za_.setZero();
      hx_.setZero();
    } else {
      be.cons_mul(x, za_);
      be.hess_mul(x, hx_);
    }
    be.cons_tmul(lam_a, r_);
    r_ += hx_ + g + lam_x;
    since_exact_ = 0;
  }
  products_ = exact ? Products::from_scratch : Products::updated;
  du_ = r_.size() > 0 ? r_.cwiseAbs().maxCoeff() : Scalar(0);
  if (!std::isfinite(du_))
    du_ = inf();
  // Whether every entry the passes below read is finite (x 0 is NaN for +-inf and NaN; one
  // vectorised sum): then they skip their per-entry tests, whose results are known.
  const Scalar zero = (x.array() * Scalar(0)).sum() + (lam_x.array() * Scalar(0)).sum() +
                      (za_.array() * Scalar(0)).sum() + (lam_a.array() * Scalar(0)).sum() +
                      (hx_.array() * Scalar(0)).sum() + (g.array() * Scalar(0)).sum() +
                      (r_.array() * Scalar(0)).sum();
  const bool finite = zero == zero;
  // scales of the relative tolerances: |z|_inf and the largest term of the stationarity sum
  Scalar dscale = 1;
  if (finite && NV > 0) {  // the same maxima, by vectorised reductions (exact on finite entries)
    dscale = std::max(dscale, hx_.cwiseAbs().maxCoeff());
    dscale = std::max(dscale, g.cwiseAbs().maxCoeff());
    dscale = std::max(dscale, (r_ - hx_ - g).cwiseAbs().maxCoeff());
  } else {
    for (int i = 0; i < NV; ++i) {  // (std::max ignores a NaN term)
      dscale = std::max(dscale, std::abs(hx_(i)));
      dscale = std::max(dscale, std::abs(g(i)));
      dscale = std::max(dscale, std::abs(r_(i) - hx_(i) - g(i)));
    }
  }
  du_scale_ = dscale;
  ResidualScan<Scalar> sc;
  if (kept != nullptr) {  // prepare_start(): the pass over [n, nz) kept for scan_moved()
    sc.pass(values(), 0, kept->n_, finite);
    kept->rest_ = ResidualScan<Scalar>{};
    kept->rest_.pass(values(), kept->n_, nz, finite);
    kept->finite_ = finite;
    sc.merge(kept->rest_);
  } else {
    sc.pass(values(), 0, nz, finite);
  }
  store(sc);
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::store(const ResidualScan<Scalar>& sc) {
  pr_scale_ = sc.pscale + Scalar(1);
  pr_ = sc.pr;
  co_ = sc.co;
  pr_abs_ = sc.pr_abs;
  co_abs_ = sc.co_abs;
  sd_ = sc.sd;
  isd_ = sc.isd;
  pc_ = sc.pc;
  ipc_ = sc.ipc;
  spc_ = sc.spc;
}

}  // namespace arbor::qp::detail
