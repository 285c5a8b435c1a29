// arbor::nmpc: the NMPC controller: multiple shooting, SQP on the static QP (qp/), with
//   - SCQP (HessianKind::gauss_newton, the paper's method): convex QPs from the outer functions'
//     Hessians, no second derivatives of the dynamics;
//   - exact-Hessian SQP (HessianKind::exact): the Lagrangian's Hessian from the expression layer;
//     an iteration whose QP the solver finds non-convex, or whose step the line search rejects,
//     is redone with the Gauss-Newton Hessian (convex by construction): globally SCQP's
//     robustness, locally Newton steps (stage blocks may be indefinite while the QP is convex on
//     the dynamics' null space);
//   - globalisation of full solves by backtracking on the L1 merit function
//       M(w) = f(w) + nu (|defects|_1 + constraint and bound violations),
//     Armijo on the directional derivative g'd - nu viol(w) (exact for the L1 merit when d solves
//     the QP), nu >= settings().penalty_margin |lambda_QP|_inf, never decreased; non-monotone:
//     the decrease is measured from the largest merit of the last accepted points
//     (Grippo-Lampariello-Lucidi), so full steps near a solution survive the Maratos effect;
//   - real-time iteration: prepare() linearises around the current (shifted) plan and prepares
//     the QP (nmpc/qp_session.hpp) before the state is measured; feedback(x0) embeds x0
//     (dx_0 = x0 - x_0), solves that QP, takes the full step and returns; control() is then u_0.
//     shift() moves the plan one stage (the multipliers too when settings().shift_multipliers
//     is set: see settings.hpp).
//
//   using Ctrl = nmpc::Nmpc<decltype(problem), double>;
//   static Ctrl ctrl(problem);              // big: static storage (sizeof in bench/nmpc)
//   ctrl.set_initial_guess(x_guess, u_guess);
//   if (ctrl.solve(x0) != NmpcStatus::converged) ...;      // full SQP
//   loop: apply(ctrl.control()); ctrl.shift(); ctrl.prepare(); x0 = measure();
//         ctrl.feedback(x0);                               // RTI: latency = feedback only
//
// A failed call (see NmpcStatus) leaves the plan unchanged: control() is always finite, the
// current plan's u_0 (after shift(), the previous plan's u_1). A measured state outside its
// bounds (recovering) and a QP that keeps failing (fallback_relaxed, fallback_stop): the safety
// policy, nmpc/safety.hpp. The multipliers are stored once, in the QP solver (its warm start and
// its result): after qp_failed they are the solver's best iterate (iteration limit, stall) or
// zero (infeasible, unbounded, non-finite); after line_search_failed, the rejected QP's.
// Everything is sized at compile time, nothing allocates, the object is reentrant (its state is
// its members; RBD calls use the workspaces their handles point to, one controller per
// workspace set).
// Cost per SQP iteration: N path linearisations + the terminal one (ocp/linearize.hpp), one QP
// update (vector copies and finiteness checks), one QP solve, and per line-search step N + 1
// stage evaluations without derivatives. In real-time iteration the QP's first factorization
// (and with settings().presolve_feedback its first step) belongs to the preparation: the
// feedback is the QP's iterations only, at most settings().feedback_qp_iterations of them
// (step_limited when that bound stops it).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include "arbor/core/config.hpp"
#include "arbor/nmpc/kkt.hpp"
#include "arbor/nmpc/merit.hpp"
#include "arbor/nmpc/qp_session.hpp"
#include "arbor/nmpc/safety.hpp"
#include "arbor/nmpc/settings.hpp"
#include "arbor/nmpc/status.hpp"
#include "arbor/ocp/generated_stage.hpp"
#include "arbor/ocp/linearize.hpp"

namespace arbor::nmpc {

/// NMPC controller for problem type P (ocp::Problem) at Scalar, Hessian kind H.
template <class P, class Scalar = double, ocp::HessianKind H = ocp::HessianKind::gauss_newton>
class Nmpc {
 public:
  static constexpr int nx = P::nx;       ///< states
  static constexpr int nu = P::nu;       ///< inputs
  static constexpr int np = P::np;       ///< parameters per stage
  static constexpr int ns = P::ns;       ///< slacks per path stage
  static constexpr int nw = nu + ns;     ///< QP inputs per path stage ([u; s])
  static constexpr int N = P::horizon;   ///< shooting intervals
  using Qp = ocp::QpOf<P, Scalar>;       ///< the QP of one SQP iteration
  static constexpr int ng = Qp::ng;      ///< QP rows per path stage (>= 1, see ocp::qp_rows)
  static constexpr int ngn = Qp::ngn;    ///< QP rows of the terminal stage (>= 1)
  using QpSolver = qp::OcpQpSolver<Qp>;  ///< its solver
  using Session = detail::QpSession<Qp, Scalar>;        ///< the solver with its preparation
  using Safety = detail::SafetyPolicy<Scalar, nx, nu>;  ///< recovery and fallback
  using Vx = VecN<Scalar, nx>;                          ///< a state
  using Vu = VecN<Scalar, nu>;                          ///< an input
  using Vw = VecN<Scalar, nw>;                          ///< an input with its slacks
  using Vp = VecN<Scalar, np>;                          ///< stage parameters
  using Settings = NmpcSettings<Scalar>;                ///< settings
  using Info = NmpcInfo<Scalar>;                        ///< figures of the last call
  /// Workspace of the QP's interior-point cold start (set_cold_start_workspace)
  using ColdStart = typename Session::ColdStart;
  /// A control law that stops the system (FallbackPolicy::stop): u = law(x, user), e.g. for a
  /// robot gravity compensation plus joint damping; the controller clips it to the input bounds.
  using StopLaw = typename Safety::StopLaw;

  /// Copies the problem (its expressions and default bounds); plan, parameters and multipliers
  /// start at zero (set a guess with set_initial_guess).
  explicit Nmpc(const P& problem, const Settings& settings = Settings{})
      : problem_(problem), settings_(settings) {
    for (int k = 0; k <= N; ++k) {
      x_[std::size_t(k)].setZero();
      p_[std::size_t(k)].setZero();
      lbx_[std::size_t(k)] = problem.lbx.template cast<Scalar>();
      ubx_[std::size_t(k)] = problem.ubx.template cast<Scalar>();
    }
    for (int k = 0; k < N; ++k) {
      w_[std::size_t(k)].setZero();
      lbu_[std::size_t(k)] = problem.lbu.template cast<Scalar>();
      ubu_[std::size_t(k)] = problem.ubu.template cast<Scalar>();
    }
    session_.reset_multipliers();
  }
  Nmpc(const Nmpc&) = delete;  // the QP solver points into this object
  Nmpc& operator=(const Nmpc&) = delete;

  // ---- data -----------------------------------------------------------------------------------
  /// The same guess on every stage (slacks zero, multipliers reset). Returns accepted or
  /// non_finite_input (nothing stored); the setters below too.
  [[nodiscard]] NmpcStatus set_initial_guess(const Vx& x, const Vu& u) {
    if (!x.allFinite() || !u.allFinite())
      return NmpcStatus::non_finite_input;
    for (auto& xk : x_)
      xk = x;
    for (auto& wk : w_) {
      wk.setZero();
      wk.template head<nu>() = u;
    }
    session_.reset_multipliers();
    prepared_ = false;
    return NmpcStatus::accepted;
  }
  /// Guess of x_k, k = 0..N.
  [[nodiscard]] NmpcStatus set_state_guess(int k, const Vx& x) {
    ARBOR_ASSERT(k >= 0 && k <= N, "state index out of range");
    if (!x.allFinite())
      return NmpcStatus::non_finite_input;
    x_[std::size_t(k)] = x;
    prepared_ = false;
    return NmpcStatus::accepted;
  }
  /// Guess of u_k, k = 0..N-1.
  [[nodiscard]] NmpcStatus set_input_guess(int k, const Vu& u) {
    ARBOR_ASSERT(k >= 0 && k < N, "input index out of range");
    if (!u.allFinite())
      return NmpcStatus::non_finite_input;
    w_[std::size_t(k)].template head<nu>() = u;
    prepared_ = false;
    return NmpcStatus::accepted;
  }
  /// Parameters of stage k = 0..N (checked for finiteness by solve()/prepare()).
  void set_parameter(int k, const Vp& p) {
    ARBOR_ASSERT(k >= 0 && k <= N, "parameter index out of range");
    p_[std::size_t(k)] = p;
    prepared_ = false;
  }
  /// Bounds of x_k, k = 0..N (x_0's are not used: x_0 is the measured state).
  void set_state_bounds(int k, const Vx& lb, const Vx& ub) {
    ARBOR_ASSERT(k >= 0 && k <= N, "state index out of range");
    lbx_[std::size_t(k)] = lb;
    ubx_[std::size_t(k)] = ub;
    prepared_ = false;
  }
  /// Bounds of u_k, k = 0..N-1.
  void set_input_bounds(int k, const Vu& lb, const Vu& ub) {
    ARBOR_ASSERT(k >= 0 && k < N, "input index out of range");
    lbu_[std::size_t(k)] = lb;
    ubu_[std::size_t(k)] = ub;
    prepared_ = false;
  }
  /// Settings (take effect at the next call).
  Settings& settings() { return settings_; }
  /// The QP's cold starts (its multipliers all zero: the first QP, and after a reset by an
  /// infeasible, unbounded or non-finite QP) run the interior point on ws and cross over to the
  /// active set (qp/ocp_interior_point.hpp; info().qp_ipm_iterations); when the interior point
  /// does not converge (an equality other than x_0, an infeasible QP: its iteration cap) the
  /// active set starts cold, as without it. nullptr (the default): the active set starts cold
  /// alone. ws is the caller's (its size: docs/api.md section 2); settings().cold_start holds
  /// its settings. A program that never calls this compiles and links none of the interior
  /// point's code (QpSession::set_cold_start_workspace).
  void set_cold_start_workspace(ColdStart* ws) { session_.set_cold_start_workspace(ws); }
  /// The stop law of the fallback (nullptr: none) and its user pointer.
  void set_stop_law(StopLaw law, void* user = nullptr) { safety_.set_stop_law(law, user); }

  // ---- results --------------------------------------------------------------------------------
  /// The control to apply: u_0 of the current plan (always finite).
  Vu control() const { return w_[0].template head<nu>(); }
  /// x_k of the plan, k = 0..N.
  const Vx& state(int k) const {
    ARBOR_ASSERT(k >= 0 && k <= N, "state index out of range");
    return x_[std::size_t(k)];
  }
  /// u_k of the plan, k = 0..N-1.
  Vu input(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "input index out of range");
    return w_[std::size_t(k)].template head<nu>();
  }
  /// Slacks of the soft path constraints of stage k (in the order of the terms).
  VecN<Scalar, ns> slack(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "stage index out of range");
    return w_[std::size_t(k)].template tail<ns>();
  }
  /// Multipliers of x_{k+1} - F(x_k, u_k, p_k) = 0, k = 0..N-1 (QP sign convention).
  auto dynamics_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "stage index out of range");
    return lam_rows().template segment<nx>(Qp::dynamics_offset(k));
  }
  /// Multipliers of the bounds of x_k, k = 0..N (> 0: upper bound active; at k = 0 the
  /// multiplier of x_0 = x0).
  auto state_bound_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k <= N, "state index out of range");
    return lam_bounds().template segment<nx>(Qp::state_offset(k));
  }
  /// Multipliers of the bounds of [u_k; s_k], k = 0..N-1 (> 0: upper bound active).
  auto input_bound_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "input index out of range");
    return lam_bounds().template segment<nw>(Qp::input_offset(k));
  }
  /// Multipliers of the QP rows of the terminal constraints.
  auto terminal_constraint_multiplier() const { return lam_rows().template tail<ngn>(); }
  /// Multipliers of the QP rows of the path constraints of stage k (> 0: upper side active).
  auto constraint_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "stage index out of range");
    return lam_rows().template segment<ng>(Qp::constraint_offset(k));
  }
  /// Figures of the last call.
  const Info& info() const { return info_; }
  /// The QP of the last linearisation (delta form) and its solver, for inspection.
  const Qp& qp() const { return qp_; }
  /// The QP solver (its info() holds the last QP's figures).
  const QpSolver& qp_solver() const { return session_.solver(); }
  /// The local feedback gain of stage k (0 <= k < N) of the last feedback()'s QP: gain =
  /// du_k / dx_k on the QP's final working set (qp::OcpQpSolver::feedback_gain: the Riccati
  /// recursion's -(M_uu)^-1 M_ux, reused from its factor), so that near the plan
  /// u_0 + gain(0) (x - x_0) is the first input of the QP re-solved from x on the same working
  /// set. Rows of inputs on a bound in that working set are zero (they stay there); state
  /// bounds and constraint rows in it act as the QP holds them, as stiff penalties (docs/nmpc.md,
  /// "Feedback gains"); the slacks of soft constraints respond as free inputs (their rows are
  /// not returned). Valid from a feedback() that took a step (step_taken, recovering,
  /// step_limited: the gain of the working set of the QP's last iterate) until the next
  /// prepare(), solve() or linearize(); shift() does not change it (stage k stays the solved
  /// QP's stage k, the shifted plan's stage k - 1). Returns accepted (gain written), not_prepared
  /// (no feedback() step since the last linearisation: before the first one, after prepare(),
  /// after solve(), whose last iteration ends on a linearisation without its QP) or qp_failed
  /// (the last feedback()'s QP failed or ended in a fallback, or the solver returned an iterate
  /// whose working set it did not factorize; gain not written). Cost (Kinova sizes nx = 16,
  /// nu = 8, no slacks): stage 0 ~6 k multiply-adds, stage k >= 1 ~0.5 k; no heap.
  [[nodiscard]] NmpcStatus feedback_gain(int k, Eigen::Matrix<Scalar, nu, nx>& gain) const {
    ARBOR_ASSERT(k >= 0 && k < N, "stage index out of range");
    if (gain_ != GainState::available)
      return gain_ == GainState::failed ? NmpcStatus::qp_failed : NmpcStatus::not_prepared;
    Eigen::Matrix<Scalar, nw, nx> g;
    if (!session_.solver().feedback_gain(k, g))
      return NmpcStatus::qp_failed;
    gain = g.template topRows<nu>();
    return NmpcStatus::accepted;
  }

  // ---- solving --------------------------------------------------------------------------------
  /// Full SQP from the current plan with x_0 = x0: iterates until the KKT residuals are below
  /// the tolerances (converged) or max_iter steps were taken (iteration_limit), with the L1-merit
  /// line search unless settings().line_search is false.
  [[nodiscard]] NmpcStatus solve(const Vx& x0) {
    info_ = Info{};
    if (!x0.allFinite() || !parameters_finite())
      return NmpcStatus::non_finite_input;
    x_[0] = x0;
    merit_.start(x0);
    for (int it = 0;; ++it) {
      const NmpcStatus lin = linearize();
      if (lin != NmpcStatus::prepared)
        return lin;
      embed(x0);
      const bool recovering = recover(x0);
      record_kkt();
      if (converged() || it == settings_.max_iter) {
        safety_.qp_succeeded();
        info_.failed_samples = 0;
        if (recovering)
          return NmpcStatus::recovering;
        return converged() ? NmpcStatus::converged : NmpcStatus::iteration_limit;
      }
      const NmpcStatus qs = solve_qp();
      if (qs == NmpcStatus::qp_failed)
        return after_qp_failure(x0);
      if (qs != NmpcStatus::step_taken)
        return qs;
      NmpcStatus ls = NmpcStatus::step_taken;
      if (settings_.line_search)
        ls = line_search(x0);
      else
        take_step(Scalar(1));
      if constexpr (H == ocp::HessianKind::exact) {
        if (ls == NmpcStatus::line_search_failed) {  // not a descent step: Gauss-Newton's
          const NmpcStatus gs = gauss_newton_step();
          if (gs != NmpcStatus::step_taken)
            return gs;
          ls = line_search(x0);
        }
      }
      if (ls != NmpcStatus::step_taken)
        return ls;
      x_[0] = x0;  // x_0 = x0 exactly (the QP meets dx_0 = x0 - x_0 to its tolerance)
    }
  }

  /// Real-time iteration, preparation phase: linearises around the current plan (call after
  /// shift()) and prepares its QP. Returns prepared, non_finite_input or non_finite_evaluation
  /// (a QP the solver rejects is left to the feedback, which reports it as qp_failed).
  [[nodiscard]] NmpcStatus prepare() {
    prepared_ = false;
    if (!parameters_finite())
      return NmpcStatus::non_finite_input;
    const NmpcStatus lin = linearize();
    if (lin != NmpcStatus::prepared)
      return lin;
    embed(x_[0]);  // the residuals as if the measurement equalled the prediction
    record_kkt();
    // the QP's matrices are final: its first factorization (for the working set the multipliers
    // name, which the feedback starts from) runs now, before the measurement; the feedback
    // re-reads only the vectors (qp::OcpQpSolver::update_vectors, prefactorize)
    // (and, unless the feedback runs the interior-point cold start, the QP's first step for
    // this x_0: the feedback moves it to the measured one, qp::OcpQpSolver::prepare_start)
    if (session_.update(qp_, settings_.qp, matrices_checked_) == qp::QpStatus::accepted)
      session_.prepare(settings_.presolve_feedback && !session_.cold_start_due());
    prepared_ = true;
    return NmpcStatus::prepared;
  }

  /// Real-time iteration, feedback phase: embeds the measured x0, solves the prepared QP and
  /// takes the full step. Returns step_taken (control() is the new u_0), recovering,
  /// step_limited, not_prepared, non_finite_input (the preparation is kept), qp_failed (the plan
  /// is unchanged), fallback_relaxed, fallback_stop, or non_finite_evaluation (the exact
  /// Hessian's Gauss-Newton redo).
  [[nodiscard]] NmpcStatus feedback(const Vx& x0) {
    if (!prepared_)
      return NmpcStatus::not_prepared;
    if (!x0.allFinite())
      return NmpcStatus::non_finite_input;
    prepared_ = false;
    gain_ = GainState::failed;  // (available once this call's QP gave a step)
    embed(x0);
    const bool recovering = recover(x0);
    info_.iterations = 0;
    info_.qp_iterations = 0;
    info_.qp_presolved = false;  // (set by a solve that ran)
    // the user's bound on the QP's work (settings.hpp, feedback_qp_iterations): an iterate at
    // the bound is a step too
    const QpStep qs = solve_qp(Session::budget(settings_.qp, settings_.feedback_qp_iterations));
    if (qs.status == NmpcStatus::qp_failed)
      return after_qp_failure(x0);
    if (qs.status != NmpcStatus::step_taken)
      return qs.status;
    safety_.qp_succeeded();
    info_.failed_samples = 0;
    take_step(Scalar(1));
    gain_ = GainState::available;
    if (qs.capped) {
      // the iterate of an unfinished QP: its dynamics hold (the Riccati solve meets them
      // exactly), the inputs outside the working set may lie beyond their bounds: clipped, and
      // x_0 is the measurement (the QP may have stopped short of it)
      for (int k = 0; k < N; ++k) {
        auto& wk = w_[std::size_t(k)];
        wk.template head<nu>() =
            wk.template head<nu>().cwiseMax(lbu_[std::size_t(k)]).cwiseMin(ubu_[std::size_t(k)]);
        wk.template tail<ns>() = wk.template tail<ns>().cwiseMax(Scalar(0));
      }
      x_[0] = x0;
      return NmpcStatus::step_limited;
    }
    return recovering ? NmpcStatus::recovering : NmpcStatus::step_taken;
  }

  /// Moves the plan one stage earlier for the next sample: stage k takes stage k+1's values; the
  /// last input repeats and x_N becomes F(x_N, u_{N-1}, p_N) (kept if not finite). The
  /// multipliers move with it when settings().shift_multipliers is set, else they stay where
  /// they are (the next QP's warm start is then the last solution's working set, stage by
  /// stage; see settings.hpp for why that is the default).
  void shift() {
    for (int k = 0; k < N; ++k)
      x_[std::size_t(k)] = x_[std::size_t(k + 1)];
    for (int k = 0; k + 1 < N; ++k)
      w_[std::size_t(k)] = w_[std::size_t(k + 1)];
    const Vu u = w_[N - 1].template head<nu>();
    const Vx xn = ad::evaluate(problem_.dynamics, x_[N], u, p_[N]);
    if (xn.allFinite())
      x_[N] = xn;
    if (settings_.shift_multipliers) {
      session_.shift_multipliers();
    }
    prepared_ = false;
  }

  // ---- the phases of one SQP iteration (public for benchmarks and custom loops) ---------------
  /// Evaluation and linearisation of every stage at the current plan, written into the QP, with
  /// the variable bounds in delta form (x_0's are set by embed()). Returns prepared or
  /// non_finite_evaluation.
  [[nodiscard]] NmpcStatus linearize() { return linearize_as<H>(); }

  /// linearize() with Hessian kind K (the exact-Hessian controller's Gauss-Newton fallback).
  template <ocp::HessianKind K>
  [[nodiscard]] NmpcStatus linearize_as() {
    constexpr Scalar inf = std::numeric_limits<Scalar>::infinity();
    session_.forget();  // new matrices: the QP reads everything again
    // (the solver's factor is the old matrices': no gain)
    gain_ = GainState::none;
    // (checked here, once: the QP's update then assumes them finite)
    matrices_checked_ = false;
    int batched = 0;  // path stages [0, batched) linearised several at a time (generated code)
    if constexpr (K == ocp::HessianKind::gauss_newton)
      batched = linearize_path_batches();
    for (int k = 0; k < N; ++k) {
      auto& st = qp_.stage[std::size_t(k)];
      const std::size_t i = std::size_t(k);
      if (k >= batched) {
        const VecN<Scalar, ng> lg = lam_rows().template segment<ng>(Qp::constraint_offset(k));
        const Vx ld = lam_rows().template segment<nx>(Qp::dynamics_offset(k));
        ocp::linearize_path<K>(problem_, x_[i], w_[i], p_[i], x_[i + 1], ld, lg, st);
      }
      if (settings_.input_regularization > Scalar(0))  // the proximal term (NmpcSettings)
        st.R.diagonal().template head<nu>().array() += settings_.input_regularization;
      if (!qp::detail::all_finite(st.Q, st.S, st.R, st.q, st.r, st.A, st.B, st.b, st.C, st.D) ||
          st.lg.hasNaN() || st.ug.hasNaN())  // (row bounds may be infinite)
        return NmpcStatus::non_finite_evaluation;
      st.lbx = lbx_[i] - x_[i];
      st.ubx = ubx_[i] - x_[i];
      st.lbu.template head<nu>() = lbu_[i] - w_[i].template head<nu>();
      st.ubu.template head<nu>() = ubu_[i] - w_[i].template head<nu>();
      st.lbu.template tail<ns>() = -w_[i].template tail<ns>();  // s >= 0
      st.ubu.template tail<ns>().setConstant(inf);
    }
    auto& t = qp_.terminal;
    const VecN<Scalar, ngn> lgn = lam_rows().template tail<ngn>();
    ocp::linearize_terminal<K>(problem_, x_[N], p_[N], lgn, t);
    if (!qp::detail::all_finite(t.Q, t.q, t.C) || t.lg.hasNaN() || t.ug.hasNaN())
      return NmpcStatus::non_finite_evaluation;
    t.lbx = lbx_[N] - x_[N];
    t.ubx = ubx_[N] - x_[N];
    matrices_checked_ = true;
    return NmpcStatus::prepared;
  }

  /// Embeds the measured state: dx_0 = x0 - x_0.
  void embed(const Vx& x0) {
    embedded_ = x0;
    qp_.stage[0].lbx = x0 - x_[0];
    qp_.stage[0].ubx = qp_.stage[0].lbx;
  }

  /// QP construction (update: the solver re-reads the vectors) and solve, warm-started at d = 0
  /// with the current multipliers. Returns step_taken (the step is in the solver) or qp_failed.
  [[nodiscard]] NmpcStatus solve_qp() { return solve_qp(unbounded()).status; }

  /// The exact-Hessian controller's fallback for one iteration: relinearises with the
  /// Gauss-Newton Hessian (convex by construction) and solves the QP again.
  [[nodiscard]] NmpcStatus gauss_newton_step() { return gauss_newton_step(unbounded()).status; }

  /// Backtracking on the L1 merit along the solver's step (see the top of this file); takes the
  /// accepted step. Returns step_taken or line_search_failed (plan unchanged).
  [[nodiscard]] NmpcStatus line_search(const Vx& x0) {
    const Scalar lam_max =
        std::fmax(lam_bounds().cwiseAbs().maxCoeff(),
                  lam_rows().size() > 0 ? lam_rows().cwiseAbs().maxCoeff() : Scalar(0));
    const Scalar penalty = merit_.raise_penalty(lam_max, settings_.penalty_margin);
    info_.penalty = penalty;
    if (info_.step_norm == Scalar(0)) {
      take_step(Scalar(1));  // only the multipliers change
      return NmpcStatus::step_taken;
    }
    const ocp::StageMerit<Scalar> m0 = merit_at(Scalar(0), x0);
    const Scalar phi_now = m0.cost + penalty * m0.violation;
    const Scalar phi0 = merit_.reference(phi_now);  // non-monotone (MeritHistory)
    Scalar slope = directional_cost_derivative() - penalty * m0.violation;
    if (slope > Scalar(0))
      slope = Scalar(0);  // round-off: require plain decrease
    Scalar alpha = 1;
    for (int i = 0; i <= settings_.max_line_search; ++i) {
      const ocp::StageMerit<Scalar> m = merit_at(alpha, x0);
      const Scalar phi = m.cost + penalty * m.violation;
      // sufficient decrease, up to the rounding noise of evaluating the merit
      const Scalar noise = Scalar(16) * std::numeric_limits<Scalar>::epsilon() * std::fabs(phi_now);
      if (std::isfinite(phi) && phi <= phi0 + settings_.armijo * alpha * slope + noise) {
        info_.line_search_steps = i;
        info_.merit = phi;
        merit_.accept(phi);
        take_step(alpha);
        return NmpcStatus::step_taken;
      }
      alpha *= settings_.backtrack;
    }
    info_.line_search_steps = settings_.max_line_search;
    return NmpcStatus::line_search_failed;
  }

 private:
  using QpBudget = typename Session::Budget;
  /// A QP solve's outcome: step_taken (the step is in the solver), qp_failed, or the exact
  /// Hessian's Gauss-Newton redo's non_finite_evaluation; capped: the QP stopped at its
  /// budget's bound before it was solved (its last iterate is the step).
  struct QpStep {
    NmpcStatus status;
    bool capped;
  };

  /// The budget of a QP solve bounded by the settings' cap only.
  QpBudget unbounded() const { return Session::budget(settings_.qp, 0); }

  /// solve_qp() within budget b.
  QpStep solve_qp(QpBudget b) {
    const qp::QpStatus st = solve_prepared_qp(b);
    if constexpr (H == ocp::HessianKind::exact) {
      if (st == qp::QpStatus::non_convex) {  // this iteration: the Gauss-Newton Hessian
        info_.qp_iterations += solver().info().iterations;
        return gauss_newton_step(b);
      }
    }
    return finish_qp(st, b);
  }

  /// gauss_newton_step() within budget b.
  QpStep gauss_newton_step(QpBudget b) {
    ++info_.hessian_fallbacks;
    const NmpcStatus lin = linearize_as<ocp::HessianKind::gauss_newton>();
    if (lin != NmpcStatus::prepared)
      return {lin, false};
    embed(embedded_);
    return finish_qp(solve_prepared_qp(b), b);
  }

  /// The recovery of a measured x0 outside the state bounds (Safety::relax_violated_bounds),
  /// its relaxed bounds moved into a presolved QP; true when it relaxed.
  bool recover(const Vx& x0) {
    const int K =
        Safety::relax_violated_bounds(settings_, x0, lbx_, ubx_, x_, qp_, info_.state_violation);
    for (int k = 1; k <= K && session_.presolved(); ++k)
      session_.move_state_bounds(k, k < N ? qp_.stage[std::size_t(k)].lbx : qp_.terminal.lbx,
                                 k < N ? qp_.stage[std::size_t(k)].ubx : qp_.terminal.ubx);
    return K > 0;
  }

  /// A call whose QP failed: counts it and, from the max_failed_samples-th consecutive one,
  /// applies the fallback (FallbackPolicy). Returns qp_failed (plan unchanged),
  /// fallback_relaxed (the relaxed QP's step taken) or fallback_stop (control() is the stop
  /// law's).
  NmpcStatus after_qp_failure(const Vx& x0) {
    const detail::Fallback f = safety_.qp_failed(settings_);
    info_.failed_samples = safety_.failed_samples();
    if (f == detail::Fallback::none)
      return NmpcStatus::qp_failed;
    if (f == detail::Fallback::relax) {
      Safety::relax_qp(qp_);
      const QpBudget b = unbounded();
      if (finish_qp(solve_prepared_qp(b), b).status == NmpcStatus::step_taken) {
        take_step(Scalar(1));
        return NmpcStatus::fallback_relaxed;
      }
    }
    Vu u;
    if (safety_.stop_control(x0, lbu_[0], ubu_[0], u)) {
      w_[0].template head<nu>() = u;
      return NmpcStatus::fallback_stop;
    }
    return NmpcStatus::qp_failed;
  }

  /// The multiplier estimate: the QP solver's multipliers (flat; its warm start and its result,
  /// stored once).
  const auto& lam_bounds() const { return session_.solver().lam_x(); }
  /// The Gauss-Newton path stages L = ocp::path_lanes at a time (ocp::linearize_paths: the
  /// generated stage code in SIMD lanes), as many whole groups of L as N holds (linearize_as
  /// does the rest one by one); returns the number of stages done (0 without a batched path:
  /// no generated stages, no SIMD, or the problem's generated or batched flag off).
  int linearize_path_batches() {
    constexpr int L = ocp::path_lanes<P, Scalar>;
    int k0 = 0;
    if constexpr (L > 1) {
      const Scalar* lam = lam_rows().data();
      for (; k0 + L <= N; k0 += L) {
        ocp::PathPoint<Scalar> pt[L];
        typename Qp::Stage* st[L];
        for (int l = 0; l < L; ++l) {
          const int k = k0 + l;
          const std::size_t i = std::size_t(k);
          pt[l] = {x_[i].data(),
                   w_[i].data(),
                   p_[i].data(),
                   x_[i + 1].data(),
                   lam + Qp::dynamics_offset(k),
                   lam + Qp::constraint_offset(k)};
          st[l] = &qp_.stage[i];
        }
        if (!ocp::linearize_paths<L>(problem_, pt, st))
          return 0;
      }
    }
    return k0;
  }

  const auto& lam_rows() const { return session_.solver().lam_a(); }
  QpSolver& solver() { return session_.solver(); }
  const QpSolver& solver() const { return session_.solver(); }

  /// The QP's solve within budget b from what prepare() left (QpSession::solve); its status.
  qp::QpStatus solve_prepared_qp(QpBudget b) {
    return session_.solve(qp_, qp_.stage[0].lbx, settings_.qp, matrices_checked_,
                          settings_.cold_start, b, info_.qp_ipm_iterations);
  }

  /// Records a QP solve within budget b; step_taken when it gave a finite solution (or a capped
  /// iterate), else qp_failed.
  QpStep finish_qp(qp::QpStatus st, QpBudget b) {
    info_.qp_status = st;
    info_.qp_presolved = solver().info().presolved;
    info_.qp_iterations += solver().info().iterations;
    ++info_.iterations;
    // a stall (or the cap) at the scalar's round-off floor, near the tolerances: the step is
    // usable (settings.hpp, accept_stalled_qp)
    info_.qp_merit = solver().info().merit;
    // stopped by the caller's bound (feedback_qp_iterations), not by the settings' cap
    const bool capped = st == qp::QpStatus::iteration_limit && b.last_iterate_at_cap;
    const bool usable = st == qp::QpStatus::solved || capped ||
                        ((st == qp::QpStatus::stalled || st == qp::QpStatus::iteration_limit) &&
                         solver().info().merit <= settings_.accept_stalled_qp);
    // (qp::detail::all_finite: one multiply-add per entry where Eigen's allFinite() takes several)
    if (!usable || !qp::detail::all_finite(solver().x(), lam_bounds(), lam_rows())) {
      // The multipliers are the solver's iterate (one copy, no backup): keep its best iterate
      // (iteration limit, stall) as the next warm start, reset anything else (an infeasibility
      // or unboundedness certificate, non-finite values).
      if (st == qp::QpStatus::infeasible || st == qp::QpStatus::unbounded ||
          !qp::detail::all_finite(lam_bounds(), lam_rows())) {
        session_.reset_multipliers();
      }
      return {NmpcStatus::qp_failed, false};
    }
    info_.step_norm = solver().x().cwiseAbs().maxCoeff();
    return {NmpcStatus::step_taken, capped};
  }

  bool parameters_finite() const {
    for (const auto& p : p_)
      if (!p.allFinite())
        return false;
    return true;
  }

  void record_kkt() {
    const KktResiduals<Scalar> r = kkt_residuals(qp_, lam_bounds(), lam_rows());
    info_.stationarity = r.stationarity;
    info_.primal_residual = r.primal;
    info_.complementarity = r.complementarity;
  }

  /// Stationarity and complementarity are relative to 1 + max(|grad f|_inf, |lambda|_inf) (as the
  /// QP's tolerances are); the primal residual is absolute.
  bool converged() const {
    const Scalar scale = kkt_scale(qp_, lam_bounds(), lam_rows());
    return info_.stationarity <= settings_.tol_stationarity * scale &&
           info_.primal_residual <= settings_.tol_primal &&
           info_.complementarity <= settings_.tol_complementarity * scale;
  }

  /// Takes x += alpha dx, w += alpha dw, lambda = lambda_QP.
  void take_step(Scalar alpha) {
    for (int k = 0; k <= N; ++k)
      x_[std::size_t(k)] += alpha * solver().state(k);
    for (int k = 0; k < N; ++k)
      w_[std::size_t(k)] += alpha * solver().input(k);
    // full multiplier step: the QP's multipliers, already in place, are the estimate
    info_.step_size = alpha;
  }

  /// g'd for the solver's step d (the QP gradient is the cost's gradient).
  Scalar directional_cost_derivative() const {
    Scalar s = 0;
    for (int k = 0; k < N; ++k) {
      const auto& st = qp_.stage[std::size_t(k)];
      s += st.q.dot(solver().state(k)) + st.r.dot(solver().input(k));
    }
    return s + qp_.terminal.q.dot(solver().state(N));
  }

  /// Cost and L1 violation (dynamics, constraints, bounds, x_0 = x0) at the plan + alpha d.
  ocp::StageMerit<Scalar> merit_at(Scalar alpha, const Vx& x0) const {
    ocp::StageMerit<Scalar> m;
    auto add_bounds = [&m](const auto& v, const auto& lb, const auto& ub) {
      m.violation += (lb - v).cwiseMax(Scalar(0)).sum() + (v - ub).cwiseMax(Scalar(0)).sum();
    };
    Vx xk = x_[0] + alpha * solver().state(0);
    m.violation += (xk - x0).cwiseAbs().sum();
    for (int k = 0; k < N; ++k) {
      const Vw wk = w_[std::size_t(k)] + alpha * solver().input(k);
      const Vx xn = x_[std::size_t(k + 1)] + alpha * solver().state(k + 1);
      const ocp::StageMerit<Scalar> s = ocp::path_merit(problem_, xk, wk, p_[std::size_t(k)], xn);
      m.cost += s.cost;
      m.violation += s.violation;
      if (k > 0)
        add_bounds(xk, lbx_[std::size_t(k)], ubx_[std::size_t(k)]);
      add_bounds(wk.template head<nu>(), lbu_[std::size_t(k)], ubu_[std::size_t(k)]);
      m.violation += (-wk.template tail<ns>()).cwiseMax(Scalar(0)).sum();
      xk = xn;
    }
    const ocp::StageMerit<Scalar> t = ocp::terminal_merit(problem_, xk, p_[N]);
    m.cost += t.cost;
    m.violation += t.violation;
    add_bounds(xk, lbx_[N], ubx_[N]);
    return m;
  }

  P problem_;                               ///< the OCP (expressions, default bounds)
  Settings settings_;                       ///< settings
  std::array<Vx, N + 1> x_;                 ///< planned states x_0..x_N
  std::array<Vw, N> w_;                     ///< planned inputs and slacks [u_k; s_k]
  std::array<Vp, N + 1> p_;                 ///< stage parameters
  std::array<Vx, N + 1> lbx_, ubx_;         ///< state bounds per stage
  std::array<Vu, N> lbu_, ubu_;             ///< input bounds per stage
  Qp qp_;                                   ///< the QP of the current linearisation
  Session session_;                         ///< its solver (points to qp_) and preparation
  Safety safety_;                           ///< recovery and fallback
  Info info_{};                             ///< figures of the last call
  detail::MeritHistory<Scalar, nx> merit_;  ///< the line search's penalty and merits
  bool prepared_ = false;                   ///< prepare() succeeded, feedback() not yet run
  Vx embedded_ = Vx::Zero();                ///< the x0 of the last embed()
  bool matrices_checked_ = false;           ///< linearize_as() found every QP matrix finite

  /// Whether feedback_gain() has a gain: none (no feedback() step since the last
  /// linearisation), available (the solver holds the QP of the last feedback()), failed.
  enum class GainState : unsigned char { none, available, failed };
  GainState gain_ = GainState::none;  ///< see GainState
};

}  // namespace arbor::nmpc
