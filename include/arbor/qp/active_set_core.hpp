// arbor::qp::detail: ActiveSetCore, the primal-dual active-set method's iterate, bounds and
// workspace and the order of its steps (iterate()); the method is described in active_set.hpp,
// the steps are defined in active_set_evaluate.hpp (residuals), active_set_step.hpp (working-set
// change, factorization, step, ratio test) and active_set_termination.hpp (termination tests,
// certificates, the returned point), and active_set_prepared.hpp (the prepared start of
// real-time iteration: prepared_start.hpp). Memory: about 14 NV + 9 NA scalars and 2 (NV + NA)
// bytes.
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
#include "arbor/qp/prepared_start.hpp"
#include "arbor/qp/residual_scan.hpp"
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

  using Prepared = PreparedStart<Scalar, NV>;

  /// x = projection of 0 onto the bounds, all multipliers zero.
  void cold_start() {
    for (int i = 0; i < NV; ++i)
      x(i) = clamp(Scalar(0), lbx(i), ubx(i));
    lam_x.setZero();
    lam_a.setZero();
    note_change();
  }

  /// Records a change of what a prepared start depends on (the iterate, the vectors or the
  /// matrices): every PreparedStart made before it is invalid. The solvers call it for each
  /// operation that writes them (ActiveSetSolver::set_warm_start(), update(), shift(), ...); the
  /// steps here call it themselves.
  void note_change() { ++revision_; }
  /// Forgets a prefactorization (the matrices changed), and with it every prepared start.
  void discard_prefactorization() {
    factor_ = Factor::out_of_date;
    note_change();
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
    begin(be, s);
    SolveInfo<Scalar> info{};
    const bool ok = refactorize(be, s, info) && delta_ == s.reg_primal;
    stages = info.stages_factorized;
    factor_ = ok ? Factor::prepared : Factor::out_of_date;
    pre_ws_ = ws;
    pre_w_ = w_;
    return ok;
  }

  /// Real-time iteration's preparation (active_set_prepared.hpp): prefactorize() and the first
  /// step of a solve from x = 0 (x is set to 0 here) with the current multipliers and vectors,
  /// for a QP that differs from this one only in the targets of the first n variables' bounds
  /// (equalities the backend holds exactly: the OCP's x_0). The returned start is valid until
  /// note_change() (any write of the iterate, the vectors or the matrices, any solve).
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  [[nodiscard]] Prepared prepare_start(Backend& be, const QpSettings<Scalar>& s, int n);

  /// The solve from x = 0 with the first n variables' bounds moved to lbx = ubx = t (n values):
  /// with a valid prepared start for these n targets and the same regularisation settings, the
  /// first iteration takes its step plus the response to the move (active_set_prepared.hpp);
  /// otherwise solve(). The same iterates as solve() to round-off.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  [[nodiscard]] QpStatus solve_from(Backend& be, const QpSettings<Scalar>& s,
                                    SolveInfo<Scalar>& info, const Prepared& prepared,
                                    const Scalar* t, int n);

  /// Sets the bounds of variable i (lo <= hi, not NaN: the caller checks). prepared (may be null)
  /// stays valid when the working set its preparation factorized still holds for the new bounds
  /// (active_set_prepared.hpp); every other prepared start is invalid afterwards.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  void move_bound(Prepared* prepared, int i, Scalar lo, Scalar hi);

  /// Runs the method from the current (x, lam); fills info; returns the status.
  template <ActiveSetBackend<Scalar, NV, NA> Backend>
  [[nodiscard]] QpStatus solve(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info) {
    info = SolveInfo<Scalar>{};
    begin(be, s);
    return iterate(be, s, info, nullptr);
  }

 private:
  /// The iterations of solve() and solve_from() (prepared: the first iteration starts from the
  /// prepared start's pass and step, moved by the fixed steps in fixed_).
  template <typename Backend>
  QpStatus iterate(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info,
                   const Prepared* prepared) {
    QpStatus status = QpStatus::iteration_limit;
    for (int it = 0;; ++it) {
      // prepared: the products at x = 0 are the preparation's and only the first bounds moved:
      // their residuals merged with its pass over the rest (products not from scratch: a loop
      // that may end here judges products from scratch, below); at the iteration cap, where the
      // loop ends, the products from scratch at once instead of updated and then recomputed
      if (prepared != nullptr && it == 0)
        scan_moved(*prepared);
      else
        evaluate(be, next_products_ == Products::from_scratch || it >= s.max_iter);
      settle_farkas(be, s, it);
      if (products_ == Products::updated && may_stop(s, it)) {
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
      // (a change in the first iteration is known at the preparation, not from the targets:
      // then the preparation kept no step, and this iteration computes its own)
      if (prepared != nullptr && it == 0 && !changed && prepared->first_ == Prepared::Reuse::step) {
        move_presolved_step(be, *prepared);
        info.presolved = true;
      } else {
        compute_step(be);
      }
      Scalar tau = ratio_test(s);
      const bool refined = tau == Scalar(1) && pending_ < 0 && refine_step(be, s);
      if (refined)
        tau = ratio_test(s);
      const Scalar tau_dual = singular_dual_step(s, tau, changed);
      take_step(be, s, tau, tau_dual, changed, refined);
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
  /// kept (prepare_start()): the pass over the constraints [kept->n_, nz) is also kept there,
  /// with whether every entry it read was finite.
  template <typename Backend>
  void evaluate(const Backend& be, bool exact = true, Prepared* kept = nullptr);
  /// What a pass over the constraints reads (ResidualScan).
  ConstraintValues<Scalar, NV, NA> values() const {
    return {x, lbx, ubx, lam_x, za_, lba, uba, lam_a, rn_, ws.data()};
  }
  /// The residual members from a finished pass.
  void store(const ResidualScan<Scalar>& sc);
  /// evaluate() in solve_from()'s first iteration: only the first n bounds moved since the
  /// preparation (their pass merged with its kept one), or bounds after them too (move_bound():
  /// the whole pass again); the products are the preparation's.
  void scan_moved(const Prepared& prepared);
  /// The change change_working_set() would make now (-1: none) and the constraint's next state.
  int due_change(const QpSettings<Scalar>& s, State& side) const;
  /// Whether the first iteration of a warm start is still due (see PreviousStep).
  bool warm_first() const { return previous_ == PreviousStep::none_warm; }
  /// The previous iteration left the working set unchanged (its step refined the iterate).
  bool refining() const { return previous_ == PreviousStep::kept; }
  /// best_x_ etc. hold an iterate (best_ starts infinite and falls only with one).
  bool have_best() const { return best_ < inf(); }
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
  /// Prepare (prepare_start()): only what move_presolved_step() does not recompute (no A dx on
  /// the path rows, no multiplier steps of the weighted constraints, which it sets).
  template <bool Prepare = false, typename Backend>
  void compute_step(const Backend& be);
  /// The prepared step plus its response to the fixed steps' move in fixed_ and to the working
  /// bounds' target moves the prepared start holds (solve_from()'s first iteration).
  template <typename Backend>
  void move_presolved_step(const Backend& be, const Prepared& prepared);
  /// The multiplier steps after the step's response to another right-hand side was added (dx_
  /// and dza_ hold the new step, fixed_ and tmpa_ the backend's multipliers of the fixed
  /// variables and exact rows for the response: those are added); the weighted constraints'
  /// from the new step, w (x - t + dx): added (Add: refine_step()'s second proximal step) or set
  /// (move_presolved_step(), whose preparation left them unset). O(NV + NA).
  template <bool Add, typename Backend>
  void response_multipliers();
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
  /// refined: refine_step() corrected the step (the next products are computed from scratch).
  template <typename Backend>
  void take_step(const Backend& be, const QpSettings<Scalar>& s, Scalar tau, Scalar tau_dual,
                 bool changed, bool refined);
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
  /// Where the factorization stands: out of date (the working set changed), current, or
  /// prepared by prefactorize() for the working set pre_ws_ and weight pre_w_ (the next begin()
  /// reuses it when it builds the same).
  enum class Factor : std::uint8_t { out_of_date, current, prepared };
  /// What the previous iteration did to the working set. none_warm: no iteration yet and the
  /// multipliers named an inequality (a warm start), whose first iteration adds no constraint
  /// before one step on the working set they name (a constraint violated only at the start point
  /// is added only when that step leaves it violated); none: no iteration yet otherwise.
  enum class PreviousStep : std::uint8_t { none_warm, none, changed, kept };
  /// How evaluate() obtains A x, H x and r: computed from scratch, or updated by take_step().
  enum class Products : std::uint8_t { from_scratch, updated };
  Scalar delta_ = 0;                    ///< primal regularisation in use
  Scalar w_ = 0;                        ///< bound weight h / eps
  Scalar h_ = 1;                        ///< curvature scale: largest |H_ii| (1 when H = 0)
  int pending_ = -1;                    ///< index of a pending change from the ratio test
  State pending_ws_ = State::inactive;  ///< its next working-set state
  Factor factor_ = Factor::out_of_date;
  Scalar best_ = 0;                   ///< best merit so far (infinite: none yet)
  bool unbounded_candidate_ = false;  ///< the last step was an unbounded-direction candidate
  int certificate_count_ = 0;         ///< consecutive steps with a Farkas certificate
  int stall_count_ = 0;               ///< iterations without a change and without progress
  Scalar stall_ref_ = 0;              ///< merit at the last change or progress
  std::array<int, kDropMemory> singular_drops_{};  ///< last constraints the singular step dropped
  int next_drop_ = 0;                              ///< ring position in singular_drops_
  int cycles_ = 0;                                 ///< repeated singular drops refused
  PreviousStep previous_ = PreviousStep::none;
  Scalar pr_prev_ = 0;                               ///< primal error of the previous iteration
  Products products_ = Products::from_scratch;       ///< how the last evaluate() obtained them
  Products next_products_ = Products::from_scratch;  ///< how the next evaluate() obtains them
  bool farkas_pending_ = false;  ///< the last step's certificate test is still to be made
  int since_exact_ = 0;          ///< steps since the products were last computed from scratch
  std::uint32_t revision_ = 0;   ///< note_change() count: a PreparedStart is valid while it holds

  // vectors: each holds one quantity; scratch ones hold nothing from one step function to the
  // next
  VecA za_;          ///< A x
  VecV hx_;          ///< H x
  VecV r_;           ///< stationarity residual H x + g + lam_x + A' lam_a
  VecV dx_;          ///< primal step (its right-hand side while it is computed)
  VecA dza_;         ///< A dx
  VecV dlam_x_;      ///< bound-multiplier step
  VecA dlam_a_;      ///< row-multiplier step
  VecV fixed_;       ///< the fixed variables' steps in a backend solve, their multipliers out
  VecV response_;    ///< the step's response to another right-hand side (refinement, x_0 move)
  VecA tmpa_;        ///< row scratch (right-hand sides; the exact rows' multipliers out)
  VecV tmpv_;        ///< variable scratch (products of one step function)
  VecA wa_;          ///< regularisation weight of each row, h / (eps |a_j|^2)
  VecA rn_;          ///< row norms |a_j| (1 for a zero row)
  VecV best_x_;      ///< best iterate so far
  VecV best_lam_x_;  ///< its bound multipliers
  VecA best_lam_a_;  ///< its row multipliers
  std::array<ConstraintState, nz> pre_ws_{};  ///< the working set prefactorize() factorized
  Scalar pre_w_ = 0;                          ///< the bound weight it used
};

}  // namespace arbor::qp::detail
