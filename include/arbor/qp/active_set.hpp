// arbor::qp::detail: the primal-dual active-set logic shared by the dense and the OCP solvers.
//
// Problem (flat form; the OCP solver flattens its stages into it):
//   min 1/2 x'Hx + g'x   s.t.  lbx <= x <= ubx,  lba <= A x <= uba,   x in R^NV, A x in R^NA.
// Stack z = [x; A x] (NZ = NV + NA) with one multiplier lam = [lam_x; lam_a]; stationarity reads
// H x + g + lam_x + A' lam_a = 0; lam_i > 0 means "upper bound active", lam_i < 0 "lower active".
//
// Method (in the style of CasADi's QRQP primal-dual active-set solver; our own implementation):
// - An explicit int8 working set ws (ConstraintState in backend.hpp: inactive, lower, upper,
//   equality) is built from the multipliers' signs at the start of every solve (warm start =
//   keep x and lam), and kept consistent afterwards: an inactive constraint has lam_i == 0
//   exactly.
// - Each iteration evaluates the residuals and makes at most ONE working-set change: a pending
//   change from the last ratio test, else, if the (scaled) primal error dominates, the most
//   violated constraint is added on its violated side, else the active constraint whose
//   multiplier has the most wrong sign is dropped.
// - The step goes to the solution of the equality-constrained QP of the working set, with a
//   proximal regularisation centred at the current iterate (delta = reg_primal on x,
//   epsilon = reg_dual on the active multipliers):
//     (H + delta I + A_W' E A_W) dx = -(H x + g + A' lam) - A_W' E (A_W x - t_W)
//     dlam_W = E (A_W (x + dx) - t_W),   dlam_i = 0 off the working set,
//   with E = diag(1 / (eps |a_i|^2)) (rows normalised; |a_i| = 1 for bounds).
//   The matrix is positive definite for any convex H, whatever the working set: redundant or
//   linearly dependent active constraints and directions of zero curvature (states without
//   cost, LPs) never make it singular. Along a zero-curvature direction the step is long
//   (~ gradient / delta) and the ratio test stops it at the first blocking constraint: this is
//   QRQP's null-space step, obtained without predicting the singularity. Because the proximal
//   terms are centred at the iterate, a fixed point is an exact KKT point; repeated iterations
//   on an unchanged working set reuse the factorization and act as iterative refinement.
// - When the primal error stalls on an unchanged working set (a nearly inconsistent one), the
//   multipliers are moved along their step to the first active one that reaches zero, which is
//   dropped (QRQP's singular step in multiplier space).
// - Ratio test on tau in [0, 1]: inactive constraints may not cross their bound by more than
//   max(tol_primal, current max violation) (primal blocking -> pending add), active multipliers
//   of the right sign may not cross zero (dual break point -> pending drop).
// - Termination by an explicit check on the original data: primal feasibility, stationarity and
//   complementarity (min(|lam_i|, distance to its bound)), with tolerances relative to the data
//   scale (settings.hpp). A Farkas certificate (y = lam/|lam|
//   with A' y ~ 0 and negative support of the bounds) on three consecutive iterates gives
//   `infeasible` (an inconsistent working set makes lam grow like 1/epsilon); a full step along a
//   zero-curvature descent direction that no constraint blocks gives `unbounded`; the iteration
//   cap returns the best iterate seen, with its residuals.
// Memory of this part: about 11 NV + 8 NA scalars and NV + NA bytes. Cost per iteration: O(NV +
// NA) here plus one backend solve, and a (partial) refactorization after a working-set change.
// The linear algebra lives in a backend satisfying ActiveSetBackend (backend.hpp). solve() runs
// the steps below in this order, each a member function: begin() once, then per iteration
// evaluate(), converged_or_stopped(), change_working_set(), refactorize(), compute_step(),
// ratio_test(), singular_dual_step(), take_step(); finish() once.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "arbor/core/config.hpp"
#include "arbor/qp/backend.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp::detail {

/// Iterate, bounds and workspace of the active-set method (sizes fixed at compile time).
template <typename Scalar, int NV, int NA>
class ActiveSetCore {
 public:
  static constexpr int nv = NV;       ///< number of variables
  static constexpr int na = NA;       ///< number of general constraint rows
  static constexpr int nz = NV + NA;  ///< number of constraints (bounds first)
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;

  VecV lbx, ubx;                         ///< variable bounds (may be +-inf)
  VecA lba, uba;                         ///< constraint-row bounds (may be +-inf)
  VecV g;                                ///< linear cost
  VecV x;                                ///< primal iterate (warm start in, solution out)
  VecV lam_x;                            ///< multipliers of the variable bounds
  VecA lam_a;                            ///< multipliers of the constraint rows
  std::array<ConstraintState, nz> ws{};  ///< working set

  /// x = projection of 0 onto the bounds, all multipliers zero.
  void cold_start() {
    for (int i = 0; i < NV; ++i)
      x(i) = clamp(Scalar(0), lbx(i), ubx(i));
    lam_x.setZero();
    lam_a.setZero();
  }

  /// Runs the method from the current (x, lam); fills info; returns the status.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  [[nodiscard]] QpStatus solve(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info) {
    info = SolveInfo<Scalar>{};
    begin(be, s);
    QpStatus status = QpStatus::iteration_limit;
    for (int it = 0;; ++it) {
      evaluate(be);
      if (converged_or_stopped(s, it, status))
        break;
      info.iterations = it + 1;
      const bool changed = change_working_set(be, s, info);
      if (!refactorize(be, s, info)) {
        status = QpStatus::non_convex;
        break;
      }
      compute_step(be);
      const Scalar tau = ratio_test(s);
      const Scalar tau_dual = singular_dual_step(s, tau, changed);
      take_step(be, s, tau, tau_dual, changed);
    }
    return finish(be, s, info, status);
  }

 private:
  using State = ConstraintState;
  static constexpr Scalar inf() { return std::numeric_limits<Scalar>::infinity(); }
  static Scalar clamp(Scalar v, Scalar lo, Scalar hi) { return v < lo ? lo : (v > hi ? hi : v); }

  Scalar lb(int i) const { return i < NV ? lbx(i) : lba(i - NV); }
  Scalar ub(int i) const { return i < NV ? ubx(i) : uba(i - NV); }
  Scalar zval(int i) const { return i < NV ? x(i) : za_(i - NV); }
  Scalar dzval(int i) const { return i < NV ? dx_(i) : dza_(i - NV); }
  Scalar& lam(int i) { return i < NV ? lam_x(i) : lam_a(i - NV); }
  Scalar lam(int i) const { return i < NV ? lam_x(i) : lam_a(i - NV); }
  Scalar dlam(int i) const { return i < NV ? dlam_x_(i) : dlam_a_(i - NV); }
  /// Target value of an active constraint.
  Scalar target(int i) const { return ws[i] == State::lower ? lb(i) : ub(i); }
  /// Active on one side (not inactive, not an equality).
  bool one_sided(int i) const { return ws[i] == State::upper || ws[i] == State::lower; }

  // ---- the steps of solve()
  /// Repairs a non-finite iterate, builds the working set and the row weights, resets the loop.
  template <typename Backend>
  void begin(Backend& be, const QpSettings<Scalar>& s);
  /// Working set from the multipliers' signs; zeroes multipliers that cannot be active.
  void working_set_from_multipliers();
  /// z = A x, hx = H x, r = H x + g + A' lam and the scalar residuals below.
  template <typename Backend>
  void evaluate(const Backend& be);
  /// Keeps the best iterate; true (with the status) when the loop must end here.
  bool converged_or_stopped(const QpSettings<Scalar>& s, int it, QpStatus& status);
  /// Makes at most one working-set change; true when one was made.
  template <typename Backend>
  bool change_working_set(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info);
  /// Refactorizes after a change, raising delta on pivot failures; false when it exceeds its cap.
  template <typename Backend>
  bool refactorize(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info);
  /// (dx, dz, dlam): the step to the regularised equality-constrained QP of the working set.
  template <typename Backend>
  void compute_step(const Backend& be);
  /// Longest step in [0, 1] keeping constraints within tolerance and multiplier signs; sets the
  /// pending change of the blocking constraint.
  Scalar ratio_test(const QpSettings<Scalar>& s);
  /// Multiplier step length (tau, or longer when a stalled, inconsistent working set must shed
  /// a constraint: QRQP's singular step in multiplier space).
  Scalar singular_dual_step(const QpSettings<Scalar>& s, Scalar tau, bool changed);
  /// Applies the step and flags a possible unbounded direction.
  template <typename Backend>
  void take_step(const Backend& be, const QpSettings<Scalar>& s, Scalar tau, Scalar tau_dual,
                 bool changed);
  /// Returns the best iterate when the loop did not succeed; final residuals and check.
  template <typename Backend>
  QpStatus finish(const Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info,
                  QpStatus status);
  bool infeasibility_certificate(const QpSettings<Scalar>& s) const;
  template <typename Backend>
  bool unboundedness_certificate(const Backend& be, const QpSettings<Scalar>& s);

  // residuals of the last evaluate()
  Scalar pr_ = 0;        ///< max violation
  Scalar du_ = 0;        ///< max |stationarity residual|
  Scalar co_ = 0;        ///< complementarity residual
  Scalar pr_scale_ = 1;  ///< 1 + |z|_inf (scale of the primal and complementarity tolerances)
  Scalar du_scale_ = 1;  ///< 1 + largest term of H x + g + A' lam (scale of the dual one)
  Scalar sd_ = 0;        ///< max wrong-sign multiplier on the working set
  int isd_ = -1;         ///< its index
  Scalar pc_ = 0;        ///< max violation among constraints that are not active on that side
  int ipc_ = -1;         ///< its index
  State spc_ = State::inactive;  ///< the violated side

  // state of the iteration loop
  Scalar delta_ = 0;                    ///< primal regularisation in use
  Scalar w_ = 0;                        ///< bound weight 1 / eps
  int pending_ = -1;                    ///< index of a pending change from the ratio test
  State pending_ws_ = State::inactive;  ///< its next working-set state
  bool refactor_ = true;                ///< the factorization is out of date
  Scalar best_ = 0;                     ///< best merit so far
  bool have_best_ = false;              ///< best_x_ etc. hold an iterate
  bool unbounded_candidate_ = false;    ///< the last step was an unbounded-direction candidate
  int certificate_count_ = 0;           ///< consecutive iterates with a Farkas certificate
  bool refining_ = false;               ///< the previous iteration left the working set unchanged
  Scalar pr_prev_ = 0;                  ///< primal error of the previous iteration

  VecA za_;          ///< A x
  VecV hx_;          ///< H x
  VecV r_;           ///< stationarity residual
  VecV dx_;          ///< primal step (also the right-hand side)
  VecA dza_;         ///< A dx
  VecV dlam_x_;      ///< bound-multiplier step
  VecA dlam_a_;      ///< row-multiplier step
  VecA tmpa_;        ///< row workspace
  VecA wa_;          ///< regularisation weight of each row, 1 / (eps |a_j|^2)
  VecV best_x_;      ///< best iterate so far
  VecV best_lam_x_;  ///< its bound multipliers
  VecA best_lam_a_;  ///< its row multipliers
};

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::begin(Backend& be, const QpSettings<Scalar>& s) {
  ARBOR_ASSERT(s.reg_primal > 0 && s.reg_dual > 0, "regularisations must be positive");
  for (int i = 0; i < NV; ++i) {
    if (!std::isfinite(x(i)) || !std::isfinite(lam_x(i))) {
      cold_start();
      break;
    }
  }
  for (int i = 0; i < NA; ++i) {
    if (!std::isfinite(lam_a(i))) {
      cold_start();
      break;
    }
  }
  working_set_from_multipliers();
  delta_ = s.reg_primal;
  w_ = Scalar(1) / s.reg_dual;
  // row weights 1 / (eps |a_j|^2): the regularisation acts on normalised rows, so rows with
  // small coefficients (a linearised path constraint) converge as fast as bounds
  be.row_norms_sq(wa_);
  for (int j = 0; j < NA; ++j)
    wa_(j) = wa_(j) > 0 ? w_ / wa_(j) : w_;
  refactor_ = true;
  be.mark_all();
  pending_ = -1;
  pending_ws_ = State::inactive;
  best_ = inf();
  have_best_ = false;
  unbounded_candidate_ = false;
  certificate_count_ = 0;
  refining_ = false;
  pr_prev_ = inf();
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::working_set_from_multipliers() {
  for (int i = 0; i < nz; ++i) {
    const Scalar l = lb(i), u = ub(i), m = lam(i);
    if (l == u) {
      ws[i] = State::equality;
    } else if (m > 0 && u < inf()) {
      ws[i] = State::upper;
    } else if (m < 0 && l > -inf()) {
      ws[i] = State::lower;
    } else {
      ws[i] = State::inactive;
      lam(i) = 0;
    }
  }
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::evaluate(const Backend& be) {
  be.cons_mul(x, za_);
  be.hess_mul(x, hx_);
  be.cons_tmul(lam_a, r_);
  r_ += hx_ + g + lam_x;
  du_ = r_.size() > 0 ? r_.cwiseAbs().maxCoeff() : Scalar(0);
  if (!std::isfinite(du_))
    du_ = inf();
  // scales of the relative tolerances: |z|_inf and the largest term of the stationarity sum
  du_scale_ = Scalar(1);
  for (int i = 0; i < NV; ++i) {
    du_scale_ = std::max(du_scale_, std::abs(hx_(i)));
    du_scale_ = std::max(du_scale_, std::abs(g(i)));
    du_scale_ = std::max(du_scale_, std::abs(r_(i) - hx_(i) - g(i)));
  }
  pr_scale_ = Scalar(1);
  pr_ = 0;
  co_ = 0;
  sd_ = 0;
  isd_ = -1;
  pc_ = 0;
  ipc_ = -1;
  spc_ = State::inactive;
  for (int i = 0; i < nz; ++i) {
    const Scalar z = zval(i), l = lb(i), u = ub(i), m = lam(i);
    if (!std::isfinite(z) || !std::isfinite(m)) {
      pr_ = inf();
      continue;
    }
    pr_scale_ = std::max(pr_scale_, std::abs(z));
    const Scalar vl = l - z, vu = z - u;
    const Scalar v = vl > vu ? vl : vu;
    if (v > pr_)
      pr_ = v;
    if (v > 0) {
      const State side = vl > vu ? State::lower : State::upper;
      if (ws[i] != side && ws[i] != State::equality && v > pc_) {
        pc_ = v;
        ipc_ = i;
        spc_ = side;
      }
    }
    if (m != 0) {
      const Scalar dist =
          m > 0 ? (u < inf() ? std::abs(u - z) : inf()) : (l > -inf() ? std::abs(z - l) : inf());
      const Scalar am = std::abs(m);
      const Scalar c = am < dist ? am : dist;
      if (c > co_)
        co_ = c;
    }
    if (one_sided(i)) {
      const Scalar wrong = -m * side_sign<Scalar>(ws[i]);
      if (wrong > sd_) {
        sd_ = wrong;
        isd_ = i;
      }
    }
  }
}

template <typename Scalar, int NV, int NA>
bool ActiveSetCore<Scalar, NV, NA>::converged_or_stopped(const QpSettings<Scalar>& s, int it,
                                                         QpStatus& status) {
  if (!std::isfinite(pr_) || !std::isfinite(du_)) {
    status = QpStatus::non_finite;
    return true;
  }
  const Scalar merit =
      std::max(std::max(pr_ / (s.tol_primal * pr_scale_), du_ / (s.tol_dual * du_scale_)),
               co_ / (s.tol_comp * pr_scale_));
  if (merit < best_) {
    best_ = merit;
    have_best_ = true;
    best_x_ = x;
    best_lam_x_ = lam_x;
    best_lam_a_ = lam_a;
  }
  if (merit <= 1) {
    status = QpStatus::solved;
    return true;
  }
  if (unbounded_candidate_ && pr_ <= s.tol_primal) {
    status = QpStatus::unbounded;
    return true;
  }
  unbounded_candidate_ = false;
  // a certificate that holds on several consecutive iterates (transients do not count)
  certificate_count_ = infeasibility_certificate(s) ? certificate_count_ + 1 : 0;
  if (certificate_count_ >= 3) {
    status = QpStatus::infeasible;
    return true;
  }
  return it >= s.max_iter;  // status stays iteration_limit
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
bool ActiveSetCore<Scalar, NV, NA>::change_working_set(Backend& be, const QpSettings<Scalar>& s,
                                                       SolveInfo<Scalar>& info) {
  // a pending change from the last ratio test, else the most violated constraint when the
  // primal error dominates, else the multiplier of the most wrong sign
  int change = -1;
  State change_ws = State::inactive;
  if (pending_ >= 0) {
    change = pending_;
    change_ws = pending_ws_;
  } else if (ipc_ >= 0 && pc_ > s.tol_primal && pc_ / s.tol_primal >= sd_ / s.tol_dual) {
    change = ipc_;
    change_ws = spc_;
  } else if (isd_ >= 0 && sd_ > s.tol_dual) {
    change = isd_;
    change_ws = State::inactive;
  }
  pending_ = -1;
  if (change < 0 || ws[change] == change_ws || ws[change] == State::equality)
    return false;
  ws[change] = change_ws;
  const bool had_multiplier = lam(change) != 0;
  lam(change) = 0;
  if (had_multiplier)
    evaluate(be);  // r must not keep the dropped multiplier
  be.mark_changed(change);
  refactor_ = true;
  ++info.active_set_changes;
  return true;
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
bool ActiveSetCore<Scalar, NV, NA>::refactorize(Backend& be, const QpSettings<Scalar>& s,
                                                SolveInfo<Scalar>& info) {
  if (!refactor_)
    return true;
  for (;;) {
    const int done = be.factorize(ws.data(), delta_, w_, wa_);
    if (done >= 0) {
      info.stages_factorized += done;
      if constexpr (requires { be.updates_last; })
        info.factor_updates += be.updates_last;
      break;
    }
    delta_ *= Scalar(10);
    ++info.regularization_bumps;
    be.mark_all();
    if (delta_ > s.reg_primal_max)
      return false;
  }
  ++info.factorizations;
  refactor_ = false;
  return true;
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::compute_step(const Backend& be) {
  tmpa_.setZero();
  for (int j = 0; j < NA; ++j) {
    if (ws[NV + j] != State::inactive)
      tmpa_(j) = wa_(j) * (za_(j) - target(NV + j));
  }
  be.cons_tmul(tmpa_, dx_);
  dx_ = -(dx_ + r_);
  for (int i = 0; i < NV; ++i) {
    if (ws[i] != State::inactive)
      dx_(i) -= w_ * (x(i) - target(i));
  }
  be.solve(dx_);
  be.cons_mul(dx_, dza_);
  for (int i = 0; i < nz; ++i) {
    const Scalar wi = i < NV ? w_ : wa_(i - NV);
    const Scalar d = ws[i] != State::inactive ? wi * (zval(i) - target(i) + dzval(i)) : -lam(i);
    if (i < NV) {
      dlam_x_(i) = d;
    } else {
      dlam_a_(i - NV) = d;
    }
  }
}

template <typename Scalar, int NV, int NA>
Scalar ActiveSetCore<Scalar, NV, NA>::ratio_test(const QpSettings<Scalar>& s) {
  Scalar tau = 1;
  const Scalar e = std::max(s.tol_primal, pr_);
  for (int i = 0; i < nz; ++i) {
    const Scalar dz = dzval(i);
    if (ws[i] == State::inactive) {
      if (dz > 0 && ub(i) < inf()) {
        const Scalar t = std::max(Scalar(0), ub(i) + e - zval(i)) / dz;
        if (t < tau) {
          tau = t;
          pending_ = i;
          pending_ws_ = State::upper;
        }
      } else if (dz < 0 && lb(i) > -inf()) {
        const Scalar t = std::min(Scalar(0), lb(i) - e - zval(i)) / dz;
        if (t < tau) {
          tau = t;
          pending_ = i;
          pending_ws_ = State::lower;
        }
      }
    } else if (one_sided(i)) {
      const Scalar sg = side_sign<Scalar>(ws[i]);
      const Scalar m = lam(i) * sg, dm = dlam(i) * sg;
      if (m > 0 && dm < 0) {
        const Scalar t = m / -dm;
        if (t < tau) {
          tau = t;
          pending_ = i;
          pending_ws_ = State::inactive;
        }
      }
    }
  }
  return tau;
}

template <typename Scalar, int NV, int NA>
Scalar ActiveSetCore<Scalar, NV, NA>::singular_dual_step(const QpSettings<Scalar>& s, Scalar tau,
                                                         bool changed) {
  // Stagnation on an unchanged working set: the primal error does not fall although full
  // steps are taken, so the working set is (nearly) inconsistent and the multipliers drift
  // along a null-space direction of A_W'. Follow that direction to the first active multiplier
  // that reaches zero and drop its constraint (QRQP's singular step, in multiplier space).
  Scalar tau_dual = tau;
  if (tau == Scalar(1) && pending_ < 0 && !changed && refining_ && pr_ > s.tol_primal &&
      pr_ > Scalar(0.5) * pr_prev_) {
    Scalar tmin = inf();
    for (int i = 0; i < nz; ++i) {
      if (!one_sided(i))
        continue;
      const Scalar sg = side_sign<Scalar>(ws[i]);
      const Scalar m = lam(i) * sg, dm = dlam(i) * sg;
      if (m >= 0 && dm < 0 && m / -dm < tmin) {
        tmin = m / -dm;
        pending_ = i;
        pending_ws_ = State::inactive;
      }
    }
    if (pending_ >= 0)
      tau_dual = tmin > tau ? tmin : tau;
  }
  return tau_dual;
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::take_step(const Backend& be, const QpSettings<Scalar>& s,
                                              Scalar tau, Scalar tau_dual, bool changed) {
  refining_ = !changed;
  pr_prev_ = pr_;
  x += tau * dx_;
  lam_x += tau_dual * dlam_x_;
  lam_a += tau_dual * dlam_a_;
  if (pending_ >= 0 && pending_ws_ == State::inactive)
    lam(pending_) = 0;
  if (tau == Scalar(1) && delta_ * dx_.cwiseAbs().maxCoeff() > s.tol_dual &&
      unboundedness_certificate(be, s)) {
    unbounded_candidate_ = true;  // confirmed if the next iterate is primal feasible
  }
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
QpStatus ActiveSetCore<Scalar, NV, NA>::finish(const Backend& be, const QpSettings<Scalar>& s,
                                               SolveInfo<Scalar>& info, QpStatus status) {
  if (status != QpStatus::solved && status != QpStatus::infeasible &&
      status != QpStatus::unbounded && have_best_) {
    x = best_x_;
    lam_x = best_lam_x_;
    lam_a = best_lam_a_;
    working_set_from_multipliers();
    evaluate(be);
  }
  // explicit final check on the original data (residuals of the returned iterate)
  info.primal_residual = pr_;
  info.dual_residual = du_;
  info.complementarity = co_;
  info.objective = Scalar(0.5) * x.dot(hx_) + g.dot(x);
  int na_ws = 0;
  for (int i = 0; i < nz; ++i)
    na_ws += ws[i] != State::inactive ? 1 : 0;
  info.active_constraints = na_ws;
  if (status == QpStatus::solved &&
      !(pr_ <= s.tol_primal * pr_scale_ && du_ <= s.tol_dual * du_scale_ &&
        co_ <= s.tol_comp * pr_scale_)) {
    status = QpStatus::iteration_limit;
  }
  return status;
}

template <typename Scalar, int NV, int NA>
bool ActiveSetCore<Scalar, NV, NA>::infeasibility_certificate(const QpSettings<Scalar>& s) const {
  // y = lam / |lam|_inf; A' y + y_x = (r - H x - g) / |lam|_inf.
  Scalar nl = 0;
  for (int i = 0; i < nz; ++i)
    nl = std::max(nl, std::abs(lam(i)));
  if (!(nl > 0) || !std::isfinite(nl))
    return false;
  Scalar cert = 0;
  for (int i = 0; i < NV; ++i)
    cert = std::max(cert, std::abs(r_(i) - hx_(i) - g(i)));
  cert /= nl;
  if (cert > s.tol_certificate)
    return false;
  Scalar sigma = 0;
  for (int i = 0; i < nz; ++i) {
    const Scalar m = lam(i) / nl;
    if (m > 0) {
      if (!(ub(i) < inf()))
        return false;
      sigma += ub(i) * m;
    } else if (m < 0) {
      if (!(lb(i) > -inf()))
        return false;
      sigma += lb(i) * m;
    }
  }
  return sigma < -Scalar(10) * (s.tol_primal + s.tol_certificate);
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
    const Scalar d = dzval(i) / nd;
    if (ub(i) < inf() && d > tol)
      return false;
    if (lb(i) > -inf() && d < -tol)
      return false;
  }
  VecV& hd = dlam_x_;  // reused as workspace: the step has been applied already
  be.hess_mul(dx_, hd);
  if (hd.cwiseAbs().maxCoeff() / nd > tol * (Scalar(1) + hx_.cwiseAbs().maxCoeff()))
    return false;
  return g.dot(dx_) / nd < -tol * (Scalar(1) + g.cwiseAbs().maxCoeff());
}

}  // namespace arbor::qp::detail
