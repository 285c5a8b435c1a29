// Test bodies for Dual through the RBD templates (the paper's J^c): against the project's
// analytical derivatives, the reference values (Pinocchio's analytical derivatives) and central
// finite differences of the double-valued rnea/aba. Directions are seeded in chunks of at most
// 8 (one chunk type for every robot: Data<Atlas, Dual<double, 8>> stays within Eigen's
// fixed-size limit). Every library call runs inside an allocation guard.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <arbor/ad/dual.hpp>
#include <arbor/derivatives/derivatives.hpp>
#include <arbor/dynamics/dynamics.hpp>
#include <memory>
#include <random>
#include <string>

#include "../derivatives/derivative_checks.hpp"

namespace arbor::test::dual_checks {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

/// Which algorithm a Jacobian is taken of.
enum class Algo { Rnea, Aba };

/// d out / d (x0, x1, x2) of rnea (out = tau, x = q, v, a) or aba (out = ddq, x = q, v, tau) by
/// Dual<double, C> through the templates, C directions per pass; J = [d/dx0, d/dx1, d/dx2].
template <class R, Algo A>
Eigen::Matrix<double, R::nv, 3 * R::nv> dual_jacobian(const Vec<R::nv>& x0, const Vec<R::nv>& x1,
                                                      const Vec<R::nv>& x2) {
  constexpr int n = R::nv;
  constexpr int C = n < 8 ? n : 8;
  using D = ad::Dual<double, C>;
  static Data<R, D> d;  // large for Atlas: static storage
  Eigen::Matrix<double, n, 3 * n> J;
  for (int c0 = 0; c0 < 3 * n; c0 += C) {
    VecN<D, n> x[3];
    for (int g = 0; g < 3; ++g)
      for (int i = 0; i < n; ++i) {
        const double xv = g == 0 ? x0[i] : g == 1 ? x1[i] : x2[i];
        const int k = g * n + i - c0;
        x[g][i] = (k >= 0 && k < C) ? D::variable(xv, k) : D(xv);
      }
    VecN<D, n> out;
    {
      NoAllocScope guard;
      if constexpr (A == Algo::Rnea) {
        rnea<R>(d, x[0], x[1], x[2]);
        out = d.tau;
      } else {
        aba<R>(d, x[0], x[1], x[2]);
        out = d.ddq;
      }
    }
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < C && c0 + k < 3 * n; ++k)
        J(i, c0 + k) = out[i].d[k];
  }
  return J;
}

/// Central differences of the double-valued rnea / aba with respect to (x0, x1, x2).
template <class R, Algo A>
Eigen::Matrix<double, R::nv, 3 * R::nv> fd_jacobian(const Vec<R::nv>& x0, const Vec<R::nv>& x1,
                                                    const Vec<R::nv>& x2) {
  constexpr int n = R::nv;
  auto d = std::make_unique<Data<R, double>>();
  Vec<3 * n> x;
  x << x0, x1, x2;
  return derivative_checks::central_diff<n, 3 * n>(x, [&](const Vec<3 * n>& y) {
    if constexpr (A == Algo::Rnea) {
      rnea<R>(*d, y.template segment<n>(0), y.template segment<n>(n), y.template segment<n>(2 * n));
      return Vec<n>(d->tau);
    } else {
      aba<R>(*d, y.template segment<n>(0), y.template segment<n>(n), y.template segment<n>(2 * n));
      return Vec<n>(d->ddq);
    }
  });
}

/// The Dual Jacobian of rnea (A = Rnea: d tau / d(q, v, a)) or aba (A = Aba: d ddq / d(q, v,
/// tau)) against the reference values and the analytical derivatives on every reference sample,
/// and against central finite differences on the first. WithAnalytical = false skips the
/// comparison with the project's analytical routine (for Atlas, whose analytical derivatives are
/// checked against the same reference values in tests/derivatives: it halves compile memory).
template <class R, Algo A, bool WithAnalytical = true>
void dual_matches_reference_and_analytical(const std::string& file_name, double tol_ref,
                                           double tol_fd) {
  constexpr int n = R::nv;
  constexpr bool id = A == Algo::Rnea;
  const ReferenceFile ref = load_reference(file_name);
  ASSERT_EQ(ref.nv, n);
  ASSERT_FALSE(ref.samples.empty());
  const std::vector<int> perm = joint_permutation<R>(ref);
  auto d = std::make_unique<Data<R, double>>();
  auto dd = std::make_unique<DerivativeData<R, double>>();
  int k = 0;
  for (const ReferenceSample& s : ref.samples) {
    SCOPED_TRACE("sample " + std::to_string(k++));
    const Vec<n> q = permute_vector(s.values.at("q"), perm);
    const Vec<n> v = permute_vector(s.values.at("v"), perm);
    const Vec<n> x2 = permute_vector(s.values.at(id ? "a" : "tau"), perm);
    const auto J = dual_jacobian<R, A>(q, v, x2);
    ARBOR_EXPECT_REL(J.template leftCols<n>(),
                     permute_matrix(s.values.at(id ? "drnea_dq" : "daba_dq"), perm), tol_ref);
    ARBOR_EXPECT_REL(J.template middleCols<n>(n),
                     permute_matrix(s.values.at(id ? "drnea_dv" : "daba_dv"), perm), tol_ref);
    ARBOR_EXPECT_REL(J.template rightCols<n>(),
                     permute_matrix(s.values.at(id ? "crba" : "minv"), perm), tol_ref);
    if constexpr (WithAnalytical) {
      {
        NoAllocScope guard;
        if constexpr (id)
          rnea_derivatives<R>(*d, *dd, q, v, x2);
        else
          aba_derivatives<R>(*d, *dd, q, v, x2);
      }
      ARBOR_EXPECT_REL(J.template leftCols<n>(), id ? dd->dtau_dq : dd->ddq_dq, 1e-10);
      ARBOR_EXPECT_REL(J.template middleCols<n>(n), id ? dd->dtau_dv : dd->ddq_dv, 1e-10);
      ARBOR_EXPECT_REL(J.template rightCols<n>(), id ? d->M : d->Minv, 1e-10);
    }
    if (k == 1) {
      ARBOR_EXPECT_REL(J, (fd_jacobian<R, A>(q, v, x2)), tol_fd);
    }
  }
}

}  // namespace arbor::test::dual_checks
