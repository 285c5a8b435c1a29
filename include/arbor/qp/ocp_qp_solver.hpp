// arbor::qp: static-memory active-set solver for the optimal-control QP (OcpQp in problem.hpp).
//
// Active-set logic: active_set.hpp (QRQP-style primal-dual, one change per iteration, ratio test
// with primal blocking constraints and dual break points, warm start from x and lam). Linear
// algebra: ocp_riccati_backend.hpp (the default: the dynamics rows solved exactly by a backward
// square-root Riccati recursion, costates from the solve, rank-one sweeps for working-set
// changes; its products with the stage blocks in ocp_products.hpp, its packed triangular kernels
// in packed_kernels.hpp and kernels.hpp).
// Cost: O(N (NX+NU)^3) per full factorization (one per solve), O(N (NX+NU)^2) per working-set
// change and per iteration otherwise.
// Memory (scalars, default backend): N (NW (NW+1)/2) + NX (NX+1)/2 for the factor, about
// 11 NV + 8 NA for the iterate and workspace, with NW = NX + NU, NV = N NW + NX,
// NA = N (NX+NG) + NGN; no dense KKT matrix (Kinova size, N = 16, NX = 16, NU = 8: ~101 KB in
// double). Copy/reference rule (problem.hpp): the vectors (q, r, b, bounds) are copied by
// setup()/update(), the matrices (Q, S, R, A, B, C, D) are read through a pointer by every
// solve(); the problem must outlive the solver's use of it.
//
// Real-time iteration (one problem object, refilled every sample):
//   using Qp = OcpQp<double, 16, 16, 8, 1>;
//   static Qp qp;                               // fill the stages
//   static OcpQpSolver<Qp> solver;
//   if (solver.setup(qp) != QpStatus::accepted) ...;       // checks everything, convexity too
//   QpStatus st = solver.solve();               // solver.state(k), input(k), multipliers, info()
//   loop: solver.shift();                       // warm start: the solution one stage earlier
//         refill qp (relinearise);
//         st = solver.update(Convexity::assumed);  // re-read, no per-stage convexity check
//         st = solver.solve();
// The real-time feedback (x_0 measured after the preparation):
//   auto prepared = solver.prepare_start();     // preparation: factorization, first step
//   st = solver.solve_from(prepared, x0);       // feedback: the step moved to x0
// Multipliers follow one sign convention: > 0 means the upper bound is active, < 0 the lower
// one, and H v + g + lam_x + A' lam_a = 0 in the flat layout of problem.hpp (the dynamics rows
// are dyn_k = x_{k+1} - A_k x_k - B_k u_k).
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/qp/data_checks.hpp"
#include "arbor/qp/ocp_riccati_backend.hpp"
#include "arbor/qp/problem.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/solver_base.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp {

namespace detail {
/// The exact-dynamics Riccati backend (ocp_riccati_backend.hpp) of OcpQpSolver<Qp, ...>.
template <typename Qp>
struct RiccatiOcpBackend;
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct RiccatiOcpBackend<OcpQp<Scalar, N, NX, NU, NG, NGN>> {
  using type = OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>;
};
/// The default linear algebra of OcpQpSolver<Qp>: the Riccati backend.
template <typename Qp>
struct DefaultOcpBackend : RiccatiOcpBackend<Qp> {};
}  // namespace detail

/// Structure-exploiting active-set solver for an OcpQp type `Qp` (see the top of this file).
/// `Backend` is the linear algebra: the Riccati backend, or a type derived from it (a benchmark's
/// instrumented copy, bench/nmpc/rti_qp_diag.cpp); it must model ActiveSetBackend (backend.hpp).
template <typename Qp, typename Backend = typename detail::DefaultOcpBackend<Qp>::type>
class OcpQpSolver;

template <typename Scalar, int N, int NX, int NU, int NG, int NGN, typename BackendT>
class OcpQpSolver<OcpQp<Scalar, N, NX, NU, NG, NGN>, BackendT>
    : public detail::ActiveSetSolver<Scalar, OcpQp<Scalar, N, NX, NU, NG, NGN>::nv,
                                     OcpQp<Scalar, N, NX, NU, NG, NGN>::na, BackendT> {
 public:
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  using Backend = BackendT;
  using typename detail::ActiveSetSolver<Scalar, Problem::nv, Problem::na, BackendT>::PreparedStart;

  /// Keeps a pointer to p and the settings, then update(Convexity::checked). The current
  /// iterate is kept (warm start); call cold_start() to reset it.
  [[nodiscard]] QpStatus setup(const Problem& p,
                               const QpSettings<Scalar>& s = QpSettings<Scalar>{}) {
    this->settings_ = s;
    this->be_.p = &p;
    return update(Convexity::checked);
  }

  /// Re-reads every stage of the problem given to setup(): checks it (finite unless the
  /// matrices' finiteness is assumed, bounds ordered and, unless convexity is assumed, every stage
  /// Hessian [Q S'; S R] and Q_N positive semidefinite) and copies its vectors. Returns accepted,
  /// else the problem's status (and solve() returns not_setup until an update is accepted). The
  /// iterate is kept.
  [[nodiscard]] QpStatus update(Convexity convexity = Convexity::checked,
                                Finiteness finiteness = Finiteness::checked) {
    const Problem* p = this->be_.p;
    if (p == nullptr)
      return this->conclude(QpStatus::not_setup);
    this->be_.mark_all();  // new matrices: the last factor (and its gains) no longer holds
    const bool convex = convexity == Convexity::checked;
    const bool finite = finiteness == Finiteness::checked;
    for (int k = 0; k < N; ++k) {
      const QpStatus st = read_stage(k, p->stage[k], convex, finite);
      if (st != QpStatus::accepted)
        return this->conclude(st);
    }
    return this->conclude(read_terminal(p->terminal, convex, finite));
  }

  /// Re-reads only the vectors of every stage (bounds, gradients, dynamics offsets; checked:
  /// finite, bounds ordered) and keeps the matrices as the last setup()/update() read them, and
  /// a prefactorization (prefactorize()): for what changes between the preparation and the
  /// feedback of real-time iteration (the embedded x_0). Returns accepted or the vectors' status.
  [[nodiscard]] QpStatus update_vectors() {
    const Problem* p = this->be_.p;
    if (p == nullptr)
      return this->conclude(QpStatus::not_setup);
    for (int k = 0; k < N; ++k) {
      const QpStatus st = read_vectors(k, p->stage[k]);
      if (st != QpStatus::accepted)
        return this->conclude(st);
    }
    return this->conclude(read_terminal_vectors(p->terminal), true);
  }

  /// Real-time iteration's preparation, beyond prefactorize(): also the first step of a solve
  /// from x = 0 (x is set to 0 here) with the current multipliers and the vectors as read, for
  /// x_0's bounds as they are (lbx_0 = ubx_0). solve_from() moves that step to the measured x_0
  /// (a forward Riccati sweep) instead of evaluating and solving. The returned start is valid
  /// until the next operation that writes the iterate, the vectors or the matrices: setup(),
  /// update(), update_vectors(), solve(), solve_from(), prefactorize(), prepare_start(), shift(),
  /// set_warm_start(), edit_warm_start(), set_state_bounds() (which may keep the one it is
  /// given); its stages_factorized() is -1 when nothing will be reused.
  [[nodiscard]] PreparedStart prepare_start() {
    if (!this->ready_)
      return PreparedStart{};
    return this->core_.prepare_start(this->be_, this->settings_, NX);
  }

  /// The solve from x = 0 with x_0's bounds set to x0 (lbx_0 = ubx_0 = x0; in the solver's copy
  /// of the vectors, the problem is not written) and the multipliers as warm start; with a valid
  /// prepared start, its first iteration reuses the preparation's work (the same iterates as
  /// solve() to round-off), otherwise it is solve(). For the feedback of real-time iteration,
  /// whose QP differs from the prepared one in x_0 only. Returns not_setup, non_finite (x0;
  /// nothing changed), or solve()'s status.
  [[nodiscard]] QpStatus solve_from(const PreparedStart& prepared,
                                    const Eigen::Matrix<Scalar, NX, 1>& x0) {
    if (!this->ready_)
      return QpStatus::not_setup;
    if (!detail::all_finite(x0))
      return QpStatus::non_finite;
    return this->core_.solve_from(this->be_, this->settings_, this->info_, prepared, x0.data(), NX);
  }

  /// Sets the state bounds of stage k (1 <= k <= N; N: the terminal's) in the solver's copy of
  /// the vectors (the problem is not written; the next update() or update_vectors() reads its
  /// own again): for the real-time feedback's recovery, which relaxes state bounds the measured
  /// x_0 cannot meet after prepare_start(). prepared stays valid when the working set it
  /// factorized is still the one the multipliers name for the new bounds (the first iteration
  /// then passes over every constraint again, and adds the response to a moved working bound's
  /// target with one full solve); every other prepared start is invalid afterwards. Returns
  /// accepted, or non_finite / invalid_bounds (NaN, lb > ub, lb = +inf, ub = -inf: nothing
  /// changed).
  [[nodiscard]] QpStatus set_state_bounds(PreparedStart& prepared, int k,
                                          const Eigen::Matrix<Scalar, NX, 1>& lb,
                                          const Eigen::Matrix<Scalar, NX, 1>& ub) {
    return move_state_bounds(&prepared, k, lb, ub);
  }

  /// Moves the primal and dual solution one stage earlier, for the warm start of the next
  /// sample: stage k receives what stage k+1 held (x_k, u_k, the multipliers of their bounds,
  /// of the dynamics row dyn_k and of gen_k). The last stage repeats: x_N, u_{N-1}, their bound
  /// multipliers, dyn_{N-1}, gen_{N-1} and gen_N keep their values. The working set follows,
  /// since solve() rebuilds it from the multipliers' signs. Cost: one copy of the iterate.
  void shift() {
    auto& c = this->core_;
    c.note_change();
    shift_variables(c.x);
    shift_variables(c.lam_x);
    shift_rows(c.lam_a);
  }

  /// shift() of a vector in the flat variable layout (x, or the bound multipliers): stage k
  /// takes stage k+1's [x; u], the last state and input repeat. For callers that keep their own
  /// copies (the NMPC's multipliers).
  template <class V>
  static void shift_variables(V& v) {
    constexpr int NW = NX + NU;
    for (int k = 0; k + 1 < N; ++k)
      v.template segment<NW>(k * NW) = v.template segment<NW>((k + 1) * NW);
    v.template segment<NX>((N - 1) * NW) = v.template tail<NX>();
  }

  /// shift() of a vector in the flat row layout (the row multipliers): stage k takes stage k+1's
  /// [dyn; gen] rows; the last path stage's rows and the terminal rows keep their values.
  template <class A>
  static void shift_rows(A& a) {
    constexpr int NR = NX + NG;
    for (int k = 0; k + 1 < N; ++k)
      a.template segment<NR>(k * NR) = a.template segment<NR>((k + 1) * NR);
  }

  // ---- per-stage views of the solution (read-only, valid until the next solve() or shift())
  /// State x_k, k = 0..N.
  auto state(int k) const {
    ARBOR_ASSERT(k >= 0 && k <= N, "state index out of range");
    return this->core_.x.template segment<NX>(Problem::state_offset(k));
  }
  /// Input u_k, k = 0..N-1.
  auto input(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "input index out of range");
    return this->core_.x.template segment<NU>(Problem::input_offset(k));
  }
  /// Multipliers of the state bounds lbx_k <= x_k <= ubx_k, k = 0..N.
  auto state_bound_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k <= N, "state index out of range");
    return this->core_.lam_x.template segment<NX>(Problem::state_offset(k));
  }
  /// Multipliers of the input bounds lbu_k <= u_k <= ubu_k, k = 0..N-1.
  auto input_bound_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "input index out of range");
    return this->core_.lam_x.template segment<NU>(Problem::input_offset(k));
  }
  /// Multipliers of the dynamics x_{k+1} = A_k x_k + B_k u_k + b_k, k = 0..N-1 (of the row
  /// x_{k+1} - A_k x_k - B_k u_k: the costate of x_{k+1} up to its sign).
  auto dynamics_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "dynamics index out of range");
    return this->core_.lam_a.template segment<NX>(Problem::dynamics_offset(k));
  }
  /// Multipliers of the path constraints lg_k <= C_k x_k + D_k u_k <= ug_k, k = 0..N-1.
  auto constraint_multiplier(int k) const {
    ARBOR_ASSERT(k >= 0 && k < N, "path-constraint index out of range");
    return this->core_.lam_a.template segment<NG>(Problem::constraint_offset(k));
  }
  /// Multipliers of the terminal constraints lg_N <= C_N x_N <= ug_N.
  auto terminal_constraint_multiplier() const { return this->core_.lam_a.template tail<NGN>(); }

  /// The local feedback gain of stage k, 0 <= k < N: gain = du_k / dx_k of the equality-constrained
  /// QP of the last solve's final working set, with x_k held and the stages after it free (the
  /// matrix of the Riccati recursion's u_k elimination: -(M_uu)^-1 M_ux, M_k = G_k + F_k' P_{k+1}
  /// F_k). On that working set:
  ///   - an input bound in it (u_k fixed, exact_bound) gives a zero row: that input stays on its
  ///     bound for any small dx_k; the other rows are the gain of the free inputs alone;
  ///   - a state bound of x_j, j >= 1, and a path or terminal row in it enter as the solver holds
  ///     them, by the proximal weight w = h / reg_dual on their row (active_set.hpp): the gain is
  ///     that of those constraints as stiff quadratic penalties, which tends to the gain with
  ///     them as equalities as reg_dual -> 0 (relative error ~ the curvature / w: 1e-6 in double,
  ///     1e-3 in float with the default settings), and every block carries delta = reg_primal;
  ///   - with no constraint in it, the gain is the unconstrained LQR gain of the QP's stages.
  /// The QP is linear in x_0, so for the real-time iteration's delta form the gain of stage 0 is
  /// that of u_0 with respect to the measured x_0 while the working set holds.
  /// Reuses the Riccati factor of the last solve: stage k >= 1 NU^2 NX / 2 multiply-adds, stage 0
  /// with x_0 fixed (the NMPC's) NW NX^2 / 2 + NU NX^2 + NU^2 NX (6.1 k for NX = 16, NU = 8), plus
  /// one pass over the working set; no heap. Returns false (gain not written) when there is no
  /// factor of the returned iterate's working set: no solve since the last setup()/update(), a
  /// failed factorization (non_convex), or a solve that returned an earlier iterate than its last
  /// step's (stalled, or iteration_limit without last_iterate_at_cap, whose best iterate's
  /// working set was not factorized). The matrices must still be those of the last solve
  /// (the gain reads A_0, B_0, S_0 and the path rows through the problem's pointer); the iterate
  /// may have moved by shift() (the gain stays that of the solved QP's stage k).
  [[nodiscard]] bool feedback_gain(int k, Eigen::Matrix<Scalar, NU, NX>& gain) const {
    ARBOR_ASSERT(k >= 0 && k < N, "stage index out of range");
    if (!this->ready_ || !this->be_.holds(this->core_.ws.data()))
      return false;
    this->be_.feedback_gain(k, gain);
    return true;
  }

 private:
  /// set_state_bounds(): prepared may be null (then every prepared start is invalid afterwards).
  QpStatus move_state_bounds(PreparedStart* prepared, int k, const Eigen::Matrix<Scalar, NX, 1>& lb,
                             const Eigen::Matrix<Scalar, NX, 1>& ub) {
    ARBOR_ASSERT(k >= 1 && k <= N, "state bounds of stages 1..N (x_0's: solve_from)");
    if (const QpStatus c = detail::check_bounds(lb, ub); c != QpStatus::accepted)
      return c;
    const int o = Problem::state_offset(k);
    for (int i = 0; i < NX; ++i)
      this->core_.template move_bound<Backend>(prepared, o + i, lb(i), ub(i));
    return QpStatus::accepted;
  }

  /// Checks path stage k and copies its vectors into the flat arrays.
  QpStatus read_stage(int k, const typename Problem::Stage& st, bool check_convexity,
                      bool check_finite) {
    if (check_finite && !detail::all_finite(st.Q, st.S, st.R, st.A, st.B, st.C, st.D))
      return QpStatus::non_finite;
    if (const QpStatus v = check_vectors(st); v != QpStatus::accepted)
      return v;
    if (check_convexity) {
      Eigen::Matrix<Scalar, NX + NU, NX + NU> h;
      h.template topLeftCorner<NX, NX>() = st.Q;
      h.template bottomLeftCorner<NU, NX>() = st.S;
      h.template topRightCorner<NX, NU>() = st.S.transpose();
      h.template bottomRightCorner<NU, NU>() = st.R;
      if (!detail::is_psd(h, this->settings_.psd_tolerance))
        return QpStatus::non_convex;
    }
    copy_vectors(k, st);
    return QpStatus::accepted;
  }

  /// Checks path stage k's vectors (finite, bounds ordered) and copies them.
  QpStatus read_vectors(int k, const typename Problem::Stage& st) {
    const QpStatus v = check_vectors(st);
    if (v == QpStatus::accepted)
      copy_vectors(k, st);
    return v;
  }

  /// Whether a path stage's vectors are finite (bounds may be infinite) and its bounds ordered.
  static QpStatus check_vectors(const typename Problem::Stage& st) {
    if (!detail::all_finite(st.q, st.r, st.b))
      return QpStatus::non_finite;
    for (QpStatus c : {detail::check_bounds(st.lbx, st.ubx), detail::check_bounds(st.lbu, st.ubu),
                       detail::check_bounds(st.lg, st.ug)}) {
      if (c != QpStatus::accepted)
        return c;
    }
    return QpStatus::accepted;
  }

  /// Copies path stage k's vectors into the flat arrays.
  void copy_vectors(int k, const typename Problem::Stage& st) {
    auto& c = this->core_;
    const int o = Problem::state_offset(k), r = Problem::dynamics_offset(k);
    c.lbx.template segment<NX>(o) = st.lbx;
    c.ubx.template segment<NX>(o) = st.ubx;
    c.lbx.template segment<NU>(o + NX) = st.lbu;
    c.ubx.template segment<NU>(o + NX) = st.ubu;
    c.g.template segment<NX>(o) = st.q;
    c.g.template segment<NU>(o + NX) = st.r;
    c.lba.template segment<NX>(r) = st.b;
    c.uba.template segment<NX>(r) = st.b;
    c.lba.template segment<NG>(r + NX) = st.lg;
    c.uba.template segment<NG>(r + NX) = st.ug;
  }

  /// Checks the terminal stage and copies its vectors into the flat arrays.
  QpStatus read_terminal(const typename Problem::Terminal& t, bool check_convexity,
                         bool check_finite) {
    if (check_finite && !detail::all_finite(t.Q, t.C))
      return QpStatus::non_finite;
    if (const QpStatus v = check_terminal_vectors(t); v != QpStatus::accepted)
      return v;
    if (check_convexity && !detail::is_psd(t.Q, this->settings_.psd_tolerance))
      return QpStatus::non_convex;
    copy_terminal_vectors(t);
    return QpStatus::accepted;
  }

  /// Checks the terminal stage's vectors and copies them.
  QpStatus read_terminal_vectors(const typename Problem::Terminal& t) {
    const QpStatus v = check_terminal_vectors(t);
    if (v == QpStatus::accepted)
      copy_terminal_vectors(t);
    return v;
  }

  /// Whether the terminal vectors are finite and its bounds ordered.
  static QpStatus check_terminal_vectors(const typename Problem::Terminal& t) {
    if (!detail::all_finite(t.q))
      return QpStatus::non_finite;
    for (QpStatus c : {detail::check_bounds(t.lbx, t.ubx), detail::check_bounds(t.lg, t.ug)})
      if (c != QpStatus::accepted)
        return c;
    return QpStatus::accepted;
  }

  /// Copies the terminal vectors into the flat arrays.
  void copy_terminal_vectors(const typename Problem::Terminal& t) {
    auto& c = this->core_;
    c.lbx.template tail<NX>() = t.lbx;
    c.ubx.template tail<NX>() = t.ubx;
    c.g.template tail<NX>() = t.q;
    c.lba.template tail<NGN>() = t.lg;
    c.uba.template tail<NGN>() = t.ug;
  }
};

}  // namespace arbor::qp
