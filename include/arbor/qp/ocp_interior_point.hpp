// arbor::qp: a primal-dual interior-point method for the optimal-control QP (OcpQp in
// problem.hpp), the cold start of the active-set OcpQpSolver: every iteration moves all
// constraints at once (the active set changes one per iteration), so a few interior-point
// iterations and a crossover (the working set guessed from the interior point's slacks and
// multipliers, handed to the active-set solver as a warm start) replace the ~100 one-change
// iterations of an active-set cold start.
//
//   static OcpInteriorPoint<Qp> ipm;          // workspace (static storage: no heap)
//   IpmStatus s = ipm.solve(qp);               // interior-point iterations from x = 0
//   ipm.warm_start(solver);                    // x, lam_x, lam_a of an OcpQpSolver set up on qp
//   QpStatus st = solver.solve();              // the active set finishes (exact KKT point)
//   or, in one call: cold_solve(solver, ipm, qp).
//
// Method (Mehrotra's predictor-corrector on the slack form): every finite side of a variable
// bound or a path row is an inequality with a slack and a multiplier (z - lb = s_l >= 0 with
// lam >= 0, ub - z = s_u >= 0 with mu >= 0); the dynamics rows are equalities with costates nu;
// x_0 (lbx_0 == ubx_0) is fixed. Eliminating slacks and multipliers leaves, per iteration, an
// equality-constrained OCP with the stage Hessians [Q S'; S R] + diag(lam/s_l + mu/s_u) on the
// bounds + [C D]' diag(.) [C D] on the rows (+ reg I): the matrix the active-set solver factorizes
// for a working set, with a weight on every variable. So the active set's own Riccati backend
// (ocp_riccati_backend.hpp: square-root recursion, packed kernels) factorizes it
// (OcpRiccatiBackend::diag_weights: the bounds' weights; every path row in its working set with
// its weight; x_0 an exact bound), and its solve_exact() gives the step and the costates; the
// predictor and the corrector share the factorization. Infeasible start (x = 0, slacks
// max(distance, init), multipliers init): the dynamics and slack residuals vanish with the first
// full step.
// Cost per iteration: one full factorization of the backend (~10 k multiply-adds per stage at the
// Kinova size NX = 16, NU = 8; 17 us for 17 stages with AVX-512, bench/qp/RESULTS.md), two
// solve_exact() and the backend's products for the residuals (ocp_products.hpp: H v, A v, A' v).
// Memory: the backend's factor (N NW (NW+1)/2 + NX (NX+1)/2 scalars, NW = NX + NU), 19 NI + 7 NV +
// 4 NA + 3 N NX scalars for the iterate, the directions and the weights (NI = NV + N NG + NGN:
// the inequalities' index space), NV + NA bytes (~142 KB at the Kinova size in double: a
// separate workspace, so only a program that uses the cold start pays it).
// Not handled (status unsupported: use the active set's own cold start): equalities other than
// x_0 (a bound with lb == ub on another variable, a path row with lg == ug).
// Sign conventions as OcpQpSolver: a flat multiplier > 0 means "upper bound active", and
// H x + g + lam_x + A' lam_a = 0 with dyn_k = x_{k+1} - A_k x_k - B_k u_k.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "arbor/qp/backend.hpp"
#include "arbor/qp/ocp_riccati_backend.hpp"
#include "arbor/qp/problem.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp {

/// Outcome of OcpInteriorPoint::solve().
enum class IpmStatus : unsigned char {
  converged,        ///< residuals and complementarity below the settings' tolerances
  iteration_limit,  ///< max_iter reached (not converged: e.g. an infeasible QP)
  /// the Newton matrix lost definiteness (round-off) after progress: residuals and mean
  /// complementarity below sqrt(tol), not below tol; still a crossover point
  precision_limit,
  factorization_failed,  ///< the Newton matrix was not positive definite (no usable point)
  non_finite,            ///< NaN or infinite data or iterate
  unsupported,           ///< an equality other than x_0 (see the top of the file)
};

/// Name of an IpmStatus value.
constexpr const char* to_string(IpmStatus s) {
  switch (s) {
    case IpmStatus::converged:
      return "converged";
    case IpmStatus::iteration_limit:
      return "iteration_limit";
    case IpmStatus::precision_limit:
      return "precision_limit";
    case IpmStatus::factorization_failed:
      return "factorization_failed";
    case IpmStatus::non_finite:
      return "non_finite";
    case IpmStatus::unsupported:
      return "unsupported";
  }
  return "unknown";
}

/// Report of the last OcpInteriorPoint::solve().
template <typename Scalar>
struct IpmInfo {
  int iterations = 0;          ///< interior-point iterations (each one factorization)
  Scalar complementarity = 0;  ///< mean s' lam at the end
  Scalar primal_residual = 0;  ///< max |dynamics and slack residual|
  Scalar dual_residual = 0;    ///< max |stationarity residual| (free variables)
  int guessed_active = 0;      ///< inequalities the crossover names active (warm_start())
};

template <typename Qp>
class OcpInteriorPoint;

/// Interior-point workspace and method for OcpQp<Scalar, N, NX, NU, NG, NGN> (top of the file).
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
class OcpInteriorPoint<OcpQp<Scalar, N, NX, NU, NG, NGN>> {
 public:
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  using Real = Scalar;  ///< the scalar type
  static constexpr int NW = NX + NU;
  static constexpr int NV = Problem::nv;
  static constexpr int NA = Problem::na;
  /// the inequalities' index space: the variables (their bounds), then the path rows
  static constexpr int NI = NV + N * NG + NGN;
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecI = Eigen::Matrix<Scalar, NI, 1>;
  using VecX = Eigen::Matrix<Scalar, NX, 1>;
  using Costates = Eigen::Matrix<Scalar, N * NX, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;

  /// Runs the interior-point iterations on p from x = 0 (x_0 at its fixed value).
  IpmStatus solve(const Problem& p, const IpmSettings<Scalar>& s = IpmSettings<Scalar>{}) {
    p_ = &p;
    info_ = IpmInfo<Scalar>{};
    switch (initialize(s)) {
      case Start::ready:
        break;
      case Start::unsupported:
        return status_ = IpmStatus::unsupported;
      case Start::non_finite:
        return status_ = IpmStatus::non_finite;
    }
    for (;;) {
      const Scalar tau = residuals();
      info_.complementarity = tau;
      if (!std::isfinite(tau) || !std::isfinite(info_.primal_residual) ||
          !std::isfinite(info_.dual_residual))
        return status_ = IpmStatus::non_finite;
      if (info_.primal_residual <= s.tol * scale_ && info_.dual_residual <= s.tol * scale_ &&
          tau <= s.tol)
        return status_ = IpmStatus::converged;
      if (info_.iterations >= s.max_iter)
        return status_ = IpmStatus::iteration_limit;
      inverses();
      if (!factorize(s.reg)) {
        // near the solution the weights lam / s span the scalar's range (float: tol 1e-6 fails):
        // a point that made progress is still a crossover point
        const bool near = info_.iterations > 0 &&
                          info_.primal_residual <= std::sqrt(s.tol) * scale_ &&
                          tau <= std::sqrt(s.tol);
        return status_ = near ? IpmStatus::precision_limit : IpmStatus::factorization_failed;
      }
      ++info_.iterations;
      // predictor (affine scaling): complementarity targets 0
      direction(Scalar(0), false);
      const Scalar ap = primal_step(Scalar(1)), ad = dual_step(Scalar(1));
      // (an absent side: slack 1, multiplier 0 and zero steps, so its products vanish)
      const Scalar tau_aff =
          ((sl_ + ap * dsl_).dot(lam_ + ad * dlam_) + (su_ + ap * dsu_).dot(mu_ + ad * dmu_)) /
          Scalar(m_);
      const Scalar ratio = tau_aff / tau;
      const Scalar sigma = ratio * ratio * ratio;
      // corrector: centring sigma tau and the predictor's second-order term
      direction(sigma * tau, true);
      const Scalar bp = primal_step(s.boundary), bd = dual_step(s.boundary);
      w_ += bp * dw_;
      nu_ += bd * dnu_;
      sl_ += bp * dsl_;  // absent sides: zero steps
      su_ += bp * dsu_;
      lam_ += bd * dlam_;
      mu_ += bd * dmu_;
    }
  }

  /// Writes the crossover point into an active-set solver set up on the same problem: x = the
  /// interior point, the multipliers of the inequalities guessed active (lam > s on a side: the
  /// multiplier dominates the slack) with their side's sign, 0 for the others, the costates on
  /// the dynamics rows and x_0's multipliers from stationarity. Its next solve() starts from the
  /// working set these name (a warm start).
  template <class Solver>
  void warm_start(Solver& solver) {
    solver.edit_warm_start([&](auto& x, auto& lx, auto& la) {
      x = w_;
      lx.setZero();
      la.setZero();
      info_.guessed_active = write_multipliers(lx, la);
    });
  }

 private:
  /// The crossover multipliers into lx, la (zero on entry); returns how many are guessed active.
  template <class LX, class LA>
  int write_multipliers(LX& lx, LA& la) const {
    int active = 0;
    for (int i = 0; i < NI; ++i) {
      Scalar y = 0;
      if (has_lo_[i] != Scalar(0) && lam_[i] > sl_[i])
        y = -lam_[i];
      else if (has_up_[i] != Scalar(0) && mu_[i] > su_[i])
        y = mu_[i];
      active += y != Scalar(0);
      if (i < NV) {
        lx[i] = y;
      } else {
        const int r = i - NV, k = NG > 0 && r < N * NG ? r / NG : N;
        la[Problem::constraint_offset(k) + (r - (k < N ? k * NG : N * NG))] = y;
      }
    }
    for (int k = 0; k < N; ++k)
      la.template segment<NX>(Problem::dynamics_offset(k)) = nu_.template segment<NX>(k * NX);
    // x_0: its equality's multiplier closes stationarity (rw_ without the bound term)
    lx.template head<NX>() = -rw_.template head<NX>();
    return active;
  }

 public:
  /// The primal iterate (flat layout of problem.hpp).
  const VecV& x() const { return w_; }
  /// Report of the last solve().
  const IpmInfo<Scalar>& info() const { return info_; }
  /// Status of the last solve().
  IpmStatus status() const { return status_; }

 private:
  /// Index of stage k's first path row in the inequalities' space (k = N: the terminal rows).
  static constexpr int row(int k) { return NV + k * NG; }

  /// What initialize() found: a starting point, or why there is none.
  enum class Start : unsigned char {
    ready,        ///< the iterate holds a strictly interior starting point
    unsupported,  ///< an equality other than x_0's, a NaN bound, or x_0 not fixed and finite
    non_finite,   ///< NaN or infinite data
  };

  /// Reads the bounds and the data of the problem and sets the starting point.
  Start initialize(const IpmSettings<Scalar>& s) {
    const Problem& p = *p_;
    constexpr Scalar inf = std::numeric_limits<Scalar>::infinity();
    scale_ = Scalar(1);
    m_ = 0;
    w_.setZero();
    nu_.setZero();
    auto bound = [&](int i, Scalar lo, Scalar hi) -> bool {
      lb_[i] = lo;
      ub_[i] = hi;
      if (std::isnan(lo) || std::isnan(hi))
        return false;
      if (lo == hi)
        return false;  // an equality: only x_0's are handled (by fixing it)
      if (lo > -inf) {
        has_lo_[i] = Scalar(1);
        ++m_;
      }
      if (hi < inf) {
        has_up_[i] = Scalar(1);
        ++m_;
      }
      return true;
    };
    // an absent side (no bound, or x_0's fixed entries) is carried with mask 0, bound 0, slack 1
    // and multiplier 0: every elementwise update of the iterations then leaves it so, no branch
    has_lo_.setZero();
    has_up_.setZero();
    for (int k = 0; k < N; ++k) {
      const auto& st = p.stage[k];
      const int ox = Problem::state_offset(k), ou = Problem::input_offset(k);
      for (int j = 0; j < NX; ++j) {
        if (k == 0) {  // x_0 is fixed
          if (!(st.lbx[j] == st.ubx[j]) || !std::isfinite(st.lbx[j]))
            return Start::unsupported;
          w_[j] = st.lbx[j];
          lb_[j] = ub_[j] = st.lbx[j];
          continue;
        }
        if (!bound(ox + j, st.lbx[j], st.ubx[j]))
          return Start::unsupported;
      }
      for (int j = 0; j < NU; ++j)
        if (!bound(ou + j, st.lbu[j], st.ubu[j]))
          return Start::unsupported;
      const int og = row(k);
      for (int j = 0; j < NG; ++j)
        if (!bound(og + j, st.lg[j], st.ug[j]))
          return Start::unsupported;
      for (int j = 0; j < NX; ++j)
        scale_ = std::max(scale_, std::abs(st.b[j]));
      g_.template segment<NX>(ox) = st.q;
      if constexpr (NU > 0)
        g_.template segment<NU>(ou) = st.r;
    }
    const auto& t = p.terminal;
    for (int j = 0; j < NX; ++j)
      if (!bound(Problem::state_offset(N) + j, t.lbx[j], t.ubx[j]))
        return Start::unsupported;
    for (int j = 0; j < NGN; ++j)
      if (!bound(row(N) + j, t.lg[j], t.ug[j]))
        return Start::unsupported;
    g_.template segment<NX>(Problem::state_offset(N)) = t.q;
    scale_ = std::max(scale_, g_.cwiseAbs().maxCoeff());
    if (!std::isfinite(scale_))
      return Start::non_finite;
    // the Newton matrix's working set: x_0 fixed, the dynamics rows, every path row (weighted)
    be_.p = &p;
    for (auto& c : ws_)
      c = detail::ConstraintState::inactive;
    for (int j = 0; j < NX; ++j)
      ws_[j] = detail::ConstraintState::equality;
    for (int k = 0; k <= N; ++k) {
      if (k < N)
        for (int j = 0; j < NX; ++j)
          ws_[NV + Problem::dynamics_offset(k) + j] = detail::ConstraintState::equality;
      const int nr = k < N ? NG : NGN;
      for (int j = 0; j < nr; ++j)
        ws_[NV + Problem::constraint_offset(k) + j] = detail::ConstraintState::lower;
    }
    wa_.setZero();
    bw_.setZero();
    fixed_.setZero();
    // slacks: the distance to each bound at the start, at least init; multipliers init
    row_values(w_, cz_);
    for (int i = 0; i < NI; ++i) {
      sl_[i] = su_[i] = Scalar(1);
      lam_[i] = mu_[i] = Scalar(0);
      if (has_lo_[i] != Scalar(0)) {
        sl_[i] = std::max(cz_[i] - lb_[i], s.init);
        lam_[i] = s.init;
      } else {
        lb_[i] = Scalar(0);
      }
      if (has_up_[i] != Scalar(0)) {
        su_[i] = std::max(ub_[i] - cz_[i], s.init);
        mu_[i] = s.init;
      } else {
        ub_[i] = Scalar(0);
      }
    }
    dsl_.setZero();
    dsu_.setZero();
    dlam_.setZero();
    dmu_.setZero();
    if (m_ == 0)
      m_ = 1;
    return Start::ready;
  }

  /// z = [v; rows]: the variables, and C x + D u on the path rows (the backend's A v; av_ keeps
  /// all of A v, the dynamics rows x_{k+1} - A x_k - B u_k too, unless path_only: then they are
  /// not computed and av_'s dynamics rows are stale).
  void row_values(const VecV& v, VecI& z, bool path_only = false) {
    if (path_only)
      be_.path_mul(v, av_);
    else
      be_.cons_mul(v, av_);
    z.template head<NV>() = v;
    for (int k = 0; k <= N; ++k) {
      const int nr = k < N ? NG : NGN;
      for (int j = 0; j < nr; ++j)
        z[row(k) + j] = av_[Problem::constraint_offset(k) + j];
    }
  }

  /// rw = H w + g + D' nu - sum (lam - mu) a_i (x_0's entries without their equality's
  /// multiplier), rdyn, the slack residuals; returns the mean complementarity and records the
  /// largest residuals in info_.
  Scalar residuals() {
    const Problem& p = *p_;
    row_values(w_, cz_);
    // the flat multipliers of the solvers' convention (H x + g + lam_x + A' lam_a = 0): the
    // costates on the dynamics rows, mu - lam on the path rows (and on the bounds, below)
    for (int k = 0; k <= N; ++k) {
      if (k < N) {
        la_.template segment<NX>(Problem::dynamics_offset(k)) = nu_.template segment<NX>(k * NX);
        rdyn_.template segment<NX>(k * NX) =
            av_.template segment<NX>(Problem::dynamics_offset(k)) - p.stage[k].b;
      }
      const int nr = k < N ? NG : NGN;
      for (int j = 0; j < nr; ++j)
        la_[Problem::constraint_offset(k) + j] = mu_[row(k) + j] - lam_[row(k) + j];
    }
    be_.hess_mul(w_, rw_);
    be_.cons_tmul(la_, fw_);  // (fw_: scratch until direction())
    rw_ += g_ + fw_ + mu_.template head<NV>() - lam_.template head<NV>();
    rsl_ = has_lo_.cwiseProduct(cz_ - lb_ - sl_);  // 0 on absent sides
    rsu_ = has_up_.cwiseProduct(ub_ - cz_ - su_);
    const Scalar comp = sl_.dot(lam_) + su_.dot(mu_);
    info_.primal_residual = std::max(
        {rdyn_.cwiseAbs().maxCoeff(), rsl_.cwiseAbs().maxCoeff(), rsu_.cwiseAbs().maxCoeff()});
    info_.dual_residual = rw_.template tail<NV - NX>().cwiseAbs().maxCoeff();
    return comp / Scalar(m_);
  }

  /// The inverses of this iterate's slacks (0 on absent sides: the weights, the directions and
  /// the step lengths) and multipliers (1 there: the step lengths; (1 - mask) added first, as
  /// lam + 1 - 1 would round a small multiplier away). Once per iteration.
  void inverses() {
    const auto ones = VecI::Ones().array();
    isl_ = has_lo_.cwiseQuotient(sl_);
    isu_ = has_up_.cwiseQuotient(su_);
    ilam_ = (lam_.array() + (ones - has_lo_.array())).inverse().matrix();
    imu_ = (mu_.array() + (ones - has_up_.array())).inverse().matrix();
  }

  /// Factorizes the Newton matrix for the weights lam/s_l + mu/s_u (top of the file) with the
  /// active-set solver's Riccati backend: the bounds' weights on the stage diagonals
  /// (diag_weights), the rows' as the weights of rows in the working set; x_0 fixed (an exact
  /// bound), the dynamics exact. False on a pivot failure.
  bool factorize(Scalar reg) {
    // the weights of every inequality (0 on absent sides: zero multiplier and inverse), in the
    // scratch cz_: the bounds' into bw_, the rows' into wa_
    cz_ = lam_.cwiseProduct(isl_) + mu_.cwiseProduct(isu_);
    bw_ = cz_.template head<NV>();
    for (int k = 0; k <= N; ++k) {
      const int nr = k < N ? NG : NGN;
      for (int j = 0; j < nr; ++j)
        wa_[Problem::constraint_offset(k) + j] = cz_[row(k) + j];
    }
    be_.diag_weights = bw_.data();
    be_.mark_all();
    return be_.factorize(ws_.data(), reg, Scalar(0), wa_) >= 0;
  }

  /// Solves min 1/2 dw' G dw + f' dw s.t. dx_{k+1} = A dx_k + B du_k + e_k, dx_0 = 0 on the
  /// factorization (f: fw_, e = -rdyn_): dw_ and the costate steps dnu_.
  void solve_lq() {
    dw_ = -fw_;
    for (int k = 0; k < N; ++k)
      ea_.template segment<NX>(Problem::dynamics_offset(k)) = -rdyn_.template segment<NX>(k * NX);
    fixed_.template head<NX>().setZero();  // x_0's step
    be_.solve_exact(dw_, ea_, fixed_, wa_);
    for (int k = 0; k < N; ++k)
      dnu_.template segment<NX>(k * NX) = ea_.template segment<NX>(Problem::dynamics_offset(k));
  }

  /// The Newton direction for the complementarity targets lam dsl + sl dlam = target - sl lam
  /// (- dsl dlam of the current direction: the corrector), likewise for the upper sides: dw_,
  /// dnu_, dsl_, dsu_, dlam_, dmu_ (top of the file).
  void direction(Scalar target, bool corrector) {
    const Problem& p = *p_;
    // the complementarity residuals rc (0 on absent sides), kept in dlam_ and dmu_ until the
    // direction's own values replace them (elementwise, so in place)
    if (corrector) {
      dlam_ = target * has_lo_ - sl_.cwiseProduct(lam_) - dsl_.cwiseProduct(dlam_);
      dmu_ = target * has_up_ - su_.cwiseProduct(mu_) - dsu_.cwiseProduct(dmu_);
    } else {
      dlam_ = target * has_lo_ - sl_.cwiseProduct(lam_);
      dmu_ = target * has_up_ - su_.cwiseProduct(mu_);
    }
    cz_ = (dlam_ - lam_.cwiseProduct(rsl_)).cwiseProduct(isl_) -
          (dmu_ - mu_.cwiseProduct(rsu_)).cwiseProduct(isu_);
    fw_ = rw_ - cz_.template head<NV>();
    for (int k = 0; k < N; ++k) {
      if constexpr (NG > 0) {
        const auto& st = p.stage[k];
        const auto c = cz_.template segment<NG>(row(k));
        fw_.template segment<NX>(Problem::state_offset(k)).noalias() -= st.C.transpose() * c;
        if constexpr (NU > 0)
          fw_.template segment<NU>(Problem::input_offset(k)).noalias() -= st.D.transpose() * c;
      }
    }
    if constexpr (NGN > 0) {
      const auto c = cz_.template segment<NGN>(row(N));
      fw_.template segment<NX>(Problem::state_offset(N)).noalias() -= p.terminal.C.transpose() * c;
    }
    solve_lq();
    row_values(dw_, cz_, true);  // cz_ <- the direction's path-row values
    dsl_ = has_lo_.cwiseProduct(cz_ + rsl_);
    dsu_ = has_up_.cwiseProduct(rsu_ - cz_);
    dlam_ = (dlam_ - lam_.cwiseProduct(dsl_)).cwiseProduct(isl_);
    dmu_ = (dmu_ - mu_.cwiseProduct(dsu_)).cwiseProduct(isu_);
  }

  /// Largest step in [0, 1] that keeps a + t da and b + t db at least (1 - frac) of their
  /// values (frac = 1: to the boundary), from the steps and the inverses ia = 1 / a, ib = 1 / b
  /// (a, b > 0 on the sides that exist; an absent side's step is 0): min(1, frac / q) with q
  /// the largest max(-da, 0) / a. Vector instructions, no branch, no division in the loop.
  static Scalar step_length(const VecI& da, const VecI& ia, const VecI& db, const VecI& ib,
                            Scalar frac) {
    const Scalar q = std::max(((-da.array()).max(Scalar(0)) * ia.array()).maxCoeff(),
                              ((-db.array()).max(Scalar(0)) * ib.array()).maxCoeff());
    return q <= frac ? Scalar(1) : frac / q;
  }
  /// step_length() of the slacks and of the multipliers.
  Scalar primal_step(Scalar frac) const { return step_length(dsl_, isl_, dsu_, isu_, frac); }
  Scalar dual_step(Scalar frac) const { return step_length(dlam_, ilam_, dmu_, imu_, frac); }

  const Problem* p_ = nullptr;
  IpmInfo<Scalar> info_{};
  IpmStatus status_ = IpmStatus::unsupported;
  Scalar scale_ = 1;
  int m_ = 1;  ///< number of inequalities (finite sides)
  /// bounds (0 on absent sides), slacks (1 on absent sides), multipliers (0 there),
  /// their steps, the slack residuals, the sides' masks (1: the side exists), per iteration
  /// 1 / slack (0 on absent sides) and 1 / multiplier (1 there)
  VecI lb_, ub_, sl_, su_, lam_, mu_, dsl_, dsu_, dlam_, dmu_, rsl_, rsu_;
  VecI has_lo_, has_up_, isl_, isu_, ilam_, imu_;
  /// scratch: the iterate's row values (residuals()), the weights (factorize()), the right-hand
  /// side's coefficients and the direction's row values (direction())
  VecI cz_;
  VecV w_, dw_, rw_, fw_, g_;  ///< iterate, step, stationarity residual, scratch, gradient
  Costates nu_, dnu_, rdyn_;
  /// the Newton matrix's factorization: the active-set solver's Riccati backend
  detail::OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN> be_;
  std::array<detail::ConstraintState, NV + NA> ws_{};  ///< x_0 fixed, dynamics and rows held
  VecV bw_, fixed_;                                    ///< bound weights; fixed steps (x_0: 0)
  VecA wa_, ea_;  ///< row weights; the dynamics' right-hand side, then the costate steps
  VecA av_, la_;  ///< A v of the last row_values(); the flat row multipliers
};

/// True when the interior point's status gives a crossover point (converged, precision_limit).
constexpr bool crossover_point(IpmStatus s) {
  return s == IpmStatus::converged || s == IpmStatus::precision_limit;
}

/// Cold solve of an OcpQpSolver by the interior point and a crossover: ipm.solve(p), then
/// ipm.warm_start(solver) and solver.solve(). The solver must be set up on p (setup() accepted).
/// When the interior point gives no crossover point (unsupported equalities, a factorization
/// failure without progress, non-finite values, the iteration cap: e.g. an infeasible QP, whose
/// certificate the active set finds) the active set starts cold as before (solver.cold_start()).
template <class Solver, class Ipm, class Problem>
QpStatus cold_solve(Solver& solver, Ipm& ipm, const Problem& p,
                    const IpmSettings<typename Ipm::Real>& s = {}) {
  if (crossover_point(ipm.solve(p, s)))
    ipm.warm_start(solver);
  else
    solver.cold_start();
  return solver.solve();
}

}  // namespace arbor::qp
