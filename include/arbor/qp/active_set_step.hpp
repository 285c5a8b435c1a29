// arbor::qp::detail: one iteration's working-set change, factorization and step (the
// regularised equality-constrained QP of the working set, its refinement, the ratio test, the
// singular step in multiplier space, the update of the iterate), active_set.hpp's method.
// O(NV + NA) per step plus one backend solve, and a (partial) refactorization after a change.
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
bool ActiveSetCore<Scalar, NV, NA>::change_working_set(Backend& be, const QpSettings<Scalar>& s,
                                                       SolveInfo<Scalar>& info) {
  State change_ws;
  const int change = due_change(s, change_ws);
  pending_ = -1;
  if (previous_ == PreviousStep::none_warm)
    previous_ = PreviousStep::none;  // (the warm start's first iteration adds nothing: due_change)
  if (change < 0)
    return false;
  ws[change] = change_ws;
  const Scalar m = lam(change);
  lam(change) = 0;
  if (m != 0) {  // r must not keep the dropped multiplier: its column times m comes off
    if (change < NV) {
      r_(change) -= m;
    } else {
      tmpa_.setZero();
      tmpa_(change - NV) = m;
      be.cons_tmul(tmpa_, tmpv_);
      r_ -= tmpv_;
    }
  }
  be.mark_changed(change);
  factor_ = Factor::out_of_date;
  ++info.active_set_changes;
  return true;
}

template <typename Scalar, int NV, int NA>
int ActiveSetCore<Scalar, NV, NA>::due_change(const QpSettings<Scalar>& s, State& side) const {
  // a pending change from the last ratio test, else the most violated constraint when the
  // primal error dominates, else the multiplier of the most wrong sign
  int change = -1;
  side = State::inactive;
  if (pending_ >= 0) {
    change = pending_;
    side = pending_ws_;
  } else if (ipc_ >= 0 && !warm_first() && pc_ > s.tol_primal * pr_scale_ &&
             pc_ / (s.tol_primal * pr_scale_) >= sd_ / drop_threshold(s)) {
    change = ipc_;
    side = spc_;
  } else if (isd_ >= 0 && sd_ > drop_threshold(s)) {
    change = isd_;
  }
  if (change < 0 || ws[change] == side || ws[change] == State::equality)
    return -1;
  return change;
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
bool ActiveSetCore<Scalar, NV, NA>::refactorize(Backend& be, const QpSettings<Scalar>& s,
                                                SolveInfo<Scalar>& info) {
  if (factor_ != Factor::out_of_date)
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
    if (delta_ >
        std::max(s.reg_primal_max, kRoundoffPivots * std::numeric_limits<Scalar>::epsilon() * h_))
      return false;
  }
  ++info.factorizations;
  factor_ = Factor::current;
  return true;
}

template <typename Scalar, int NV, int NA>
template <bool Prepare, typename Backend>
void ActiveSetCore<Scalar, NV, NA>::compute_step(const Backend& be) {
  // rows the backend solves exactly (ExactRowBackend: the OCP's dynamics) take no weight
  const auto exact = [](int j) {
    if constexpr (ExactRowBackend<Backend, Scalar, NV, NA>)
      return Backend::exact_row(j);
    else
      return false;
  };
  // bounds the backend holds exactly (its fixed variables) take no weight either
  const auto exact_bound = [](int i) {
    if constexpr (ExactRowBackend<Backend, Scalar, NV, NA>)
      return Backend::exact_bound(i);
    else
      return false;
  };
  tmpa_.setZero();
  for (int j = 0; j < NA; ++j) {
    if (ws[NV + j] != State::inactive && !exact(j))
      tmpa_(j) = wa_(j) * (za_(j) - target(NV + j));
  }
  if constexpr (PathProducts<Backend, Scalar, NV, NA>)
    be.path_tmul(tmpa_, dx_);  // (the exact rows have no weight: no product with them)
  else
    be.cons_tmul(tmpa_, dx_);
  dx_ = -(dx_ + r_);
  for (int i = 0; i < NV; ++i) {
    if (ws[i] == State::inactive)
      continue;
    if (exact_bound(i))
      fixed_(i) = target(i) - x(i);  // the fixed variable's step
    else
      dx_(i) -= w_ * (x(i) - target(i));
  }
  if constexpr (ExactRowBackend<Backend, Scalar, NV, NA>) {
    // D dx = t_D - D x; the backend returns dlam of the exact rows in their entries of tmpa_,
    // and of the working exact bounds in theirs of fixed_
    for (int j = 0; j < NA; ++j) {
      if (exact(j))
        tmpa_(j) = target(NV + j) - za_(j);
    }
    if constexpr (PathProducts<Backend, Scalar, NV, NA>) {
      // A dx: D dx = e on the exact rows (to round-off), a product with the path rows only
      for (int j = 0; j < NA; ++j) {
        if (exact(j))
          dza_(j) = tmpa_(j);
      }
      be.solve_exact(dx_, tmpa_, fixed_, wa_);
      if constexpr (!Prepare)
        be.path_mul(dx_, dza_);
    } else {
      be.solve_exact(dx_, tmpa_, fixed_, wa_);
      be.cons_mul(dx_, dza_);
    }
  } else {
    be.solve(dx_);
    be.cons_mul(dx_, dza_);
  }
  if constexpr (Prepare) {
    // (the weighted ones: move_presolved_step(), from the moved step)
    for (int i = 0; i < NV; ++i)
      dlam_x_(i) = ws[i] == State::inactive ? -lam_x(i) : (exact_bound(i) ? fixed_(i) : 0);
    for (int j = 0; j < NA; ++j)
      dlam_a_(j) = exact(j) ? tmpa_(j) : (ws[NV + j] != State::inactive ? 0 : -lam_a(j));
    return;
  }
  for (int i = 0; i < NV; ++i) {
    const State wi = ws[i];
    dlam_x_(i) =
        wi == State::inactive
            ? -lam_x(i)
            : (exact_bound(i) ? fixed_(i)
                              : w_ * (x(i) - (wi == State::lower ? lbx(i) : ubx(i)) + dx_(i)));
  }
  for (int j = 0; j < NA; ++j) {
    const State wj = ws[NV + j];
    dlam_a_(j) = exact(j)
                     ? tmpa_(j)
                     : (wj != State::inactive
                            ? wa_(j) * (za_(j) - (wj == State::lower ? lba(j) : uba(j)) + dza_(j))
                            : -lam_a(j));
  }
}

template <typename Scalar, int NV, int NA>
template <bool Add, typename Backend>
void ActiveSetCore<Scalar, NV, NA>::response_multipliers() {
  for (int i = 0; i < NV; ++i) {
    const State wi = ws[i];
    if (wi == State::inactive)
      continue;
    if (Backend::exact_bound(i)) {
      dlam_x_(i) += fixed_(i);
    } else {
      const Scalar v = w_ * (x(i) - (wi == State::lower ? lbx(i) : ubx(i)) + dx_(i));
      dlam_x_(i) = Add ? dlam_x_(i) + v : v;
    }
  }
  for (int j = 0; j < NA; ++j) {
    const State wj = ws[NV + j];
    if (Backend::exact_row(j)) {
      dlam_a_(j) += tmpa_(j);
    } else if (wj != State::inactive) {
      const Scalar v = wa_(j) * (za_(j) - (wj == State::lower ? lba(j) : uba(j)) + dza_(j));
      dlam_a_(j) = Add ? dlam_a_(j) + v : v;
    }
  }
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
bool ActiveSetCore<Scalar, NV, NA>::refine_step(const Backend& be, const QpSettings<Scalar>& s) {
  if constexpr (ExactRowBackend<Backend, Scalar, NV, NA>) {
    // The regularised step solves K_eps z = b, where the rows and bounds held by weights (P)
    // read E_P dx - eps dlam_P = c_P; the exact system has E_P dx = c_P. One refinement step
    // K_eps d = b - K_0 z = -eps dlam_P on those rows is, eliminated,
    //   M_P d + D' dnu' + E_B' dlam_B' = -E_P' dlam_P,  D d = 0,  E_B d = 0,
    //   dlam_P += w_P (E_P (x + dx + d) - t_P)       (a second proximal step, same factor)
    // after which the miss is eps times the change of dlam_P, not eps dlam_P.
    Scalar miss = 0;
    bool rows = false;
    for (int i = 0; i < NV; ++i) {
      if (ws[i] != State::inactive && !Backend::exact_bound(i))
        miss = std::max(miss, std::abs(dlam_x_(i)) / w_);
    }
    for (int j = 0; j < NA; ++j) {
      if (ws[NV + j] != State::inactive && !Backend::exact_row(j)) {
        miss = std::max(miss, std::abs(dlam_a_(j)) / (wa_(j) * rn_(j)));
        rows = true;
      }
    }
    if (!(miss > Scalar(0.9) * s.tol_primal * pr_scale_))
      return false;  // the step lands within tolerance (or is not finite: left to the loop)
    VecV& d = response_;
    if (rows) {
      for (int j = 0; j < NA; ++j) {
        tmpa_(j) =
            ws[NV + j] != State::inactive && !Backend::exact_row(j) ? -dlam_a_(j) : Scalar(0);
      }
      if constexpr (PathProducts<Backend, Scalar, NV, NA>)
        be.path_tmul(tmpa_, d);
      else
        be.cons_tmul(tmpa_, d);
    } else {
      d.setZero();
    }
    for (int i = 0; i < NV; ++i) {
      if (ws[i] != State::inactive && !Backend::exact_bound(i))
        d(i) -= dlam_x_(i);
      fixed_(i) = 0;
    }
    tmpa_.setZero();
    // (e = 0 and the fixed steps are 0: a backend that can skips its products with them)
    if constexpr (requires { be.template solve_exact<true>(d, tmpa_, fixed_, wa_); })
      be.template solve_exact<true>(d, tmpa_, fixed_, wa_);
    else
      be.solve_exact(d, tmpa_, fixed_, wa_);
    dx_ += d;
    if constexpr (PathProducts<Backend, Scalar, NV, NA>)
      be.path_mul(dx_, dza_);  // (D d = 0: the exact rows' A dx is unchanged)
    else
      be.cons_mul(dx_, dza_);
    response_multipliers<true, Backend>();
    return true;
  } else {
    (void)be;
    (void)s;
    return false;
  }
}

template <typename Scalar, int NV, int NA>
Scalar ActiveSetCore<Scalar, NV, NA>::ratio_test(const QpSettings<Scalar>& s) {
  Scalar tau = 1;
  const Scalar en = std::max(s.tol_primal * pr_scale_, pr_);  // per constraint
  int pending = pending_;  // locals: the working set (int8_t) may alias the members
  State pending_ws = pending_ws_;
  // one body for the bounds (n = 1) and the rows: no branch on i < NV per constraint
  const auto visit = [&](int i, Scalar z, Scalar dz, Scalar l, Scalar u, Scalar m, Scalar dm,
                         Scalar n) {
    const State wi = ws[i];
    if (wi == State::inactive) {
      const Scalar e = en * n;
      if (dz > 0 && u < inf()) {
        const Scalar t = std::max(Scalar(0), u + e - z) / dz;
        if (t < tau) {
          tau = t;
          pending = i;
          pending_ws = State::upper;
        }
      } else if (dz < 0 && l > -inf()) {
        const Scalar t = std::min(Scalar(0), l - e - z) / dz;
        if (t < tau) {
          tau = t;
          pending = i;
          pending_ws = State::lower;
        }
      }
    } else if (wi == State::upper || wi == State::lower) {
      const Scalar sg = side_sign<Scalar>(wi);
      const Scalar ms = m * sg, dms = dm * sg;
      if (ms > 0 && dms < 0) {
        const Scalar t = ms / -dms;
        if (t < tau) {
          tau = t;
          pending = i;
          pending_ws = State::inactive;
        }
      }
    }
  };
  for (int i = 0; i < NV; ++i)
    visit(i, x(i), dx_(i), lbx(i), ubx(i), lam_x(i), dlam_x_(i), Scalar(1));
  for (int j = 0; j < NA; ++j)
    visit(NV + j, za_(j), dza_(j), lba(j), uba(j), lam_a(j), dlam_a_(j), rn_(j));
  pending_ = pending;
  pending_ws_ = pending_ws;
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
  if (tau == Scalar(1) && pending_ < 0 && !changed && refining() &&
      pr_ > s.tol_primal * pr_scale_ && pr_ > Scalar(0.5) * pr_prev_) {
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
    // anti-cycling: a constraint this rule dropped before and that came back (the primal error
    // then stalls at round-off, not on an inconsistent working set) is not dropped again; the
    // iteration goes on refining, and ends `stalled` if that makes no progress
    bool repeated = false;
    for (int k = 0; k < kDropMemory; ++k)
      repeated = repeated || (pending_ >= 0 && singular_drops_[k] == pending_);
    if (repeated) {
      pending_ = -1;
      ++cycles_;
    } else if (pending_ >= 0) {
      singular_drops_[next_drop_] = pending_;
      next_drop_ = (next_drop_ + 1) % kDropMemory;
      tau_dual = tmin > tau ? tmin : tau;
    }
  }
  return tau_dual;
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::take_step(const Backend& be, const QpSettings<Scalar>& s,
                                              Scalar tau, Scalar tau_dual, bool changed,
                                              bool refined) {
  previous_ = changed ? PreviousStep::changed : PreviousStep::kept;
  pr_prev_ = pr_;
  if (tau == Scalar(1) && delta_ * dx_.cwiseAbs().maxCoeff() > s.tol_dual &&
      unboundedness_certificate(be, s)) {
    unbounded_candidate_ = true;  // confirmed if the next iterate is primal feasible
  }
  // The products of the next evaluate(): from scratch after a full step that nothing blocked
  // or a refined one (it lands on the working set's solution, so the next evaluate() may well end
  // the loop, which then needs them from scratch anyway) and every kExactEvery steps (round-off
  // of the updates does not accumulate); else updated here: A x += tau A dx (the step has A dx),
  // H x += tau H dx, r += tau H dx + the multipliers' change (the dropped one's exactly) and A'
  // times it.
  ++since_exact_;
  const bool exact_next =
      since_exact_ >= kExactEvery || (tau == Scalar(1) && pending_ < 0) || refined;
  next_products_ = exact_next ? Products::from_scratch : Products::updated;
  const int drop = pending_ >= 0 && pending_ws_ == State::inactive ? pending_ : -1;
  x += tau * dx_;
  if (exact_next) {
    lam_x += tau_dual * dlam_x_;
    lam_a += tau_dual * dlam_a_;
    if (drop >= 0)
      lam(drop) = 0;
    return;
  }
  if (tau != Scalar(0)) {
    za_ += tau * dza_;
    be.hess_mul(dx_, tmpv_);
    hx_ += tau * tmpv_;
    r_ += tau * tmpv_;
  }
  tmpv_ = tau_dual * dlam_x_;
  tmpa_ = tau_dual * dlam_a_;
  if (drop >= 0 && drop < NV)
    tmpv_(drop) = -lam_x(drop);
  else if (drop >= NV)
    tmpa_(drop - NV) = -lam_a(drop - NV);
  lam_x += tmpv_;  // (the dropped multiplier becomes m - m = 0 exactly)
  lam_a += tmpa_;
  r_ += tmpv_;
  be.cons_tmul(tmpa_, tmpv_);
  r_ += tmpv_;
}
}  // namespace arbor::qp::detail
