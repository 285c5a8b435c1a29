// arbor::qp::detail: the linear algebra of the dense solver: a dense Cholesky of
// M = H + delta I + A_W' E A_W (NV x NV, see active_set.hpp), refactorized after every change.
// Cost: NV^3 / 6 + NA_W NV^2 / 2 multiply-adds per factorization, NV^2 per solve.
// Memory: NV^2 scalars (the factor); H and A are read through a pointer.
#pragma once

#include <Eigen/Core>

#include "arbor/qp/backend.hpp"
#include "arbor/qp/cholesky.hpp"
#include "arbor/qp/problem.hpp"

namespace arbor::qp::detail {

/// Dense linear algebra backend for ActiveSetCore.
template <typename Scalar, int NV, int NA>
struct DenseBackend {
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;
  const DenseQpProblem<Scalar, NV, NA>* p = nullptr;  ///< the problem (matrices read here)
  Eigen::Matrix<Scalar, NV, NV> m;                    ///< Cholesky factor U of M (upper)

  void hess_mul(const VecV& x, VecV& y) const { y.noalias() = p->H * x; }
  void cons_mul(const VecV& x, VecA& y) const { y.noalias() = p->A * x; }
  void cons_tmul(const VecA& l, VecV& y) const { y.noalias() = p->A.transpose() * l; }
  void mark_changed(int) {}
  void mark_all() {}
  void row_norms_sq(VecA& n) const { n = p->A.rowwise().squaredNorm(); }
  Scalar hessian_scale() const { return p->H.diagonal().cwiseAbs().maxCoeff(); }
  int factorize(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    m = p->H;
    m.diagonal().array() += delta;
    for (int i = 0; i < NV; ++i) {
      if (ws[i] != ConstraintState::inactive)
        m(i, i) += w;
    }
    for (int j = 0; j < NA; ++j) {
      if (ws[NV + j] == ConstraintState::inactive)
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

}  // namespace arbor::qp::detail
