// arbor::nmpc: the controller's QP solver and what the real-time iteration's preparation left in
// it (QpSession): setup or update of the QP, its prefactorization or presolve before the
// measurement, the solve within an iteration budget, the interior-point cold start. Every call
// the controller makes into qp/ goes through here, one small function per QP operation. Costs
// are the solver's (qp/ocp_qp_solver.hpp); the session adds a few flag tests per call.
#pragma once

#include "arbor/qp/ocp_interior_point.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"

namespace arbor::nmpc::detail {

/// The active-set solver of QP type Qp with the state of its preparation. The solver keeps a
/// pointer to the QP object passed to update(): pass the same one to every call.
template <class Qp, class Scalar>
class QpSession {
 public:
  using Solver = qp::OcpQpSolver<Qp>;
  using ColdStart = qp::OcpInteriorPoint<Qp>;
  using Settings = qp::QpSettings<Scalar>;
  using Vx = Eigen::Matrix<Scalar, Qp::nx, 1>;

  /// What prepare() left in the solver for the next solve, for the current matrices: nothing
  /// (the solve updates and factorizes everything), the factorization for the multipliers'
  /// working set (the solve re-reads only the vectors), or with it the first step for the
  /// predicted x_0 (the solve moves that step to the measured x_0, re-reading nothing).
  enum class Prepared : unsigned char { none, factorized, presolved };

  /// The bound on one solve's iterations: the settings' cap, or a caller's smaller bound, at
  /// which the QP's last iterate is a step (qp::QpSettings::last_iterate_at_cap).
  struct Budget {
    int max_iter;
    bool last_iterate_at_cap;
  };
  /// The budget of a solve bounded by `bound` iterations (0: the settings' cap s.max_iter only).
  static Budget budget(const Settings& s, int bound) {
    const bool bounded = bound > 0 && bound < s.max_iter;
    return {bounded ? bound : s.max_iter, bounded};
  }

  Solver& solver() { return solver_; }
  const Solver& solver() const { return solver_; }

  /// The interior-point cold start's workspace (nullptr: off). Its code is instantiated here,
  /// through cold_start_: a program that never sets one compiles and links none of it.
  void set_cold_start_workspace(ColdStart* ws) {
    ipm_ = ws;
    cold_start_ = ws != nullptr ? &QpSession::run_cold_start : nullptr;
  }

  /// Whether the next solve starts with the interior point (a workspace is set and every
  /// multiplier is zero: nothing to warm-start from).
  bool cold_start_due() const {
    return cold_start_ != nullptr && (solver_.lam_x().array() == Scalar(0)).all() &&
           (solver_.lam_a().array() == Scalar(0)).all();
  }

  /// New matrices in the QP: nothing prepared holds any more.
  void forget() { prepared_ = Prepared::none; }

  /// The solver reads qp (setup when s differs from the settings it runs with, or none ran;
  /// else an update, skipping the finiteness checks of matrices the caller checked); the
  /// QP's status.
  qp::QpStatus update(const Qp& qp, const Settings& s, bool matrices_checked) {
    if (!setup_ || applied_ != s) {
      const qp::QpStatus st = solver_.setup(qp, s);
      applied_ = s;
      setup_ = st == qp::QpStatus::accepted;
      return st;
    }
    return solver_.update(qp::Convexity::assumed,
                          matrices_checked ? qp::Finiteness::assumed : qp::Finiteness::checked);
  }

  /// The preparation after an accepted update(): the first factorization for the working set
  /// the multipliers name and, with presolve, the first step for the current x_0 (the solve
  /// moves it to the measured one, qp::OcpQpSolver::prepare_start).
  void prepare(bool presolve) {
    if (presolve) {
      start_ = solver_.prepare_start();
      prepared_ = start_.stages_factorized() >= 0 ? Prepared::presolved : Prepared::none;
    } else {
      prepared_ = solver_.prefactorize() >= 0 ? Prepared::factorized : Prepared::none;
    }
  }

  /// Moves stage k's state bounds [lb, ub] (relaxed after prepare()) into a presolved QP's copy;
  /// the presolved step is dropped (the factorization kept) when its working set does not hold.
  void move_state_bounds(int k, const Vx& lb, const Vx& ub) {
    if (prepared_ == Prepared::presolved &&
        solver_.set_state_bounds(start_, k, lb, ub) != qp::QpStatus::accepted)
      prepared_ = Prepared::factorized;
  }
  bool presolved() const { return prepared_ == Prepared::presolved; }

  /// The solve of qp (x_0 fixed to x0, the value of its bounds) within budget b, from what
  /// prepare() left when the solver still runs with settings s, else from a full update;
  /// warm-started at x = 0 with the solver's multipliers, or from the interior point when a
  /// cold start is due (its iterations added to ipm_iterations). The QP's status.
  qp::QpStatus solve(const Qp& qp, const Vx& x0, const Settings& s, bool matrices_checked,
                     const qp::IpmSettings<Scalar>& cold, Budget b, int& ipm_iterations) {
    const Prepared prepared = setup_ && applied_ == s ? prepared_ : Prepared::none;
    prepared_ = Prepared::none;             // consumed by this solve
    if (prepared == Prepared::presolved) {  // only x_0's bounds changed: the step, moved to them
      set_budget(b);
      return solver_.solve_from(start_, x0);
    }
    const qp::QpStatus st = prepared == Prepared::factorized ? solver_.update_vectors()
                                                             : update(qp, s, matrices_checked);
    if (st != qp::QpStatus::accepted)
      return st;
    set_budget(b);
    if (cold_start_due() && cold_start_(*this, qp, cold, ipm_iterations))
      return solver_.solve();  // the active set from the interior point's crossover point
    // x = 0; the multipliers are the solver's own: its warm start
    solver_.edit_warm_start([](auto& x, auto&, auto&) { x.setZero(); });
    return solver_.solve();
  }

  /// The multiplier estimate (the solver's warm start) set to zero: a cold start.
  void reset_multipliers() {
    solver_.edit_warm_start([](auto&, auto& lam_x, auto& lam_a) {
      lam_x.setZero();
      lam_a.setZero();
    });
  }
  /// The multiplier estimate moved one stage earlier (Solver::shift_variables / shift_rows).
  void shift_multipliers() {
    solver_.edit_warm_start([](auto&, auto& lam_x, auto& lam_a) {
      Solver::shift_variables(lam_x);
      Solver::shift_rows(lam_a);
    });
  }

 private:
  void set_budget(Budget b) {
    solver_.settings().max_iter = b.max_iter;
    solver_.settings().last_iterate_at_cap = b.last_iterate_at_cap;
  }

  /// The interior point on qp from x = 0 and, when it ends at a crossover point, the active
  /// set's warm start from there; true when the active set should start from it.
  static bool run_cold_start(QpSession& s, const Qp& qp, const qp::IpmSettings<Scalar>& cold,
                             int& ipm_iterations) {
    const qp::IpmStatus is = s.ipm_->solve(qp, cold);
    ipm_iterations += s.ipm_->info().iterations;
    if (!qp::crossover_point(is))
      return false;
    s.ipm_->warm_start(s.solver_);
    return true;
  }

  Solver solver_;                           ///< the solver (points to the caller's QP)
  Prepared prepared_ = Prepared::none;      ///< what prepare() left for the current matrices
  typename Solver::PreparedStart start_{};  ///< prepare()'s first step (valid with presolved)
  bool setup_ = false;                      ///< solver_.setup() was accepted once
  Settings applied_{};                      ///< the QP settings the solver runs with
  ColdStart* ipm_ = nullptr;  ///< the interior-point workspace (caller's; nullptr: off)
  bool (*cold_start_)(QpSession&, const Qp&, const qp::IpmSettings<Scalar>&, int&) = nullptr;
};

}  // namespace arbor::nmpc::detail
