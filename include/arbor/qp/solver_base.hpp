// arbor::qp::detail: what the dense and the OCP solvers share: the active-set core, a backend,
// settings, the report of the last solve, and the life cycle setup/update -> solve. The two
// solvers add only how their data are checked and copied (their setup() and update()).
// Memory: sizeof(ActiveSetCore) + sizeof(Backend) + a few scalars.
#pragma once

#include <Eigen/Core>

#include "arbor/qp/active_set.hpp"
#include "arbor/qp/backend.hpp"
#include "arbor/qp/prepared_start.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp::detail {

/// Active-set solver on NV variables and NA rows with the linear algebra of Backend.
template <typename Scalar, int NV, int NA, typename Backend>
class ActiveSetSolver {
  static_assert(ActiveSetBackend<Backend, Scalar, NV, NA>,
                "the backend must provide the interface of backend.hpp");

 public:
  static constexpr int nv = NV;  ///< variables
  static constexpr int na = NA;  ///< constraint rows
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;
  /// What a preparation leaves for the next solve (OcpQpSolver::prepare_start()).
  using PreparedStart = detail::PreparedStart<Scalar, NV>;

  /// Resets the iterate: x = projection of 0 onto the bounds, multipliers 0.
  void cold_start() {
    core_.cold_start();
    initialized_ = true;
  }

  /// Solves from the current iterate (warm start: the last solution, or set_warm_start(),
  /// edit_warm_start()); not_setup unless the last setup()/update() was accepted.
  [[nodiscard]] QpStatus solve() {
    if (!ready_)
      return QpStatus::not_setup;
    return core_.solve(be_, settings_, info_);
  }

  /// Factorizes now, for the working set the current multipliers name, what the next solve()
  /// would factorize first; that solve() then starts with its first linear solve (its
  /// info().stages_factorized excludes these blocks). For real-time iteration: call it in the
  /// preparation phase, after the last change of the matrices; the feedback may change bounds
  /// and gradients (update_vectors() of the OCP solver keeps the factorization; setup() and
  /// update() discard it). Returns the number of blocks factorized, or -1 when nothing will be
  /// reused (not set up, or a pivot failure: solve() then factorizes as usual).
  int prefactorize() {
    if (!ready_)
      return -1;
    int stages = 0;
    return core_.prefactorize(be_, settings_, stages) ? stages : -1;
  }

  /// Sets the warm start of the next solve: the primal iterate and the multipliers (> 0: upper
  /// bound active, < 0: lower bound active). Invalidates every prepared start.
  void set_warm_start(const VecV& x, const VecV& lam_x, const VecA& lam_a) {
    core_.x = x;
    core_.lam_x = lam_x;
    core_.lam_a = lam_a;
    core_.note_change();
  }
  /// Edits the warm start in place: edit(x, lam_x, lam_a) with writable references that are
  /// valid only during the call (e.g. x.setZero(), a shift of the multipliers). Invalidates
  /// every prepared start.
  template <class Edit>
  void edit_warm_start(Edit&& edit) {
    edit(core_.x, core_.lam_x, core_.lam_a);
    core_.note_change();
  }

  /// Flat primal iterate / solution.
  const VecV& x() const { return core_.x; }
  /// Multipliers of the variable bounds (> 0: upper bound active, < 0: lower bound active).
  const VecV& lam_x() const { return core_.lam_x; }
  /// Multipliers of the rows (same sign convention); stationarity: H x + g + lam_x + A' lam_a = 0.
  const VecA& lam_a() const { return core_.lam_a; }

  /// Report of the last solve.
  const SolveInfo<Scalar>& info() const { return info_; }
  /// Settings in use (may be changed between solves).
  QpSettings<Scalar>& settings() { return settings_; }
  const QpSettings<Scalar>& settings() const { return settings_; }

 protected:
  /// Ends a setup()/update(): the solver is ready exactly when st is accepted; the iterate is
  /// cold-started the first time, kept (warm start) afterwards; a prefactorization is discarded
  /// unless only vectors were read (keep_factorization); every prepared start is invalid.
  QpStatus conclude(QpStatus st, bool keep_factorization = false) {
    if (!keep_factorization)
      core_.discard_prefactorization();
    core_.note_change();  // (the vectors were re-read in any case)
    ready_ = st == QpStatus::accepted;
    if (ready_ && !initialized_)
      cold_start();
    return st;
  }

  ActiveSetCore<Scalar, NV, NA> core_;  ///< iterate, copied vectors and active-set workspace
  Backend be_;                          ///< factorization; points to the problem's matrices
  QpSettings<Scalar> settings_{};       ///< settings of the next solve
  SolveInfo<Scalar> info_{};            ///< report of the last solve
  bool ready_ = false;                  ///< the last setup()/update() was accepted
  bool initialized_ = false;            ///< the iterate holds values
};

}  // namespace arbor::qp::detail
