// Second order by nested duals through the RBD templates (H^c) and by duals through the
// analytical first-order routines (H^a) of an RBD function object: both symmetric, equal to each
// other and to central differences of the analytical gradient lambda^T J(x); the values equal the
// plain function's. Shared by hessian_test.cpp and hessian_kinova_fd_test.cpp (one unit would
// need 2.2 GB of compiler memory). Cost: one nested-dual pass, one H^a, 2 n analytical Jacobians.
#pragma once

#include <gtest/gtest.h>

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <memory>
#include <random>

#include "../derivatives/derivative_checks.hpp"
#include "provider_checks.hpp"

namespace arbor::test::hessian_checks {

namespace pc = arbor::test::provider_checks;

template <class F>
void hessians_agree(unsigned seed) {
  constexpr int n = F::nin;
  constexpr int m = F::nout;
  std::mt19937 gen(seed);
  const VecN<double, n> x = pc::random_input<n>(gen);
  const VecN<double, m> lambda = pc::random_input<m>(gen);
  VecN<double, m> ya, yc;
  static Eigen::Matrix<double, n, n> Ha, Hc;
  // Caller-owned workspaces, one per call kind (large for nested duals: on the heap here).
  auto wa = std::make_unique<ad::HessianWorkspace<F, ad::Analytical>>();
  auto wc = std::make_unique<ad::HessianWorkspace<F, ad::AutoDiff>>();
  auto wv = std::make_unique<ad::ValueWorkspace<F>>();
  auto wj = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical>>();
  {
    NoAllocScope guard;
    ad::contracted_hessian<ad::Analytical>(ad::bind<F>(*wa), x, lambda, ya, Ha);
    ad::contracted_hessian<ad::AutoDiff>(ad::bind<F>(*wc), x, lambda, yc, Hc);
  }
  VecN<double, m> y;
  {
    NoAllocScope guard;
    ad::bind<F>(*wv).value(x, y);
  }
  ARBOR_EXPECT_REL(ya, y, 1e-13);
  ARBOR_EXPECT_REL(yc, y, 1e-13);
  ARBOR_EXPECT_REL(Ha, Ha.transpose(), 1e-11);
  ARBOR_EXPECT_REL(Hc, Hc.transpose(), 1e-11);
  ARBOR_EXPECT_REL(Ha, Hc, 1e-10);
  // Central differences of the gradient g(x) = J(x)^T lambda.
  Eigen::Matrix<double, m, n> J;
  const Eigen::Matrix<double, n, n> Hfd =
      arbor::test::derivative_checks::central_diff<n, n>(x, [&](const VecN<double, n>& xx) {
        VecN<double, m> yy;
        ad::bind<F>(*wj).template value_and_jacobian<ad::Analytical>(xx, yy, J);
        return VecN<double, n>(J.transpose() * lambda);
      });
  ARBOR_EXPECT_REL(Hc, Hfd, 1e-6);
  // Second order is not trivially zero: the q-q block of a dynamics Hessian is dense-ish.
  EXPECT_GT(Hc.cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace arbor::test::hessian_checks
