// arbor::nmpc: controller settings with defaults per scalar type (tolerances are absolute, on the
// NLP's KKT residuals in the problem's units; float's are looser for its 24-bit mantissa).
#pragma once

#include <type_traits>

#include "arbor/qp/settings.hpp"

namespace arbor::nmpc {

/// What a controller does when its QP keeps failing (NmpcSettings::fallback).
enum class FallbackPolicy : unsigned char {
  stale_plan,  ///< nothing: control() replays the stale plan (the arm drifts; not safe)
  relax,  ///< the QP again with the state bounds of stages >= 1 and every constraint row dropped
          ///< (always feasible: input bounds only); if that fails too, the stop law if one is set
  stop,   ///< the stop law (Nmpc::set_stop_law) clipped to the input bounds; none set: relax
};

/// Name of a FallbackPolicy value.
constexpr const char* to_string(FallbackPolicy p) {
  switch (p) {
    case FallbackPolicy::stale_plan:
      return "stale_plan";
    case FallbackPolicy::relax:
      return "relax";
    case FallbackPolicy::stop:
      return "stop";
  }
  return "unknown";
}

/// Settings of an Nmpc controller (see the members for the defaults' meaning).
template <class Scalar>
struct NmpcSettings {
  static constexpr bool single = std::is_same_v<Scalar, float>;
  int max_iter = 50;  ///< SQP iterations per solve()
  /// |grad L|_inf <= tol_stationarity (1 + max(|grad f|_inf, |lambda|_inf)) (relative, as the
  /// QP's tolerances)
  Scalar tol_stationarity = Scalar(single ? 1e-3 : 1e-8);
  Scalar tol_primal = Scalar(single ? 1e-4 : 1e-8);  ///< defects, bounds, constraints
  /// |lambda * gap| <= tol_complementarity (1 + max(|grad f|_inf, |lambda|_inf))
  Scalar tol_complementarity = Scalar(single ? 1e-3 : 1e-8);
  bool line_search = true;              ///< solve(): L1-merit backtracking (false: full steps)
  int max_line_search = 30;             ///< backtracking steps before line_search_failed
  Scalar armijo = Scalar(1e-4);         ///< sufficient-decrease fraction eta
  Scalar backtrack = Scalar(0.5);       ///< step reduction per backtracking step
  Scalar penalty_margin = Scalar(1.5);  ///< nu >= margin * |lambda|_inf (never decreased)
  /// Whether shift() moves the multipliers one stage earlier with the plan (true), or leaves
  /// them where they are (false, the default): the next QP then starts from the previous
  /// solution's working set stage by stage, as an online active-set strategy does (Ferreau,
  /// Bock, Diehl 2008). A controller that tracks its reference in steady state keeps its
  /// constraints active at the same stages of the horizon from sample to sample: there the
  /// shifted multipliers put every edge of that pattern one stage off, and the QP spends its
  /// iterations moving them back (docs/nmpc.md section 2, warm start: the contour loop's QP
  /// iterations). Shifting pays when constraints are met at fixed times instead (a pattern
  /// entering the horizon moves one stage per sample). The exact-Hessian controller's
  /// Lagrangian uses the same multipliers.
  bool shift_multipliers = false;
  /// Settings of the QP solver: its defaults (qp/settings.hpp), with a higher iteration cap for
  /// cold starts of long horizons. Tighter QP tolerances give SQP steps accurate enough to meet
  /// tighter NLP tolerances, but the active-set QP may then not reach them on robot-sized
  /// problems (docs/nmpc.md section 2, termination).
  /// In double the dual proximal weight is below the QP's default: a larger one slows the
  /// working-set changes of long horizons of unstable dynamics (bench/nmpc/RESULTS.md: a
  /// pendulum QP from a constant guess). The dynamics rows the NMPC adds are never dependent.
  qp::QpSettings<Scalar> qp = [] {
    qp::QpSettings<Scalar> s{};
    s.max_iter = 1000;
    if constexpr (!single)
      s.reg_dual = Scalar(1e-8);
    return s;
  }();
  /// A measured state outside its bounds (those of stage 0: the problem's unless set with
  /// set_state_bounds(0, ...)) by more than tol_primal: on stages k = 1..recovery_stages the
  /// violated bounds are relaxed to the straight line from the measured value back to the bound
  /// at stage recovery_stages + 1 (bound + v (K + 1 - k) / (K + 1), v the violation); the call
  /// returns recovering. 0: no relaxation (the QP is then infeasible whenever no control brings
  /// the state inside at stage 1).
  int recovery_stages = 3;
  /// The fallback applies from the max_failed_samples-th consecutive call whose QP failed
  /// (before that, qp_failed and the stale plan); >= 1.
  int max_failed_samples = 2;
  FallbackPolicy fallback = FallbackPolicy::relax;  ///< see FallbackPolicy
  /// A QP that ends `stalled` or at its iteration cap with its largest residual within this many
  /// tolerances (qp::SolveInfo::merit) still gives the step (the call reports step_taken or
  /// converged as usual; info().qp_status keeps the QP's own status). Float's default is a
  /// relative residual of 1e-2: the round-off floor of a float Riccati solve over tens of
  /// ill-conditioned stages lies between its tolerance and there, and such a step is as good as
  /// the QP can make it in float (docs/nmpc.md section 6). Double's default, 0, never takes an
  /// unsolved QP (its tolerances sit far above its round-off floor).
  Scalar accept_stalled_qp = Scalar(single ? 100 : 0);
  /// A bound on the work of feedback(): its QP stops after this many active-set iterations
  /// (0: no bound but qp.max_iter). Each iteration is one linear solve and at most one
  /// working-set change (a rank-one sweep of the factor, at worst a refactorization of the
  /// stages before the change); the first factorization ran in prepare(): the feedback's cost
  /// has a bound known before it runs. Use >= 2: a warm start's first iteration changes no
  /// constraint (qp/active_set.hpp), so 1 follows the previous working set forever. A QP
  /// stopped there gives its last iterate as the step (qp::QpSettings::last_iterate_at_cap):
  /// the dynamics are the QP's, the inputs are clipped to their bounds, x_0 is the measurement,
  /// and the call returns step_limited (info().qp_merit: how far from solved; other constraints
  /// of the plan may be violated until a later sample's QP, which starts from this working set,
  /// finishes). The exact-Hessian controller's Gauss-Newton fallback solves a second QP under
  /// the same bound. solve() is not bounded by it.
  int feedback_qp_iterations = 0;
  /// prepare() also computes the first step of the feedback's QP for the predicted x_0
  /// (qp::OcpQpSolver::prepare_start), and feedback() adds its response to the measured one (a
  /// forward Riccati sweep) instead of evaluating the QP's residuals and solving: less latency,
  /// more work per sample. The same iterates to round-off. A recovery (relaxed state bounds)
  /// moves the relaxed bounds into the prepared QP (qp::OcpQpSolver::set_state_bounds) and keeps
  /// it while its working set holds; a feedback that starts the interior-point cold start, or
  /// after a change of settings().qp, solves as without it. Cost: one more Riccati solve per
  /// sample (the response), moved with most of the first QP iteration from the feedback into
  /// the preparation (docs/nmpc.md section 7: the contour task's figures). On by default (the
  /// latency from measurement to control is the feedback's); off where the sample's total alone
  /// decides.
  bool presolve_feedback = true;
  /// A proximal term on the inputs: mu added to the diagonal of every path stage's input Hessian
  /// (the nu input rows, not the slacks), so that each QP also minimises mu/2 |du|^2: a
  /// Levenberg-Marquardt damping of the step. Converged solutions stay where they are (du = 0
  /// there: the KKT conditions are unchanged), so solve() reaches the same optimum, in more
  /// iterations when mu is large. Its use is the real-time iteration (one step per sample), where
  /// it can damp an oscillation of the undamped steps; its window is narrow, too small changes
  /// nothing and too large makes the loop diverge (docs/nmpc.md section 7, damping; the test:
  /// tests/nmpc/random_matrix_test.cpp). In the units of the cost's input Hessian. 0 (the
  /// default): no term.
  Scalar input_regularization = Scalar(0);
  /// The interior-point cold start's settings (Nmpc::set_cold_start_workspace).
  qp::IpmSettings<Scalar> cold_start{};
};

}  // namespace arbor::nmpc
