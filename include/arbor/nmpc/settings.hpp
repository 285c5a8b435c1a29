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
  /// constraints active at the same stages of the horizon from sample to sample (the contour
  /// example rides the tunnel at stages 1-7 every sample): there the shifted multipliers put
  /// every edge of that pattern one stage off, and the QP spent its iterations moving them back.
  /// Contour closed loop (examples/contour, RTI, to s = 0.99), QP iterations per sample median /
  /// max / total, shifted -> kept: OCP-FD 14 / 21 / 4 520 -> 4 / 17 / 1 420, OCP-ID 6 / 18 /
  /// 2 143 -> 6 / 18 / 1 930 (bench/nmpc/rti_qp_diag.cpp). Shifting pays when constraints are
  /// met at fixed times instead (a pattern entering the horizon moves one stage per sample: the
  /// OCP-ID loop's first 50 samples took 119 iterations shifted, 171 kept). The exact-Hessian
  /// controller's Lagrangian uses the same multipliers.
  bool shift_multipliers = false;
  /// Settings of the QP solver: its defaults (tolerances 1e-8 in double, 1e-4 in float), with a
  /// higher iteration cap for cold starts of long horizons. Tighter QP tolerances give SQP steps
  /// accurate enough to meet tighter NLP tolerances (the tests comparing with IPOPT use 1e-11),
  /// but the active-set QP may then not reach them on robot-sized problems (the Kinova example
  /// hit the iteration cap at 1e-10).
  /// In double the dual proximal weight is 1e-8 (the QP's default 1e-6 made a pendulum QP from
  /// a constant guess, 40 stages of unstable dynamics, take 4 252 iterations for 42 working-set
  /// changes; 1e-8: 90). The dynamics rows the NMPC adds are never dependent.
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
  /// converged as usual; info().qp_status keeps the QP's own status). Float's default, 100, is a
  /// relative residual of 1e-2: the round-off floor of a float Riccati solve over tens of
  /// ill-conditioned stages lies between its 1e-4 tolerance and there (issue 35: a float RTI loop
  /// after a state jump stalled at merit 2-30 on samples a double loop solved, and replayed its
  /// stale plan); such a step is as good as the QP can make it in float. Double's default, 0,
  /// never takes an unsolved QP (its tolerances sit far above its round-off floor).
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
  /// (qp::OcpQpSolver::presolve), and feedback() adds its response to the measured one (a
  /// forward Riccati sweep) instead of evaluating the QP's residuals and solving: less latency,
  /// more work per sample. The same iterates to round-off. A recovery (relaxed state bounds)
  /// moves the relaxed bounds into the prepared QP (qp::OcpQpSolver::set_state_bounds) and keeps
  /// it while its working set holds; a feedback that starts the interior-point cold start, or
  /// after a change of settings().qp, solves as without it. Cost: one more Riccati solve per
  /// sample (the response), moved with most of the first QP iteration from the feedback into
  /// the preparation; on the contour task (bench/nmpc/RESULTS.md, instructions) the feedback
  /// -23 % on the host and -22 % on the Cortex-M7, the sample +3.8 % and +2.2 %. On by default
  /// (the latency from measurement to control is the feedback's); off where the sample's total
  /// alone decides.
  bool presolve_feedback = true;
  /// A proximal term on the inputs: mu added to the diagonal of every path stage's input Hessian
  /// (the nu input rows, not the slacks), so that each QP also minimises mu/2 |du|^2: a
  /// Levenberg-Marquardt damping of the step. Converged solutions stay where they are (du = 0
  /// there: the KKT conditions are unchanged), so solve() reaches the same optimum, in more
  /// iterations when mu is large. Its use is the real-time iteration (one step per sample), and
  /// its window is narrow: on a random 7-DoF robot with a hard tunnel, a measured-state jump of
  /// 0.02-0.05 rad started a growing period-2 oscillation of the joint velocities without it
  /// (70-84 of 200 samples on the relaxed fallback, the arm 0.1-0.46 m out of the tunnel); mu =
  /// 1e-3 or 1e-2 removed it (no fallback, back in the tunnel; 6-13 fallback samples instead of
  /// 65-75 after jumps of 0.1-0.3 rad); 1e-4 changed little and 3e-2 or more made the loop
  /// diverge (tests/nmpc/random_matrix_test.cpp, HardTunnelRtiRecoversFromASmallJump...). In the
  /// units of the cost's input Hessian. 0 (the default): no term.
  Scalar input_regularization = Scalar(0);
  /// The interior-point cold start's settings (Nmpc::set_cold_start_workspace).
  qp::IpmSettings<Scalar> cold_start{};
};

}  // namespace arbor::nmpc
