// arbor::qp: dense active-set QP solver for small problems of fixed size.
//
//   min 1/2 x'Hx + g'x   s.t.  lbx <= x <= ubx,  lba <= A x <= uba       (x in R^NV, A: NA x NV)
//
// Same active-set logic as the OCP solver (active_set.hpp); the linear algebra is a dense
// Cholesky of M = H + delta I + A_W' E A_W (NV x NV, see active_set.hpp), refactorized after every
// change. Used for small problems and in the tests to cross-check the structured solver. Memory:
// sizeof(DenseQpSolver) ~ (NV^2 + 11 NV + 8 NA) scalars; the problem is referenced, not copied (it
// must outlive the solver's use of it). H must be symmetric and positive semidefinite.
//
//   DenseQpProblem<double, 3, 2> p;   // fill H, g, A, bounds (+-inf allowed)
//   static DenseQpSolver<double, 3, 2> solver;
//   if (solver.setup(p) == QpStatus::solved) { solver.cold_start(); status = solver.solve(); }
//   solver.x(), solver.lam_x(), solver.lam_a(), solver.info()
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>

#include "arbor/qp/active_set.hpp"
#include "arbor/qp/cholesky.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp {

/// Data of a dense QP (see the top of this file).
template <typename Scalar, int NV, int NA>
struct DenseQpProblem {
  Eigen::Matrix<Scalar, NV, NV> H;   ///< symmetric positive semidefinite Hessian
  Eigen::Matrix<Scalar, NV, 1> g;    ///< linear cost
  Eigen::Matrix<Scalar, NA, NV> A;   ///< constraint matrix
  Eigen::Matrix<Scalar, NV, 1> lbx;  ///< variable lower bounds (may be -inf)
  Eigen::Matrix<Scalar, NV, 1> ubx;  ///< variable upper bounds (may be +inf)
  Eigen::Matrix<Scalar, NA, 1> lba;  ///< row lower bounds (may be -inf)
  Eigen::Matrix<Scalar, NA, 1> uba;  ///< row upper bounds (may be +inf)
};

namespace detail {

/// Checks bounds: no NaN, lb <= ub, lb < +inf, ub > -inf.
template <typename Vec>
QpStatus check_bounds(const Vec& lb, const Vec& ub) {
  using Scalar = typename Vec::Scalar;
  constexpr Scalar inf = std::numeric_limits<Scalar>::infinity();
  for (int i = 0; i < lb.size(); ++i) {
    if (std::isnan(lb(i)) || std::isnan(ub(i)))
      return QpStatus::non_finite;
    if (lb(i) > ub(i) || lb(i) == inf || ub(i) == -inf)
      return QpStatus::invalid_bounds;
  }
  return QpStatus::solved;
}

/// True when a symmetric matrix (upper triangle) is positive semidefinite up to a relative slack.
template <typename Mat>
bool is_psd(const Mat& h, typename Mat::Scalar slack) {
  using Scalar = typename Mat::Scalar;
  Mat m = h;
  const Scalar scale = Scalar(1) + (h.size() > 0 ? h.cwiseAbs().maxCoeff() : Scalar(0));
  m.diagonal().array() += slack * scale * Scalar(h.rows());
  return cholesky_upper_in_place(m);
}

/// Dense linear algebra backend for ActiveSetCore.
template <typename Scalar, int NV, int NA>
struct DenseBackend {
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;
  const DenseQpProblem<Scalar, NV, NA>* p = nullptr;  ///< referenced problem
  Eigen::Matrix<Scalar, NV, NV> m;                    ///< Cholesky factor U of M (upper)

  void hess_mul(const VecV& x, VecV& y) const { y.noalias() = p->H * x; }
  void cons_mul(const VecV& x, VecA& y) const { y.noalias() = p->A * x; }
  void cons_tmul(const VecA& l, VecV& y) const { y.noalias() = p->A.transpose() * l; }
  void mark_changed(int) {}
  void mark_all() {}
  void row_norms_sq(VecA& n) const { n = p->A.rowwise().squaredNorm(); }
  int factorize(const std::int8_t* ws, Scalar delta, Scalar w, const VecA& wa) {
    m = p->H;
    m.diagonal().array() += delta;
    for (int i = 0; i < NV; ++i) {
      if (ws[i] != kInactive)
        m(i, i) += w;
    }
    for (int j = 0; j < NA; ++j) {
      if (ws[NV + j] == kInactive)
        continue;
      for (int c = 0; c < NV; ++c) {
        const Scalar ac = wa(j) * p->A(j, c);
        if (ac == Scalar(0))
          continue;
        for (int r = 0; r <= c; ++r)
          m(r, c) += ac * p->A(j, r);
      }
    }
    return cholesky_upper_in_place(m) ? 1 : -1;
  }
  void solve(VecV& b) const {
    solve_upper_transposed(m, b);
    solve_upper(m, b);
  }
};

}  // namespace detail

/// Dense active-set QP solver (see the top of this file).
template <typename Scalar, int NV, int NA>
class DenseQpSolver {
 public:
  using Problem = DenseQpProblem<Scalar, NV, NA>;
  using Core = detail::ActiveSetCore<Scalar, NV, NA>;

  /// Checks the data (finite, bounds ordered, H positive semidefinite) and keeps a reference to
  /// it; returns solved on success, else the problem's status. Keeps the current iterate (so a
  /// following solve() is warm-started); call cold_start() to reset it.
  QpStatus setup(const Problem& p, const QpSettings<Scalar>& s = QpSettings<Scalar>{}) {
    ready_ = false;
    settings_ = s;
    if (!p.H.allFinite() || !p.g.allFinite() || !p.A.allFinite())
      return QpStatus::non_finite;
    QpStatus st = detail::check_bounds(p.lbx, p.ubx);
    if (st != QpStatus::solved)
      return st;
    st = detail::check_bounds(p.lba, p.uba);
    if (st != QpStatus::solved)
      return st;
    if (!detail::is_psd(p.H, s.psd_tolerance))
      return QpStatus::non_convex;
    be_.p = &p;
    core_.lbx = p.lbx;
    core_.ubx = p.ubx;
    core_.lba = p.lba;
    core_.uba = p.uba;
    core_.g = p.g;
    if (!initialized_)
      cold_start();
    ready_ = true;
    return QpStatus::solved;
  }

  /// Resets the iterate: x = projection of 0 onto the bounds, multipliers 0.
  void cold_start() {
    core_.cold_start();
    initialized_ = true;
  }

  /// Solves from the current iterate (warm start: the last solution or values set through
  /// x(), lam_x(), lam_a()).
  QpStatus solve() {
    if (!ready_)
      return QpStatus::not_setup;
    return core_.solve(be_, settings_, info_);
  }

  /// Primal iterate / solution.
  Eigen::Matrix<Scalar, NV, 1>& x() { return core_.x; }
  /// Multipliers of the variable bounds (> 0 upper active, < 0 lower active).
  Eigen::Matrix<Scalar, NV, 1>& lam_x() { return core_.lam_x; }
  /// Multipliers of the constraint rows.
  Eigen::Matrix<Scalar, NA, 1>& lam_a() { return core_.lam_a; }
  /// Report of the last solve.
  const SolveInfo<Scalar>& info() const { return info_; }
  /// Settings in use (may be changed between solves).
  QpSettings<Scalar>& settings() { return settings_; }

 private:
  Core core_;                                ///< iterate and active-set workspace
  detail::DenseBackend<Scalar, NV, NA> be_;  ///< dense factorization
  QpSettings<Scalar> settings_{};            ///< settings of the next solve
  SolveInfo<Scalar> info_{};                 ///< report of the last solve
  bool ready_ = false;                       ///< setup() succeeded
  bool initialized_ = false;                 ///< the iterate holds values
};

}  // namespace arbor::qp
