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
//   multiplier has the most wrong sign is dropped. Violations and multipliers are compared per
//   constraint: row i's violation is divided by |a_i|, its multiplier multiplied by |a_i| (the
//   same quantities for any scaling of the row), against the thresholds of the termination test.
//   The first iteration of a warm start (the multipliers name at least one inequality) adds
//   nothing: it steps on the working set they name, and a constraint violated only at the start
//   point (the NMPC's extrapolated terminal state beyond a velocity bound) is added only if that
//   step leaves it violated. (Adding it first cost the contour closed loop two iterations per
//   sample, add and drop: bench/nmpc/RESULTS.md.)
// - The step goes to the solution of the equality-constrained QP of the working set, with a
//   proximal regularisation centred at the current iterate (delta = reg_primal on x,
//   epsilon = reg_dual on the active multipliers):
//     (H + delta I + A_W' E A_W) dx = -(H x + g + A' lam) - A_W' E (A_W x - t_W)
//     dlam_W = E (A_W (x + dx) - t_W),   dlam_i = 0 off the working set,
//   with E = diag(h / (eps |a_i|^2)) (rows normalised; |a_i| = 1 for bounds; h = 1, or with
//   QpSettings::relative_regularisation the largest |H_ii| (1 when H = 0): the weights then
//   dominate the curvature by 1 / eps at every scale of the cost, and a cost multiplied by s
//   gives the same steps, multipliers multiplied by s).
//   A backend that solves some rows exactly (ExactRowBackend in backend.hpp: the OCP's dynamics
//   rows, by a Riccati recursion) leaves them out of E: they hold exactly, D (x + dx) = t_D,
//   and their multiplier steps dlam_D come from its solve (compute_step(); the rows are
//   equalities, so the working-set logic never adds or drops them). Such a backend may hold
//   some bounds exactly too (exact_bound(i): the OCP's inputs and x_0, whose variable it fixes):
//   while in the working set they take no weight, the step puts the variable on its bound
//   (dx_i = t_i - x_i) and their multiplier steps come from the solve as well.
//   A full step that nothing blocks misses the weighted constraints by eps |dlam_i| |a_i|; when
//   that would fail the primal test, refine_step() adds one more proximal step on the same
//   factorization (centred at the new multipliers), so that a warm start on the right working
//   set ends after one iteration instead of two.
//   The matrix is positive definite for any convex H, whatever the working set: redundant or
//   linearly dependent active constraints and directions of zero curvature (states without
//   cost, LPs) never make it singular. Along a zero-curvature direction the step is long
//   (~ gradient / delta) and the ratio test stops it at the first blocking constraint: this is
//   QRQP's null-space step, obtained without predicting the singularity. Because the proximal
//   terms are centred at the iterate, a fixed point is an exact KKT point; repeated iterations
//   on an unchanged working set reuse the factorization and act as iterative refinement.
// - When the primal error stalls on an unchanged working set (a nearly inconsistent one), the
//   multipliers are moved along their step to the first active one that reaches zero, which is
//   dropped (QRQP's singular step in multiplier space). Anti-cycling: the last kDropMemory
//   constraints dropped this way are remembered; a constraint that comes back and would be
//   dropped again is kept (the error stalls at round-off, not on an inconsistent set), and the
//   refusal is counted in SolveInfo::cycling_refusals. (Without it, the float Kinova-sized
//   benchmark problem dropped and re-added the same three bounds until the iteration cap.)
// - Ratio test on tau in [0, 1]: inactive constraints may not cross their bound by more than
//   |a_i| max(tol_primal * scale, current max per-constraint violation) (primal blocking ->
//   pending add), active multipliers of the right sign may not cross zero (dual break point ->
//   pending drop).
// - Termination by an explicit check on the original data, judged per constraint:
//     primal     max_i violation_i / |a_i|                 <= tol_primal * pscale,
//     dual       max_j |(H x + g + lam_x + A' lam)_j|     <= tol_dual * dscale,
//     compl.     max_i min(|lam_i| |a_i|, dist_i / |a_i|)  <= tol_comp * pscale,
//   with pscale = 1 + max(1, |x|_inf, max_i |z_i| / |a_i|) and dscale = 1 + the largest term of
//   the stationarity sum, dist_i the distance of z_i to the bound lam_i's sign selects. Scaling
//   a row changes none of these (stationarity contains a_i lam_i only), so `solved` is never
//   returned at a point that violates a row relative to its own size. SolveInfo reports the
//   residuals as the data state them (unnormalised).
// - Infeasibility: every step's multiplier change y = dlam is tested as a Farkas certificate
//   (after the next evaluate(), unless that one ends the loop as `solved`, or at the iteration
//   cap with no certificate before it, where one more could not change the status:
//   settle_farkas()):
//   with y normalised (sum |y_i| |a_i| = 1), entries on a side with an infinite bound left out,
//   e = y_x + A' y_a and sigma = sum_{y_i>0} ub_i y_i + sum_{y_i<0} lb_i y_i, every x has
//   y'z = e'x and every feasible x has y'z <= sigma; with bscale the largest |bound_i| / |a_i|
//   involved, sigma < -10 tol_primal (1 + bscale) and |e|_1 (1 + bscale) <= tol_certificate
//   |sigma| prove that no point within (1 + bscale) / tol_certificate is feasible (scales of the
//   data, not of the iterate, which a long step along a free direction may have inflated). On an
//   inconsistent working set dlam settles on such a direction within a few iterations whatever the
//   size of H or of the rows (the multipliers themselves, which the former test used, turn slowly
//   when the cost is large). Two consecutive certificates give `infeasible`.
// - A full step along a zero-curvature descent direction that no constraint blocks gives
//   `unbounded`. kStallIterations iterations without a working-set change in which the merit
//   (largest residual / tolerance) does not fall by 10 % give `stalled`: the rule has nothing
//   left to change although the test fails (tolerances below the round-off floor, or mutually
//   inconsistent ones). `stalled` and the iteration cap return the best iterate seen, with its
//   residuals (the cap: the last one with QpSettings::last_iterate_at_cap).
// Memory of this part: about 12 NV + 9 NA scalars and 2 (NV + NA) bytes. Cost per iteration: O(NV +
// NA) here plus one backend solve (and one product with A' while the iterate is infeasible, for
// the certificate), and a (partial) refactorization after a working-set change.
// Products: evaluate() needs A x, H x and H x + g + lam_x + A' lam. After a step that a
// constraint blocked (the iteration goes on: the blocking constraint enters or leaves next) they
// are updated instead of recomputed, A x += tau A dx with the step's A dx, H x += tau H dx and
// A' times the multipliers' change: one product with A fewer per such iteration (a product with H
// and one with A' are left). They are computed from scratch at the start (A x and H x are zero
// at x = 0: not formed), after a full unblocked step (the next evaluate() may end the loop), every
// kExactEvery steps, at the iteration cap, and whenever the loop would end on updated ones (the
// test is repeated on products from scratch): every status and every residual reported belongs
// to the returned point as computed from the data.
// Presolved start (presolve(), solve_from(): the NMPC's feedback, whose QP differs from the
// prepared one only in the targets of the first n bounds, fixed variables of the backend): the
// preparation computes the products at x = 0, the first step and the residual pass over the
// constraints after those n; the solve merges the n bounds' residuals into that pass
// (scan_moved()) and adds to the step its response to the targets' move, one backend solve with
// only those fixed steps as right-hand side (move_presolved_step()). The step is linear in its
// right-hand side, so the iterates are solve()'s to round-off. A first iteration that changes
// the working set (known at presolve(): not from the targets) computes its own step; bounds
// moved after presolve() (move_bound(): the NMPC's recovery) keep it while the working set holds,
// with the whole pass again and the moved working targets' response in the same solve.
// The linear algebra lives in a backend satisfying ActiveSetBackend (backend.hpp). solve() runs
// the steps below in this order (iterate()), each a member function: begin() once, then per
// iteration evaluate() (solve_from()'s first: scan_moved()), settle_farkas() (the previous step's
// farkas_step()), a second evaluate() from scratch when the loop may end on updated products,
// converged_or_stopped(), change_working_set(), refactorize(), compute_step() (solve_from()'s
// first, when nothing changed: move_presolved_step()), ratio_test(), refine_step(),
// singular_dual_step(), take_step(); finish() once.
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
    have_best_ = true;
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
  if (!refining_ || merit < Scalar(0.9) * stall_ref_) {
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
bool ActiveSetCore<Scalar, NV, NA>::change_working_set(Backend& be, const QpSettings<Scalar>& s,
                                                       SolveInfo<Scalar>& info) {
  State change_ws;
  const int change = due_change(s, change_ws);
  pending_ = -1;
  warm_first_ = false;
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
  refactor_ = true;
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
  } else if (ipc_ >= 0 && !warm_first_ && pc_ > s.tol_primal * pr_scale_ &&
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
    if (delta_ >
        std::max(s.reg_primal_max, kRoundoffPivots * std::numeric_limits<Scalar>::epsilon() * h_))
      return false;
  }
  ++info.factorizations;
  refactor_ = false;
  return true;
}

template <typename Scalar, int NV, int NA>
template <bool Presolve, typename Backend>
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
      tmpv_(i) = target(i) - x(i);  // the fixed variable's step
    else
      dx_(i) -= w_ * (x(i) - target(i));
  }
  if constexpr (ExactRowBackend<Backend, Scalar, NV, NA>) {
    // D dx = t_D - D x; the backend returns dlam of the exact rows in their entries of tmpa_,
    // and of the working exact bounds in theirs of tmpv_
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
      be.solve_exact(dx_, tmpa_, tmpv_, wa_);
      if constexpr (!Presolve)
        be.path_mul(dx_, dza_);
    } else {
      be.solve_exact(dx_, tmpa_, tmpv_, wa_);
      be.cons_mul(dx_, dza_);
    }
  } else {
    be.solve(dx_);
    be.cons_mul(dx_, dza_);
  }
  if constexpr (Presolve) {
    // (move_presolved_step() recomputes the weighted ones from the moved step)
    for (int i = 0; i < NV; ++i)
      dlam_x_(i) = ws[i] == State::inactive ? -lam_x(i) : (exact_bound(i) ? tmpv_(i) : 0);
    for (int j = 0; j < NA; ++j)
      dlam_a_(j) = exact(j) ? tmpa_(j) : (ws[NV + j] != State::inactive ? 0 : -lam_a(j));
    return;
  }
  for (int i = 0; i < NV; ++i) {
    const State wi = ws[i];
    dlam_x_(i) =
        wi == State::inactive
            ? -lam_x(i)
            : (exact_bound(i) ? tmpv_(i)
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
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::move_presolved_step(const Backend& be) {
  if constexpr (PathProducts<Backend, Scalar, NV, NA> &&
                requires { be.template solve_exact<false, true>(dx_, tmpa_, tmpv_, wa_); }) {
    // The step is linear in the fixed steps: presolve()'s (dx_, dza_, dlam) plus the solve with
    // them alone as right-hand side (v = 0, e = 0: InitialOnly), on the same factorization.
    // hx_ = H x = 0 at x = 0 serves as its v and is zero again afterwards.
    VecV& d = hx_;
    d.setZero();
    tmpa_.setZero();
    if (pre_targets_) {
      // and the working bounds' target moves (move_bound()): v = w t there, a full solve
      for (int i = 0; i < NV; ++i) {
        if (ws[i] != State::inactive && !Backend::exact_bound(i))
          d(i) = w_ * dlam_x_(i);
      }
      be.template solve_exact<false, false>(d, tmpa_, tmpv_, wa_);
    } else {
      be.template solve_exact<false, true>(d, tmpa_, tmpv_, wa_);
    }
    dx_ += d;
    d.setZero();
    // A dx on the path rows (the exact rows' is e, unchanged); the multiplier steps: the exact
    // rows' and fixed variables' by the response, the weighted ones from the moved step (x = 0)
    be.path_mul(dx_, dza_);
    response_multipliers<false, Backend>();
  } else {
    compute_step(be);
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
      dlam_x_(i) += tmpv_(i);
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
    VecV& d = r_;    // workspace: after this step the products are computed from scratch
    refined_ = true;
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
      tmpv_(i) = 0;
    }
    tmpa_.setZero();
    // (e = 0 and the fixed steps are 0: a backend that can skips its products with them)
    if constexpr (requires { be.template solve_exact<true>(d, tmpa_, tmpv_, wa_); })
      be.template solve_exact<true>(d, tmpa_, tmpv_, wa_);
    else
      be.solve_exact(d, tmpa_, tmpv_, wa_);
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
  if (tau == Scalar(1) && pending_ < 0 && !changed && refining_ && pr_ > s.tol_primal * pr_scale_ &&
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
                                              Scalar tau, Scalar tau_dual, bool changed) {
  refining_ = !changed;
  pr_prev_ = pr_;
  if (tau == Scalar(1) && delta_ * dx_.cwiseAbs().maxCoeff() > s.tol_dual &&
      unboundedness_certificate(be, s)) {
    unbounded_candidate_ = true;  // confirmed if the next iterate is primal feasible
  }
  // The products of the next evaluate(): from scratch after a full step that nothing blocked
  // (it lands on the working set's solution, so the next evaluate() may well end the loop, which
  // then needs them from scratch anyway) and every kExactEvery steps (round-off of the updates
  // does not accumulate); else updated here: A x += tau A dx (the step has A dx), H x += tau H dx,
  // r += tau H dx + the multipliers' change (the dropped one's exactly) and A' times it.
  ++since_exact_;
  exact_next_ = since_exact_ >= kExactEvery || (tau == Scalar(1) && pending_ < 0) || refined_;
  refined_ = false;
  const int drop = pending_ >= 0 && pending_ws_ == State::inactive ? pending_ : -1;
  x += tau * dx_;
  if (exact_next_) {
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

template <typename Scalar, int NV, int NA>
template <typename Backend>
QpStatus ActiveSetCore<Scalar, NV, NA>::finish(const Backend& be, const QpSettings<Scalar>& s,
                                               SolveInfo<Scalar>& info, QpStatus status) {
  const bool keep_last = status == QpStatus::iteration_limit && s.last_iterate_at_cap;
  if (status != QpStatus::solved && status != QpStatus::infeasible &&
      status != QpStatus::unbounded && have_best_ && !keep_last) {  // iteration_limit, stalled
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
