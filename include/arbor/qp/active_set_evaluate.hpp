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
  // cost's scale (an absolute epsilon let a cost scaled by 100 stall float solves, 1e4 every one;
  // issue 35); else h = 1 (see settings.hpp for why it is not the default)
  h_ = s.relative_regularisation ? be.hessian_scale() : Scalar(1);
  if (!(h_ > 0) || !std::isfinite(h_))
    h_ = Scalar(1);
  w_ = h_ / s.reg_dual;
  // a prefactorization (prefactorize()) of this very working set and weights is reused once,
  // with the row weights it computed (same matrices: same norms)
  presolved_ = 0;  // a presolve belongs to the data and iterate it saw (presolve() sets it after)
  const bool reuse = prefactored_ && w_ == pre_w_ && ws == pre_ws_;
  prefactored_ = false;
  refactor_ = !reuse;
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
  have_best_ = false;
  unbounded_candidate_ = false;
  certificate_count_ = 0;
  farkas_pending_ = false;
  stall_count_ = 0;
  stall_ref_ = inf();
  singular_drops_.fill(-1);
  next_drop_ = 0;
  cycles_ = 0;
  refining_ = false;
  pr_prev_ = inf();
  warm_first_ = false;
  exact_next_ = true;
  since_exact_ = 0;
  for (int i = 0; i < nz && !warm_first_; ++i)
    warm_first_ = one_sided(i);
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
void ActiveSetCore<Scalar, NV, NA>::evaluate(const Backend& be, bool exact, int split) {
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
  exact_ = exact;
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
  finite_ = finite;
  Scan sc;
  if (split > 0) {  // presolve(): the pass over [split, nz) kept for scan_moved()
    scan(sc, 0, split);
    pre_scan_ = Scan{};
    scan(pre_scan_, split, nz);
    merge(sc, pre_scan_);
  } else {
    scan(sc, 0, nz);
  }
  store(sc);
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::scan(Scan& sc, int from, int to) const {
  // the scalars are kept in locals (the working set is int8_t, which may alias the members)
  Scalar pscale = sc.pscale, pr = sc.pr, co = sc.co, pr_abs = sc.pr_abs, co_abs = sc.co_abs;
  Scalar sd = sc.sd, pc = sc.pc;
  int isd = sc.isd, ipc = sc.ipc;
  State spc = sc.spc;
  const State* w = ws.data();
  // one body for the bounds (n = 1, folded) and the rows: no branch on i < NV per constraint
  const auto visit = [&](auto check, int i, Scalar z, Scalar l, Scalar u, Scalar m, Scalar n) {
    if constexpr (decltype(check)::value) {
      if (!std::isfinite(z) || !std::isfinite(m)) {
        pr = inf();
        pr_abs = inf();
        return;
      }
    }
    pscale = std::max(pscale, std::abs(z) / n);
    const Scalar vl = l - z, vu = z - u;
    const Scalar va = vl > vu ? vl : vu;
    if (va > pr_abs)
      pr_abs = va;
    const Scalar v = va / n;
    if (v > pr)
      pr = v;
    const State wi = w[i];
    if (v > 0) {
      const State side = vl > vu ? State::lower : State::upper;
      if (wi != side && wi != State::equality && v > pc) {
        pc = v;
        ipc = i;
        spc = side;
      }
    }
    if (m != 0) {
      const Scalar dist =
          m > 0 ? (u < inf() ? std::abs(u - z) : inf()) : (l > -inf() ? std::abs(z - l) : inf());
      const Scalar am = std::abs(m);
      const Scalar c = am < dist ? am : dist;
      if (c > co_abs)
        co_abs = c;
      const Scalar cn = std::min(am * n, dist / n);
      if (cn > co)
        co = cn;
    }
    if (wi == State::upper || wi == State::lower) {
      const Scalar wrong = -m * side_sign<Scalar>(wi) * n;
      if (wrong > sd) {
        sd = wrong;
        isd = i;
      }
    }
  };
  const int bend = std::min(to, NV), rbeg = std::max(from, NV);
  const auto pass = [&](auto check) {
    for (int i = from; i < bend; ++i)
      visit(check, i, x(i), lbx(i), ubx(i), lam_x(i), Scalar(1));
    for (int j = rbeg - NV; j < to - NV; ++j)
      visit(check, NV + j, za_(j), lba(j), uba(j), lam_a(j), rn_(j));
  };
  if (finite_)
    pass(std::false_type{});
  else
    pass(std::true_type{});
  sc = Scan{pscale, pr, co, pr_abs, co_abs, sd, pc, isd, ipc, spc};
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::merge(Scan& a, const Scan& b) {
  // b's constraints follow a's: a maximum moves to b only when b's is strictly larger (the
  // first index wins, as in one pass)
  a.pscale = std::max(a.pscale, b.pscale);
  a.pr = std::max(a.pr, b.pr);
  a.co = std::max(a.co, b.co);
  a.pr_abs = std::max(a.pr_abs, b.pr_abs);
  a.co_abs = std::max(a.co_abs, b.co_abs);
  if (b.sd > a.sd) {
    a.sd = b.sd;
    a.isd = b.isd;
  }
  if (b.pc > a.pc) {
    a.pc = b.pc;
    a.ipc = b.ipc;
    a.spc = b.spc;
  }
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::store(const Scan& sc) {
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

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::scan_moved() {
  // only the first pre_n_ bounds moved since presolve()'s evaluate(): their pass, then the
  // rest's as it kept it (or all of it again after move_bound()); the products, du_ and the
  // scales are presolve()'s
  Scan sc;
  if (pre_rescan_) {
    scan(sc, 0, nz);
  } else {
    scan(sc, 0, pre_n_);
    merge(sc, pre_scan_);
  }
  store(sc);
  exact_ = false;  // (a loop that may end here evaluates from scratch first)
}
}  // namespace arbor::qp::detail
