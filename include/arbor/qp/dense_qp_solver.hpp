// arbor::qp: dense active-set QP solver for small problems of fixed size (DenseQpProblem in
// problem.hpp).
//
// Same active-set logic as the OCP solver (active_set.hpp); the linear algebra is a dense
// Cholesky of M = H + delta I + A_W' E A_W (dense_backend.hpp), refactorized after every change.
// Used for small problems and in the tests to cross-check the structured solver. Memory:
// sizeof(DenseQpSolver) ~ (NV^2 + 11 NV + 8 NA) scalars. Copy/reference rule (problem.hpp): g
// and the bounds are copied by setup()/update(), H and A are read through a pointer by every
// solve(); the problem must outlive the solver's use of it. H must be symmetric positive
// semidefinite (checked unless Convexity::assumed).
//
//   DenseQpProblem<double, 3, 2> p;   // fill H, g, A, bounds (+-inf allowed)
//   static DenseQpSolver<double, 3, 2> solver;
//   if (solver.setup(p) == QpStatus::accepted) { solver.cold_start(); status = solver.solve(); }
//   solver.x(), solver.lam_x(), solver.lam_a(), solver.info()
//   p.g = ...; solver.update(); status = solver.solve();   // re-reads p, warm-started
#pragma once

#include "arbor/qp/data_checks.hpp"
#include "arbor/qp/dense_backend.hpp"
#include "arbor/qp/problem.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/solver_base.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp {

/// Dense active-set QP solver (see the top of this file).
template <typename Scalar, int NV, int NA>
class DenseQpSolver
    : public detail::ActiveSetSolver<Scalar, NV, NA, detail::DenseBackend<Scalar, NV, NA>> {
 public:
  using Problem = DenseQpProblem<Scalar, NV, NA>;

  /// Keeps a pointer to p and the settings, then update(Convexity::checked). The current
  /// iterate is kept (so a following solve() is warm-started); call cold_start() to reset it.
  [[nodiscard]] QpStatus setup(const Problem& p,
                               const QpSettings<Scalar>& s = QpSettings<Scalar>{}) {
    this->settings_ = s;
    this->be_.p = &p;
    return update(Convexity::checked);
  }

  /// Re-reads the problem given to setup(): checks it (finite, H and A unless their finiteness
  /// is assumed; bounds ordered and, unless convexity is assumed, H positive semidefinite) and
  /// copies g and the bounds. Returns accepted, else the problem's status (and solve() returns
  /// not_setup until one is accepted).
  [[nodiscard]] QpStatus update(Convexity convexity = Convexity::checked,
                                Finiteness finiteness = Finiteness::checked) {
    const Problem* p = this->be_.p;
    if (p == nullptr)
      return this->conclude(QpStatus::not_setup);
    if (!detail::all_finite(p->g) ||
        (finiteness == Finiteness::checked && !detail::all_finite(p->H, p->A)))
      return this->conclude(QpStatus::non_finite);
    QpStatus st = detail::check_bounds(p->lbx, p->ubx);
    if (st == QpStatus::accepted)
      st = detail::check_bounds(p->lba, p->uba);
    if (st != QpStatus::accepted)
      return this->conclude(st);
    if (convexity == Convexity::checked && !detail::is_psd(p->H, this->settings_.psd_tolerance))
      return this->conclude(QpStatus::non_convex);
    auto& c = this->core_;
    c.lbx = p->lbx;
    c.ubx = p->ubx;
    c.lba = p->lba;
    c.uba = p->uba;
    c.g = p->g;
    return this->conclude(QpStatus::accepted);
  }
};

}  // namespace arbor::qp
