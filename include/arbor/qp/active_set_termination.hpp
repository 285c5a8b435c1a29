// arbor::qp::detail: when the active-set iteration ends (converged_or_stopped()), the Farkas and
// unboundedness certificates, and the returned point with its residuals (finish()),
// active_set.hpp's method. O(NV + NA) per test plus a product with A' for a certificate.
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
bool ActiveSetCore<Scalar, NV, NA>::converged_or_stopped(const QpSettings<Scalar>& s, int it,
                                                         QpStatus& status) {
  if (!std::isfinite(pr_) || !std::isfinite(du_)) {
    status = QpStatus::non_finite;
    return true;
  }
  const Scalar merit = merit_of(s);
  if (merit < best_) {
    best_ = merit;
    best_x_ = x;
    best_lam_x_ = lam_x;
    best_lam_a_ = lam_a;
  }
  if (merit <= 1) {
    status = QpStatus::solved;
    return true;
  }
  // (feasibility of an unbounded candidate is judged without the scale, which its long step
  // has inflated)
  if (unbounded_candidate_ && pr_ <= s.tol_primal) {
    status = QpStatus::unbounded;
    return true;
  }
  unbounded_candidate_ = false;
  // a Farkas certificate on consecutive steps (a single step could be a transient)
  if (certificate_count_ >= 2) {
    status = QpStatus::infeasible;
    return true;
  }
  // no working-set change and no progress: the rule has nothing left to change although the
  // termination test fails (round-off floor above the tolerances, or inconsistent tolerances)
  if (!refining() || merit < Scalar(0.9) * stall_ref_) {
    stall_ref_ = merit;
    stall_count_ = 0;
  } else if (++stall_count_ >= kStallIterations) {
    status = QpStatus::stalled;
    return true;
  }
  return it >= s.max_iter;  // status stays iteration_limit
}
template <typename Scalar, int NV, int NA>
template <typename Backend>
QpStatus ActiveSetCore<Scalar, NV, NA>::finish(const Backend& be, const QpSettings<Scalar>& s,
                                               SolveInfo<Scalar>& info, QpStatus status) {
  const bool keep_last = status == QpStatus::iteration_limit && s.last_iterate_at_cap;
  if (status != QpStatus::solved && status != QpStatus::infeasible &&
      status != QpStatus::unbounded && have_best() && !keep_last) {  // iteration_limit, stalled
    x = best_x_;
    lam_x = best_lam_x_;
    lam_a = best_lam_a_;
    working_set_from_multipliers();
    evaluate(be);
  }
  // explicit final check on the original data (residuals of the returned iterate)
  info.primal_residual = pr_abs_;
  info.dual_residual = du_;
  info.complementarity = co_abs_;
  info.objective = Scalar(0.5) * x.dot(hx_) + g.dot(x);
  info.merit = merit_of(s);
  int na_ws = 0;
  for (int i = 0; i < nz; ++i)
    na_ws += ws[i] != State::inactive ? 1 : 0;
  info.active_constraints = na_ws;
  info.cycling_refusals = cycles_;
  if (status == QpStatus::solved && !(merit_of(s) <= 1))
    status = QpStatus::iteration_limit;
  return status;
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
bool ActiveSetCore<Scalar, NV, NA>::farkas_step(const Backend& be, const QpSettings<Scalar>& s,
                                                Scalar pr) {
  // y = dlam (the direction in which the multipliers move; on an inconsistent working set they
  // grow along a null vector of [I A']). Entries whose side has an infinite bound are left out.
  // For every x: y'z = e'x with e = y_x + A' y_a, and for a feasible x: y'z <= sigma =
  // sum_{y_i > 0} ub_i y_i + sum_{y_i < 0} lb_i y_i. With y normalised per constraint
  // (sum |y_i| |a_i| = 1), -sigma is a lower bound on the largest per-constraint violation of
  // any x with e'x = 0, so sigma < 0 with |e|_1 |x| negligible proves that no point within
  // 1 / tol_certificate times the iterate's scale is feasible. Scale-invariant (rows, cost).
  if (!(pr > s.tol_primal))
    return false;  // the iterate is feasible: no certificate to look for
  Scalar ny = 0, sigma = 0, bscale = 1;
  const auto add = [&](Scalar y, Scalar b, Scalar rn) {
    ny += std::abs(y) * rn;
    sigma += y * b;
    bscale = std::max(bscale, std::abs(b) / rn);
  };
  // the bounds, then the rows, reading their arrays directly (no per-entry test of the kind);
  // a zero entry (every constraint the step leaves alone) contributes nothing
  for (int i = 0; i < NV; ++i) {
    const Scalar y = farkas_entry(dlam_x_(i), lbx(i), ubx(i));
    if (y != 0)
      add(y, y > 0 ? ubx(i) : lbx(i), Scalar(1));
  }
  for (int j = 0; j < NA; ++j) {
    const Scalar y = farkas_entry(dlam_a_(j), lba(j), uba(j));
    tmpa_(j) = y;
    if (y != 0)
      add(y, y > 0 ? uba(j) : lba(j), rn_(j));
  }
  if (!(ny > 0) || !std::isfinite(ny) || !std::isfinite(sigma))
    return false;
  sigma /= ny;
  // the violation it proves, against the primal tolerance on the scale of the bounds involved
  // (not of the iterate, which a long step along a free direction may have inflated)
  if (!(sigma < -Scalar(10) * s.tol_primal * (Scalar(1) + bscale)))
    return false;
  // e = A' y_a + y_x, accumulated in tmpv_ (y_x is cleaned again entry by entry)
  be.cons_tmul(tmpa_, tmpv_);
  Scalar e1 = 0;
  for (int i = 0; i < NV; ++i)
    e1 += std::abs(tmpv_(i) + farkas_entry(dlam_x_(i), lbx(i), ubx(i)));
  return e1 / ny * (Scalar(1) + bscale) <= s.tol_certificate * -sigma;
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
bool ActiveSetCore<Scalar, NV, NA>::unboundedness_certificate(const Backend& be,
                                                              const QpSettings<Scalar>& s) {
  // d = dx / |dx|_inf must have H d ~ 0, g'd < 0 and stay in the recession cone of the bounds.
  const Scalar nd = dx_.cwiseAbs().maxCoeff();
  if (!(nd > 0) || !std::isfinite(nd))
    return false;
  const Scalar tol = s.tol_certificate;
  for (int i = 0; i < nz; ++i) {
    const Scalar d = dzval(i) / (nd * rnorm(i));
    if (ub(i) < inf() && d > tol)
      return false;
    if (lb(i) > -inf() && d < -tol)
      return false;
  }
  VecV& hd = tmpv_;
  be.hess_mul(dx_, hd);
  if (hd.cwiseAbs().maxCoeff() / nd > tol * (Scalar(1) + hx_.cwiseAbs().maxCoeff()))
    return false;
  return g.dot(dx_) / nd < -tol * (Scalar(1) + g.cwiseAbs().maxCoeff());
}

}  // namespace arbor::qp::detail
