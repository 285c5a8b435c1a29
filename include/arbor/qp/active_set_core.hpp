// arbor::qp::detail: ActiveSetCore, the primal-dual active-set method's iterate, bounds and
// workspace and the order of its steps (iterate()); the method is described in active_set.hpp,
// the steps are defined in active_set_evaluate.hpp (residuals), active_set_step.hpp (working-set
// change, factorization, step, ratio test) and active_set_termination.hpp (termination tests,
// certificates, the returned point). Memory: about 12 NV + 9 NA scalars and 2 (NV + NA) bytes.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

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

  /// Factorizes now what the next solve() factorizes first: the matrix of the working set the
  /// current multipliers name (for the NMPC's preparation phase, before the measurement). The
  /// next solve() skips that factorization when it starts from the same working set with the
  /// same weights; the caller guarantees that the matrices did not change in between (bounds
  /// and gradients may: they do not enter the factorization). Returns whether it will be
  /// reused (false after a pivot failure, which solve() handles as usual); stages counts the
  /// blocks factorized.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  bool prefactorize(Backend& be, const QpSettings<Scalar>& s, int& stages) {
    prefactored_ = false;
    begin(be, s);
    SolveInfo<Scalar> info{};
    const bool ok = refactorize(be, s, info) && delta_ == s.reg_primal;
    stages = info.stages_factorized;
    prefactored_ = ok;
    pre_ws_ = ws;
    pre_w_ = w_;
    return ok;
  }
  /// Forgets a prefactorization and a presolve (the matrices changed).
  void discard_prefactorization() {
    prefactored_ = false;
    presolved_ = 0;
  }
  /// Forgets a presolve (the vectors were re-read).
  void discard_presolve() { presolved_ = 0; }

  /// prefactorize() and, beyond it, the first step of a solve from x = 0 (x is set to 0 here)
  /// with the current multipliers and vectors: for the feedback of real-time iteration, whose QP
  /// differs from the prepared one only in the targets of the first n variables' bounds (the
  /// OCP's x_0: equalities the backend holds exactly). solve_from() then adds to this step its
  /// response to the targets' move instead of computing it. Needs a backend with the
  /// InitialOnly solve (ocp_riccati_backend.hpp) for the step (without one, or when the n
  /// bounds are not such equalities, only the factorization is kept). Returns prefactorize()'s
  /// result.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  bool presolve(Backend& be, const QpSettings<Scalar>& s, int& stages, int n) {
    presolved_ = 0;
    x.setZero();
    if (!prefactorize(be, s, stages))
      return false;
    if constexpr (PathProducts<Backend, Scalar, NV, NA> &&
                  requires { be.template solve_exact<false, true>(dx_, tmpa_, tmpv_, wa_); }) {
      for (int i = 0; i < n; ++i) {
        if (ws[i] != State::equality || !Backend::exact_bound(i))
          return true;  // the targets' move would not be a step of fixed variables
      }
      evaluate(be, true, n);  // (A x = 0, H x = 0: r = g + lam_x + A' lam)
      // the first iteration's working-set change does not depend on the n targets (x = 0, and
      // their bounds are equalities, which add and drop nothing): when it will make one, that
      // iteration computes its own step and the pass alone is kept
      State side;
      pre_step_ = due_change(s, side) < 0;
      if (pre_step_)
        compute_step<true>(be);
      pre_rescan_ = false;
      pre_targets_ = false;
      presolved_ = n;
      pre_lam_ = lam_checksum();
      pre_relative_ = s.relative_regularisation;
    } else {
      (void)n;
    }
    return true;
  }

  /// The solve from x = 0 (set here) with the bounds of the first n variables moved to
  /// lbx = ubx = t (n values): after presolve() with the same n, when the multipliers are still
  /// those it saw (the caller has not written them: checked by a checksum) and no vector was
  /// re-read (update_vectors() discards it), the first iteration takes presolve()'s step plus
  /// its response to the move (one InitialOnly solve; a full one when move_bound() moved a
  /// working bound's target) instead of a full evaluation and solve;
  /// otherwise, and for a first iteration that changes the working set, solve() as usual.
  /// The same iterates as solve() to round-off.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  [[nodiscard]] QpStatus solve_from(Backend& be, const QpSettings<Scalar>& s,
                                    SolveInfo<Scalar>& info, const Scalar* t, int n) {
    const bool use = presolved_ > 0 && presolved_ == n && prefactored_ && w_ == pre_w_ &&
                     w_ == h_ / s.reg_dual && delta_ == s.reg_primal &&
                     s.relative_regularisation == pre_relative_ &&
                     x.cwiseAbs().sum() == Scalar(0) && lam_checksum() == pre_lam_;
    pre_n_ = presolved_;  // (scan_moved() passes over these)
    presolved_ = 0;
    if (!use) {
      for (int i = 0; i < n; ++i)
        lbx(i) = ubx(i) = t[i];
      x.setZero();
      return solve(be, s, info);
    }
    // presolve()'s begin() built the working set, the row weights and the factorization for
    // these multipliers: the loop starts without them; tmpv_ carries the fixed steps' move
    info = SolveInfo<Scalar>{};
    prefactored_ = false;
    refactor_ = false;
    tmpv_.setZero();
    for (int i = 0; i < n; ++i) {
      tmpv_(i) = t[i] - lbx(i);
      lbx(i) = ubx(i) = t[i];
    }
    reset_loop();
    return iterate(be, s, info, true);
  }

  /// Sets the bounds of variable i (lo <= hi, not NaN: the caller checks) and keeps a presolve
  /// when the working set begin() would build from the multipliers with the new bounds is the
  /// one presolve() factorized (i is not one of its n targets; an equality stays one, lo == hi,
  /// a one-sided active bound keeps that side finite) and the bound is not one the
  /// backend holds exactly: solve_from() then passes over every constraint again and, when the
  /// target of a working bound moved, adds the step's response to that move to the one of the n
  /// targets (one full backend solve instead of the InitialOnly one). Otherwise the presolve is
  /// discarded. For the NMPC's recovery, which relaxes state bounds after its preparation.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  void move_bound(int i, Scalar lo, Scalar hi) {
    const Scalar l0 = lbx(i), u0 = ubx(i);
    lbx(i) = lo;
    ubx(i) = hi;
    if (presolved_ == 0 || (lo == l0 && hi == u0))
      return;
    const State wi = ws[i];
    bool keep = i >= presolved_ && (l0 == u0) == (lo == hi) && (wi != State::upper || hi < inf()) &&
                (wi != State::lower || lo > -inf());
    if constexpr (ExactRowBackend<Backend, Scalar, NV, NA>)
      keep = keep && (wi == State::inactive || !Backend::exact_bound(i));
    if (!keep) {
      presolved_ = 0;
      return;
    }
    pre_rescan_ = true;
    const Scalar d = wi == State::upper ? hi - u0 : lo - l0;  // (an equality moves both)
    if (wi != State::inactive && d != 0 && pre_step_) {
      dlam_x_(i) += d;  // the pending target move, in the entry the moved step recomputes
      pre_targets_ = true;
    }
  }

  /// Runs the method from the current (x, lam); fills info; returns the status.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  [[nodiscard]] QpStatus solve(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info) {
    info = SolveInfo<Scalar>{};
    begin(be, s);
    return iterate(be, s, info, false);
  }

 private:
  /// The iterations of solve() and solve_from() (presolved: the first step is presolve()'s,
  /// moved by the fixed steps in tmpv_).
  template <typename Backend>
  QpStatus iterate(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info,
                   bool presolved) {
    QpStatus status = QpStatus::iteration_limit;
    for (int it = 0;; ++it) {
      // presolved: the products at x = 0 are presolve()'s and only the first bounds moved:
      // their residuals merged with presolve()'s pass over the rest (not exact_: a loop that
      // may end here judges products from scratch, below); at the iteration cap, where the
      // loop ends, the products from scratch at once instead of updated and then recomputed
      if (presolved && it == 0)
        scan_moved();
      else
        evaluate(be, exact_next_ || it >= s.max_iter);
      settle_farkas(be, s, it);
      if (!exact_ && may_stop(s, it)) {
        evaluate(be, true);  // a loop that ends judges (and reports) products from scratch
        settle_farkas(be, s, it);
      }
      if (converged_or_stopped(s, it, status))
        break;
      info.iterations = it + 1;
      const bool changed = change_working_set(be, s, info);
      if (!refactorize(be, s, info)) {
        status = QpStatus::non_convex;
        break;
      }
      if (presolved && it == 0 && !changed && !refactor_ && pre_step_) {
        move_presolved_step(be);
        info.presolved = true;
      } else {
        compute_step(be);
      }
      Scalar tau = ratio_test(s);
      if (tau == Scalar(1) && pending_ < 0 && refine_step(be, s))
        tau = ratio_test(s);
      const Scalar tau_dual = singular_dual_step(s, tau, changed);
      take_step(be, s, tau, tau_dual, changed);
      farkas_pending_ = true;  // the step's certificate test: settle_farkas()
    }
    return finish(be, s, info, status);
  }

  using State = ConstraintState;
  static constexpr Scalar inf() { return std::numeric_limits<Scalar>::infinity(); }
  static Scalar clamp(Scalar v, Scalar lo, Scalar hi) { return v < lo ? lo : (v > hi ? hi : v); }
  /// Iterations on an unchanged working set without a 10 % fall of the merit before `stalled`.
  static constexpr int kStallIterations = 10;
  /// Singular-step drops remembered by the anti-cycling rule.
  static constexpr int kDropMemory = 8;
  /// The primal regularisation's cap is reg_primal_max or, for a large cost, this many units of
  /// round-off of the curvature scale h (float: 1.2e-4 h), whichever is larger: enough for the
  /// pivots that round-off of a positive semidefinite H breaks, never enough to hide a
  /// curvature of -1e-3 h or below (the exact-Hessian SQP falls back on non_convex).
  static constexpr Scalar kRoundoffPivots = 1000;
  /// Iterations with incrementally updated products before they are recomputed from scratch.
  static constexpr int kExactEvery = 10;

  Scalar lb(int i) const { return i < NV ? lbx(i) : lba(i - NV); }
  Scalar ub(int i) const { return i < NV ? ubx(i) : uba(i - NV); }
  Scalar zval(int i) const { return i < NV ? x(i) : za_(i - NV); }
  Scalar dzval(int i) const { return i < NV ? dx_(i) : dza_(i - NV); }
  Scalar& lam(int i) { return i < NV ? lam_x(i) : lam_a(i - NV); }
  Scalar lam(int i) const { return i < NV ? lam_x(i) : lam_a(i - NV); }
  Scalar dlam(int i) const { return i < NV ? dlam_x_(i) : dlam_a_(i - NV); }
  /// Norm of constraint i's row (1 for a bound): divides its violation and multiplies its
  /// multiplier, so that every test is invariant to scaling a row.
  Scalar rnorm(int i) const { return i < NV ? Scalar(1) : rn_(i - NV); }
  /// Target value of an active constraint.
  Scalar target(int i) const { return ws[i] == State::lower ? lb(i) : ub(i); }
  /// Active on one side (not inactive, not an equality).
  bool one_sided(int i) const { return ws[i] == State::upper || ws[i] == State::lower; }
  /// Largest ratio residual / tolerance of the last evaluate() (<= 1: solved).
  Scalar merit_of(const QpSettings<Scalar>& s) const {
    return std::max(std::max(pr_ / (s.tol_primal * pr_scale_), du_ / (s.tol_dual * du_scale_)),
                    co_ / (s.tol_comp * pr_scale_));
  }
  /// An entry of the Farkas direction: the multiplier step y of a constraint with bounds lo, hi,
  /// or 0 on a side whose bound is infinite or when not finite.
  static Scalar farkas_entry(Scalar y, Scalar lo, Scalar hi) {
    if (y == 0 || !std::isfinite(y))
      return Scalar(0);
    return (y > 0 ? hi < inf() : lo > -inf()) ? y : Scalar(0);
  }
  /// Threshold above which a wrong-sign multiplier (per constraint) fails the termination test.
  Scalar drop_threshold(const QpSettings<Scalar>& s) const {
    return std::min(s.tol_dual * du_scale_, s.tol_comp * pr_scale_);
  }

  // ---- the steps of solve()
  /// Repairs a non-finite iterate, builds the working set and the row weights, resets the loop.
  template <typename Backend>
  void begin(Backend& be, const QpSettings<Scalar>& s);
  /// The iteration loop's state at the start of a solve (counters, memories, pending change).
  void reset_loop();
  /// Working set from the multipliers' signs; zeroes multipliers that cannot be active.
  void working_set_from_multipliers();
  /// The scalar residuals below from z = A x, hx = H x and r = H x + g + lam_x + A' lam: with
  /// exact, these products are computed from scratch first, else take_step() updated them.
  /// split > 0 (presolve()): the pass over the constraints [split, nz) is also kept in pre_scan_.
  template <typename Backend>
  void evaluate(const Backend& be, bool exact = true, int split = 0);
  /// The running maxima of evaluate()'s pass over the constraints (see there).
  struct Scan {
    Scalar pscale = 1, pr = 0, co = 0, pr_abs = 0, co_abs = 0, sd = 0, pc = 0;
    int isd = -1, ipc = -1;
    ConstraintState spc = ConstraintState::inactive;
  };
  /// evaluate()'s pass over the constraints [from, to), continuing sc.
  void scan(Scan& sc, int from, int to) const;
  /// a <- the pass over a's constraints then b's (which follow them).
  static void merge(Scan& a, const Scan& b);
  /// The residual members from a finished pass.
  void store(const Scan& sc);
  /// evaluate() after presolve() when only the first pre_n_ bounds moved (solve_from()), or
  /// bounds after them too (move_bound(): the whole pass again).
  void scan_moved();
  /// The change change_working_set() would make now (-1: none) and the constraint's next state.
  int due_change(const QpSettings<Scalar>& s, State& side) const;
  /// True when converged_or_stopped() might end the loop (a conservative test, no side effects).
  bool may_stop(const QpSettings<Scalar>& s, int it) const {
    return !std::isfinite(pr_) || !std::isfinite(du_) || merit_of(s) <= 1 || unbounded_candidate_ ||
           certificate_count_ >= 2 || stall_count_ + 1 >= kStallIterations || it >= s.max_iter;
  }
  /// Keeps the best iterate; true (with the status) when the loop must end here.
  bool converged_or_stopped(const QpSettings<Scalar>& s, int it, QpStatus& status);
  /// Makes at most one working-set change; true when one was made.
  template <typename Backend>
  bool change_working_set(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info);
  /// Refactorizes after a change, raising delta on pivot failures; false when it exceeds its cap.
  template <typename Backend>
  bool refactorize(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info);
  /// (dx, dz, dlam): the step to the regularised equality-constrained QP of the working set.
  /// Presolve (presolve()): only what move_presolved_step() does not recompute (no A dx on the
  /// path rows, no multiplier steps of the weighted constraints: those of the working bounds are
  /// zero, move_bound() adds its target moves there).
  template <bool Presolve = false, typename Backend>
  void compute_step(const Backend& be);
  /// presolve()'s step plus its response to the fixed steps' move in tmpv_ and to the working
  /// bounds' target moves move_bound() left in dlam_x_ (solve_from()).
  template <typename Backend>
  void move_presolved_step(const Backend& be);
  /// The multiplier steps after a response d of the step to another right-hand side was added
  /// (dx_ and dza_ hold it, tmpv_ and tmpa_ the backend's multipliers of the fixed variables and
  /// exact rows for d: those are added); the weighted constraints' from the new step, w (x - t +
  /// dx): added (Add: refine_step()'s second proximal step) or set (move_presolved_step(), whose
  /// presolve() left them free). O(NV + NA).
  template <bool Add, typename Backend>
  void response_multipliers();
  /// Two sums of the multipliers (values, magnitudes): whether presolve()'s still hold.
  std::array<Scalar, 2> lam_checksum() const {
    return {lam_x.sum() + lam_a.sum(), lam_x.cwiseAbs().sum() + lam_a.cwiseAbs().sum()};
  }
  /// A full step that nothing blocks lands on the working set's regularised solution, which
  /// misses the constraints held by weights by eps |dlam_i| |a_i| (per constraint); when that
  /// would fail the primal test, one more proximal step on the same factorization (centred at
  /// the new multipliers) is added to the step. True when it was.
  template <typename Backend>
  bool refine_step(const Backend& be, const QpSettings<Scalar>& s);
  /// Longest step in [0, 1] keeping constraints within tolerance and multiplier signs; sets the
  /// pending change of the blocking constraint.
  Scalar ratio_test(const QpSettings<Scalar>& s);
  /// Multiplier step length (tau, or longer when a stalled, inconsistent working set must shed
  /// a constraint: QRQP's singular step in multiplier space).
  Scalar singular_dual_step(const QpSettings<Scalar>& s, Scalar tau, bool changed);
  /// The Farkas test of the last step's multiplier change (farkas_step(), counted in
  /// certificate_count_), made after the next evaluate() and only when that one does not end the
  /// loop as `solved` (which reads no certificate): the one-iteration warm starts skip it; nor
  /// at the iteration cap (it) without a certificate before it, where one more could not make the
  /// status `infeasible`. The step's dlam is still in dlam_x_, dlam_a_, and pr_prev_ holds the
  /// primal error it was taken from, so the count is the one a test right after the step would
  /// give.
  template <typename Backend>
  void settle_farkas(const Backend& be, const QpSettings<Scalar>& s, int it) {
    if (!farkas_pending_ || merit_of(s) <= 1)
      return;
    farkas_pending_ = false;
    // at the iteration cap the loop ends here: a first certificate could not make it
    // `infeasible` (two consecutive ones do), so the test would change nothing (the bounded
    // feedback of the NMPC ends at its cap in most samples)
    if (it >= s.max_iter && certificate_count_ == 0)
      return;
    if (farkas_step(be, s, pr_prev_))
      ++certificate_count_;
    else
      certificate_count_ = 0;
  }
  /// Applies the step and flags a possible unbounded direction.
  template <typename Backend>
  void take_step(const Backend& be, const QpSettings<Scalar>& s, Scalar tau, Scalar tau_dual,
                 bool changed);
  /// Returns the best iterate when the loop did not succeed; final residuals and check.
  template <typename Backend>
  QpStatus finish(const Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info,
                  QpStatus status);
  /// True when the multiplier step (dlam) is a Farkas certificate of infeasibility (pr: the
  /// primal error of the iterate the step was taken from).
  template <typename Backend>
  bool farkas_step(const Backend& be, const QpSettings<Scalar>& s, Scalar pr);
  template <typename Backend>
  bool unboundedness_certificate(const Backend& be, const QpSettings<Scalar>& s);

  // residuals of the last evaluate()
  // (per constraint: a violation is divided by the row's norm, a multiplier multiplied by it)
  Scalar pr_ = 0;        ///< max violation, per constraint (row norm 1)
  Scalar du_ = 0;        ///< max |stationarity residual|
  Scalar co_ = 0;        ///< complementarity residual, per constraint
  Scalar pr_abs_ = 0;    ///< max violation as the data state it (reported)
  Scalar co_abs_ = 0;    ///< complementarity residual as the data state it (reported)
  Scalar pr_scale_ = 1;  ///< 1 + max(1, |x|_inf, |z_i| / |a_i|): scale of primal and compl. tol.
  Scalar du_scale_ = 1;  ///< 1 + largest term of H x + g + A' lam (scale of the dual one)
  Scalar sd_ = 0;        ///< max wrong-sign multiplier on the working set, per constraint
  int isd_ = -1;         ///< its index
  Scalar pc_ = 0;        ///< max violation among constraints not active on that side (per c.)
  int ipc_ = -1;         ///< its index
  State spc_ = State::inactive;  ///< the violated side

  // state of the iteration loop
  Scalar delta_ = 0;                    ///< primal regularisation in use
  Scalar w_ = 0;                        ///< bound weight h / eps
  Scalar h_ = 1;                        ///< curvature scale: largest |H_ii| (1 when H = 0)
  int pending_ = -1;                    ///< index of a pending change from the ratio test
  State pending_ws_ = State::inactive;  ///< its next working-set state
  bool refactor_ = true;                ///< the factorization is out of date
  Scalar best_ = 0;                     ///< best merit so far
  bool have_best_ = false;              ///< best_x_ etc. hold an iterate
  bool unbounded_candidate_ = false;    ///< the last step was an unbounded-direction candidate
  int certificate_count_ = 0;           ///< consecutive steps with a Farkas certificate
  int stall_count_ = 0;                 ///< iterations without a change and without progress
  Scalar stall_ref_ = 0;                ///< merit at the last change or progress
  std::array<int, kDropMemory> singular_drops_{};  ///< last constraints the singular step dropped
  int next_drop_ = 0;                              ///< ring position in singular_drops_
  int cycles_ = 0;                                 ///< repeated singular drops refused
  bool refining_ = false;  ///< the previous iteration left the working set unchanged
  /// First iteration of a warm start (the multipliers named an inequality): no constraint is
  /// added before one step on the working set they name
  bool warm_first_ = false;
  Scalar pr_prev_ = 0;           ///< primal error of the previous iteration
  bool exact_ = true;            ///< the last evaluate() computed the products from scratch
  bool exact_next_ = true;       ///< the next evaluate() computes them from scratch
  bool refined_ = false;         ///< refine_step() used r_ as workspace in this iteration
  bool farkas_pending_ = false;  ///< the last step's certificate test is still to be made
  int since_exact_ = 0;          ///< steps since the products were last computed from scratch

  VecA za_;                   ///< A x
  VecV hx_;                   ///< H x
  VecV r_;                    ///< stationarity residual
  VecV dx_;                   ///< primal step (also the right-hand side)
  VecA dza_;                  ///< A dx
  VecV dlam_x_;               ///< bound-multiplier step
  VecA dlam_a_;               ///< row-multiplier step
  VecA tmpa_;                 ///< row workspace
  VecA wa_;                   ///< regularisation weight of each row, h / (eps |a_j|^2)
  VecA rn_;                   ///< row norms |a_j| (1 for a zero row)
  VecV tmpv_;                 ///< variable workspace (certificates)
  VecV best_x_;               ///< best iterate so far
  VecV best_lam_x_;           ///< its bound multipliers
  VecA best_lam_a_;           ///< its row multipliers
  bool prefactored_ = false;  ///< prefactorize() left a factorization to reuse
  std::array<ConstraintState, nz> pre_ws_{};  ///< the working set it factorized
  Scalar pre_w_ = 0;                          ///< the bound weight it used
  bool finite_ = true;        ///< every entry the last evaluate()'s pass read was finite
  Scan pre_scan_{};           ///< presolve()'s pass over the constraints after the moved bounds
  int presolved_ = 0;         ///< presolve() left the first step for this many targets
  int pre_n_ = 0;             ///< solve_from()'s moved targets (its first pass)
  bool pre_step_ = false;     ///< presolve() computed the first step (no change due first)
  bool pre_rescan_ = false;   ///< move_bound() moved bounds after the targets: the whole pass
  bool pre_targets_ = false;  ///< ... and targets of working bounds (in dlam_x_)
  std::array<Scalar, 2> pre_lam_{};  ///< lam_checksum() at presolve()
  bool pre_relative_ = false;        ///< QpSettings::relative_regularisation at presolve()
};

}  // namespace arbor::qp::detail
