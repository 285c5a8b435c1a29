// arbor::qp: solver statuses and the per-solve report shared by the dense and the OCP solvers.
//
// setup() and update() return accepted or the reason the data were rejected (non_finite,
// invalid_bounds, non_convex). Every solve returns a QpStatus and fills a SolveInfo with the
// residuals of the returned iterate, measured by an explicit final check on the original data
// (never on the working set):
//   primal     max violation of bounds, constraints and dynamics,
//   dual       max |H x + g + A' lam_a + lam_x| (stationarity of the Lagrangian),
//   complementarity  max_i min(|lam_i|, distance of z_i to the bound that lam_i's sign selects).
#pragma once

namespace arbor::qp {

/// Outcome of setup(), update() or solve().
enum class QpStatus : unsigned char {
  accepted,         ///< setup()/update(): the data passed the checks; solve() may run
  solved,           ///< solve(): the final check passed (primal, dual, complementarity in tol.)
  iteration_limit,  ///< max_iter reached; the best iterate and its residuals are returned
  infeasible,       ///< a Farkas certificate (A' y = 0, support of the bounds < 0) was found
  unbounded,        ///< a direction of zero curvature and descent that no constraint blocks
  non_convex,       ///< a stage Hessian (or H) has a negative eigenvalue beyond round-off
  non_finite,       ///< NaN or infinite data (or iterate); bounds may be +-inf, never NaN
  invalid_bounds,   ///< some lower bound is above its upper bound, or lb = +inf / ub = -inf
  not_setup,        ///< solve() when the last setup()/update() was not accepted (or none ran)
  stalled,  ///< no working-set change left and no progress (best iterate and residuals returned)
};

/// Short lowercase name of a status, for logs and test messages.
constexpr const char* to_string(QpStatus s) {
  switch (s) {
    case QpStatus::accepted:
      return "accepted";
    case QpStatus::solved:
      return "solved";
    case QpStatus::iteration_limit:
      return "iteration_limit";
    case QpStatus::infeasible:
      return "infeasible";
    case QpStatus::unbounded:
      return "unbounded";
    case QpStatus::non_convex:
      return "non_convex";
    case QpStatus::non_finite:
      return "non_finite";
    case QpStatus::invalid_bounds:
      return "invalid_bounds";
    case QpStatus::not_setup:
      return "not_setup";
    case QpStatus::stalled:
      return "stalled";
  }
  return "unknown";
}

/// Report of one solve (counts and the residuals of the returned iterate).
template <typename Scalar>
struct SolveInfo {
  int iterations = 0;            ///< active-set iterations (each one linear solve)
  int active_set_changes = 0;    ///< constraints added or dropped
  int factorizations = 0;        ///< (partial) refactorizations after a working-set change
  int stages_factorized = 0;     ///< stage blocks refactorized in total (OCP solver; dense: 1 each)
  int factor_updates = 0;        ///< working-set changes applied as rank-one factor updates (OCP)
  int regularization_bumps = 0;  ///< times the primal regularisation was raised (round-off)
  Scalar primal_residual = 0;    ///< max constraint violation
  Scalar dual_residual = 0;      ///< max |grad of the Lagrangian|
  Scalar complementarity = 0;    ///< max min(|lam_i|, distance to the selected bound)
  Scalar objective = 0;          ///< 1/2 x'Hx + g'x at the returned iterate
  /// Largest ratio residual / tolerance (primal, dual, complementarity, each on its scale as the
  /// termination test) at the returned iterate: <= 1 when solved; how far a stalled or capped
  /// solve ended from its tolerances (a caller may still use a step that ended near them).
  Scalar merit = 0;
  int active_constraints = 0;  ///< size of the final working set (equalities included)
  int cycling_refusals = 0;    ///< drops refused by the anti-cycling rule (active_set.hpp)
  /// The first step was prepare_start()'s, moved to the new initial state (OcpQpSolver's
  /// solve_from()); false when that solve ran as solve().
  bool presolved = false;
};

}  // namespace arbor::qp
