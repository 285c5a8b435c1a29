// arbor::qp::detail: the prepared start of real-time iteration (PreparedStart, prepared_start.hpp)
// in ActiveSetCore. The feedback's QP differs from the prepared one only in the targets of the
// first n bounds (the OCP's x_0, equalities the Riccati backend holds by fixing the variables).
// prepare_start() factorizes, computes the products at x = 0, the first step and the pass over the
// constraints after those n; solve_from() merges the n bounds' residuals into that pass
// (scan_moved()) and adds to the step its response to the targets' move: one backend solve with
// only those fixed steps as right-hand side (the InitialOnly solve, ~55 % of a full one;
// move_presolved_step()). The step is linear in its right-hand side, so the iterates are solve()'s
// to round-off. A first iteration that changes the working set (known at the preparation: not from
// the targets) computes its own step. Bounds moved after the preparation (move_bound(): the NMPC's
// recovery) keep it while the working set holds, with the whole pass again and the moved working
// targets' response in the same solve (a full one).
#pragma once

#include <Eigen/Core>
#include <limits>

#include "arbor/qp/active_set_core.hpp"
#include "arbor/qp/backend.hpp"
#include "arbor/qp/prepared_start.hpp"
#include "arbor/qp/residual_scan.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp::detail {

template <typename Scalar, int NV, int NA>
template <ActiveSetBackend<Scalar, NV, NA> Backend>
auto ActiveSetCore<Scalar, NV, NA>::prepare_start(Backend& be, const QpSettings<Scalar>& s, int n)
    -> Prepared {
  Prepared p;
  x.setZero();
  if (!prefactorize(be, s, p.stages_))
    return p;  // (Reuse::nothing)
  p.first_ = Prepared::Reuse::factorization;
  p.n_ = n;
  p.reg_primal_ = s.reg_primal;
  p.reg_dual_ = s.reg_dual;
  p.relative_ = s.relative_regularisation;
  p.revision_ = revision_;
  // the step needs the InitialOnly solve (ocp_riccati_backend.hpp), and the targets' move must be a
  // step of fixed variables: the n bounds equalities the backend holds exactly
  if constexpr (PathProducts<Backend, Scalar, NV, NA> &&
                requires { be.template solve_exact<false, true>(dx_, tmpa_, fixed_, wa_); }) {
    for (int i = 0; i < n; ++i) {
      if (ws[i] != State::equality || !Backend::exact_bound(i))
        return p;
    }
    evaluate(be, true, &p);  // (A x = 0, H x = 0: r = g + lam_x + A' lam)
    // the first iteration's working-set change does not depend on the n targets (x = 0, and their
    // bounds are equalities, which add and drop nothing): when it will make one, that iteration
    // computes its own step and the pass alone is kept
    State side;
    if (due_change(s, side) < 0) {
      compute_step<true>(be);
      p.first_ = Prepared::Reuse::step;
    } else {
      p.first_ = Prepared::Reuse::pass;
    }
  }
  return p;
}

template <typename Scalar, int NV, int NA>
template <ActiveSetBackend<Scalar, NV, NA> Backend>
QpStatus ActiveSetCore<Scalar, NV, NA>::solve_from(Backend& be, const QpSettings<Scalar>& s,
                                                   SolveInfo<Scalar>& info,
                                                   const Prepared& prepared, const Scalar* t,
                                                   int n) {
  const bool use = prepared.first_ >= Prepared::Reuse::pass && prepared.revision_ == revision_ &&
                   prepared.n_ == n && s.reg_primal == prepared.reg_primal_ &&
                   s.reg_dual == prepared.reg_dual_ &&
                   s.relative_regularisation == prepared.relative_;
  if (!use) {
    for (int i = 0; i < n; ++i)
      lbx(i) = ubx(i) = t[i];
    x.setZero();
    return solve(be, s, info);
  }
  note_change();  // (the iterate and the working set are this solve's now)
  // the preparation's begin() built the working set, the row weights and the factorization for
  // these multipliers: the loop starts without them; fixed_ carries the fixed steps' move
  info = SolveInfo<Scalar>{};
  factor_ = Factor::current;
  fixed_.setZero();
  for (int i = 0; i < n; ++i) {
    fixed_(i) = t[i] - lbx(i);
    lbx(i) = ubx(i) = t[i];
  }
  reset_loop();
  return iterate(be, s, info, &prepared);
}

template <typename Scalar, int NV, int NA>
template <ActiveSetBackend<Scalar, NV, NA> Backend>
void ActiveSetCore<Scalar, NV, NA>::move_bound(Prepared* prepared, int i, Scalar lo, Scalar hi) {
  const Scalar l0 = lbx(i), u0 = ubx(i);
  if (lo == l0 && hi == u0)
    return;  // (nothing changed)
  lbx(i) = lo;
  ubx(i) = hi;
  const bool valid = prepared != nullptr && prepared->revision_ == revision_ &&
                     prepared->first_ >= Prepared::Reuse::pass;
  note_change();
  if (!valid)
    return;
  // kept when the working set begin() would build from the multipliers with the new bounds is the
  // one the preparation factorized: i is not one of the n targets, an equality stays one, a
  // one-sided active bound keeps that side finite, and the bound is not one the backend holds
  // exactly (its variable is fixed in the factor)
  const State wi = ws[i];
  bool keep = i >= prepared->n_ && (l0 == u0) == (lo == hi) && (wi != State::upper || hi < inf()) &&
              (wi != State::lower || lo > -inf());
  if constexpr (ExactRowBackend<Backend, Scalar, NV, NA>)
    keep = keep && (wi == State::inactive || !Backend::exact_bound(i));
  if (!keep)
    return;
  prepared->revision_ = revision_;
  const Scalar d = wi == State::upper ? hi - u0 : lo - l0;  // (an equality moves both)
  if (wi != State::inactive && d != 0 && prepared->first_ == Prepared::Reuse::step) {
    if (prepared->moved_ != Prepared::Moved::targets)
      prepared->target_moves_.setZero();
    prepared->target_moves_(i) += d;
    prepared->moved_ = Prepared::Moved::targets;
  } else if (prepared->moved_ == Prepared::Moved::none) {
    prepared->moved_ = Prepared::Moved::bounds;
  }
}

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::scan_moved(const Prepared& prepared) {
  // only the first n bounds moved since the preparation's evaluate(): their pass, then the rest's
  // as it kept it (or all of it again after move_bound()); the products, du_ and the scales are the
  // preparation's
  ResidualScan<Scalar> sc;
  if (prepared.moved_ != Prepared::Moved::none) {
    sc.pass(values(), 0, nz, prepared.finite_);
  } else {
    sc.pass(values(), 0, prepared.n_, prepared.finite_);
    sc.merge(prepared.rest_);
  }
  store(sc);
  products_ = Products::updated;  // (a loop that may end here evaluates from scratch first)
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::move_presolved_step(const Backend& be,
                                                        const Prepared& prepared) {
  if constexpr (PathProducts<Backend, Scalar, NV, NA> &&
                requires { be.template solve_exact<false, true>(dx_, tmpa_, fixed_, wa_); }) {
    // The step is linear in the fixed steps: the prepared (dx_, dza_, dlam) plus the solve with
    // them alone as right-hand side (v = 0, e = 0: InitialOnly), on the same factorization.
    VecV& d = response_;
    d.setZero();
    tmpa_.setZero();
    if (prepared.moved_ == Prepared::Moved::targets) {
      // and the working bounds' target moves (move_bound()): v = w t there, a full solve
      for (int i = 0; i < NV; ++i) {
        if (ws[i] != State::inactive && !Backend::exact_bound(i))
          d(i) = w_ * prepared.target_moves_(i);
      }
      be.template solve_exact<false, false>(d, tmpa_, fixed_, wa_);
    } else {
      be.template solve_exact<false, true>(d, tmpa_, fixed_, wa_);
    }
    dx_ += d;
    // A dx on the path rows (the exact rows' is e, unchanged); the multiplier steps: the exact
    // rows' and fixed variables' by the response, the weighted ones from the moved step (x = 0)
    be.path_mul(dx_, dza_);
    response_multipliers<false, Backend>();
  } else {
    (void)prepared;
    compute_step(be);
  }
}

}  // namespace arbor::qp::detail
