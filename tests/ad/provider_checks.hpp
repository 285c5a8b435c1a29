// Test helpers shared by the AD provider tests (generated_random_test.cpp, hessian_test.cpp):
// a random input, one provider's value and Jacobian of an RBD function object (its workspace on
// the heap, the call under the allocation guard), the plain value, and central differences of
// the value. Costs what the calls cost; nothing here is checked, the callers compare.
#pragma once

#include <arbor/ad/rbd_functions.hpp>
#include <memory>
#include <random>

#include "../derivatives/derivative_checks.hpp"

namespace arbor::test::provider_checks {

/// x uniform in [-1.2, 1.2]^n.
template <int n>
VecN<double, n> random_input(std::mt19937& gen) {
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  VecN<double, n> x;
  for (int i = 0; i < n; ++i)
    x[i] = u(gen);
  return x;
}

/// y = F(x) and J = dF/dx by provider Tag (workspace on the heap, the call allocation-free).
template <class F, class Tag>
void value_and_jacobian(const VecN<double, F::nin>& x, VecN<double, F::nout>& y,
                        Eigen::Matrix<double, F::nout, F::nin>& J) {
  auto w = std::make_unique<ad::JacobianWorkspace<F, Tag>>();
  // (zero-initialised: at -O1 GCC warns that an output argument may be used uninitialised)
  y.setZero();
  J.setZero();
  NoAllocScope guard;
  ad::bind<F>(*w).template value_and_jacobian<Tag>(x, y, J);
}

/// F(x), allocation-free.
template <class F>
VecN<double, F::nout> value(const VecN<double, F::nin>& x) {
  auto w = std::make_unique<ad::ValueWorkspace<F>>();
  VecN<double, F::nout> y = VecN<double, F::nout>::Zero();
  NoAllocScope guard;
  ad::bind<F>(*w).value(x, y);
  return y;
}

/// Central differences of F's value at x (derivative_checks::central_diff).
template <class F>
Eigen::Matrix<double, F::nout, F::nin> value_central_diff(const VecN<double, F::nin>& x) {
  auto w = std::make_unique<ad::ValueWorkspace<F>>();
  return derivative_checks::central_diff<F::nout, F::nin>(x, [&](const VecN<double, F::nin>& xx) {
    VecN<double, F::nout> yy;
    ad::bind<F>(*w).value(xx, yy);
    return yy;
  });
}

}  // namespace arbor::test::provider_checks
