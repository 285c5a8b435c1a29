// arbor::nmpc: what a controller call reports (NmpcStatus) and the figures of the last call
// (NmpcInfo). Every failure leaves the stored plan unchanged, so control() stays finite and is
// the best available control (the previous plan, shifted).
#pragma once

#include "arbor/qp/status.hpp"

namespace arbor::nmpc {

/// Outcome of a controller call: solve(), prepare(), feedback(), the phases and the setters.
enum class NmpcStatus : unsigned char {
  converged,              ///< solve(): the NLP's KKT residuals are below the tolerances
  step_taken,             ///< feedback() (real-time iteration): one full SQP step was taken
  prepared,               ///< prepare() (feedback() may run), linearize(): the QP is linearised
  iteration_limit,        ///< solve(): max_iter SQP iterations without convergence
  qp_failed,              ///< the QP was rejected or not solved (NmpcInfo::qp_status says why)
  line_search_failed,     ///< solve(): no step length gave sufficient merit decrease
  non_finite_input,       ///< NaN/Inf in the measured state, a parameter, a guess or a bound
  non_finite_evaluation,  ///< a function or derivative of the OCP evaluated to NaN/Inf
  not_prepared,           ///< feedback() without a successful prepare() since the last one
  /// the measured state violates a state bound: the step was taken (solve(): the iterations ended)
  /// with the violated bounds relaxed on the first stages (NmpcSettings::recovery_stages), so
  /// the plan brings the state back instead of assuming the violation away
  recovering,
  /// the QP kept failing (NmpcSettings::max_failed_samples): control() is the relaxed QP's
  /// (state bounds of stages >= 1 and constraint rows dropped for this call, input bounds kept)
  fallback_relaxed,
  /// the QP kept failing: control() is the user's stop law (Nmpc::set_stop_law) clipped to the
  /// input bounds
  fallback_stop,
  /// feedback(): the QP stopped at the user's bound on its iterations
  /// (NmpcSettings::feedback_qp_iterations) before it was solved; its last iterate's step was
  /// taken (dynamics held, inputs clipped to their bounds); info().qp_merit says how far from
  /// solved it was. The next sample's QP continues from its working set.
  step_limited,
  /// a setter (set_initial_guess, set_state_guess, set_input_guess): the value was stored;
  /// feedback() needs a prepare() after it
  accepted,
};

/// Name of a status, for logs and test messages.
constexpr const char* to_string(NmpcStatus s) {
  switch (s) {
    case NmpcStatus::converged:
      return "converged";
    case NmpcStatus::step_taken:
      return "step_taken";
    case NmpcStatus::prepared:
      return "prepared";
    case NmpcStatus::iteration_limit:
      return "iteration_limit";
    case NmpcStatus::qp_failed:
      return "qp_failed";
    case NmpcStatus::line_search_failed:
      return "line_search_failed";
    case NmpcStatus::non_finite_input:
      return "non_finite_input";
    case NmpcStatus::non_finite_evaluation:
      return "non_finite_evaluation";
    case NmpcStatus::not_prepared:
      return "not_prepared";
    case NmpcStatus::recovering:
      return "recovering";
    case NmpcStatus::fallback_relaxed:
      return "fallback_relaxed";
    case NmpcStatus::fallback_stop:
      return "fallback_stop";
    case NmpcStatus::step_limited:
      return "step_limited";
    case NmpcStatus::accepted:
      return "accepted";
  }
  return "unknown";
}

/// True when the call did what it was asked (recovering included: the request was met as well
/// as the measured state allows; step_limited too: the step the user's bound on the work
/// allowed).
constexpr bool succeeded(NmpcStatus s) {
  return s == NmpcStatus::converged || s == NmpcStatus::step_taken || s == NmpcStatus::prepared ||
         s == NmpcStatus::recovering || s == NmpcStatus::step_limited || s == NmpcStatus::accepted;
}

/// True when control() comes from a fallback (the QP kept failing).
constexpr bool fell_back(NmpcStatus s) {
  return s == NmpcStatus::fallback_relaxed || s == NmpcStatus::fallback_stop;
}

/// Figures of the last solve(), or of the last prepare()/feedback() pair.
template <class Scalar>
struct NmpcInfo {
  int iterations = 0;                                ///< SQP iterations (QP solves) of the call
  int qp_iterations = 0;                             ///< active-set iterations, summed over the QPs
  qp::QpStatus qp_status = qp::QpStatus::not_setup;  ///< status of the last QP call
  Scalar stationarity = 0;     ///< |grad_w L|_inf at the last linearisation point
  Scalar primal_residual = 0;  ///< max |defect|, bound or constraint violation
  Scalar complementarity = 0;  ///< max |multiplier * distance to its bound|
  Scalar step_norm = 0;        ///< |d|_inf of the last QP step (before alpha)
  Scalar step_size = 0;        ///< alpha of the last step (1 in real-time mode)
  Scalar merit = 0;            ///< L1 merit at the last accepted point
  Scalar penalty = 0;          ///< the merit's penalty weight nu
  int line_search_steps = 0;   ///< backtracking steps of the last line search
  int hessian_fallbacks = 0;   ///< exact Hessian: iterations redone with Gauss-Newton
  Scalar state_violation = 0;  ///< max violation of a state bound by the measured x0
  int failed_samples = 0;      ///< consecutive calls whose QP failed, this one included
  /// qp::SolveInfo::merit of the last QP: its largest residual / tolerance (<= 1: solved)
  Scalar qp_merit = 0;
  /// interior-point iterations of the QP cold starts of the call (Nmpc::set_cold_start_workspace)
  int qp_ipm_iterations = 0;
  /// the feedback's QP took the first step prepare() computed (NmpcSettings::presolve_feedback;
  /// qp::SolveInfo::presolved): false when it could not (the working set changed in its first
  /// iteration, the QP's settings changed, a cold start ran) or the option is off
  bool qp_presolved = false;
};

}  // namespace arbor::nmpc
