// Second order: H = d^2 (lambda^T f) / dx^2 of forward and inverse dynamics by nested duals
// through the RBD templates (H^c) and by duals through the analytical first-order routines (H^a).
// Both must be symmetric, agree with each other, and match central finite differences of the
// gradient lambda^T J(x) (J from the analytical routine in double). The first-order providers
// (Analytical, AutoDiff) must agree too, for the dynamics and the frame positions.
#include <gtest/gtest.h>

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <memory>
#include <random>
#include <robots/double_pendulum.hpp>
#include <robots/iiwa7.hpp>
#include <robots/kinova_gen3.hpp>

#include "../derivatives/derivative_checks.hpp"

namespace {

using namespace arbor;
using arbor::test::NoAllocScope;

template <class F>
void hessians_agree(unsigned seed) {
  constexpr int n = F::nin;
  constexpr int m = F::nout;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  VecN<double, n> x;
  VecN<double, m> lambda;
  for (int i = 0; i < n; ++i)
    x[i] = u(gen);
  for (int i = 0; i < m; ++i)
    lambda[i] = u(gen);
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

template <class F>
void jacobian_providers_agree(unsigned seed) {
  constexpr int n = F::nin;
  constexpr int m = F::nout;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  VecN<double, n> x;
  for (int i = 0; i < n; ++i)
    x[i] = u(gen);
  VecN<double, m> ya, yc, y;
  // (zero-initialised: at -O1 GCC warns that an output argument may be used uninitialised)
  Eigen::Matrix<double, m, n> Ja = Eigen::Matrix<double, m, n>::Zero(), Jc = Ja;
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical>>();
  auto wc = std::make_unique<ad::JacobianWorkspace<F, ad::AutoDiff>>();
  auto wv = std::make_unique<ad::ValueWorkspace<F>>();
  {
    NoAllocScope guard;
    ad::bind<F>(*wa).template value_and_jacobian<ad::Analytical>(x, ya, Ja);
    ad::bind<F>(*wc).template value_and_jacobian<ad::AutoDiff>(x, yc, Jc);
    ad::bind<F>(*wv).value(x, y);
  }
  // The analytical provider's forward-dynamics value is M^-1 (tau - nle) with M^-1 from the
  // derivative sweep's own mass matrix (aba_derivatives since 7df6851), not aba's recursion: the
  // same quantity rounded differently (iiwa7: 2.1e-13 relative), hence 1e-12 here; the duals run
  // aba itself.
  ARBOR_EXPECT_REL(ya, y, 1e-12);
  ARBOR_EXPECT_REL(yc, y, 1e-13);
  ARBOR_EXPECT_REL(Ja, Jc, 1e-10);
}

TEST(AdHessian, DoublePendulumForwardDynamics) {
  hessians_agree<ad::ForwardDynamics<robots::DoublePendulum>>(1);
}
TEST(AdHessian, DoublePendulumInverseDynamics) {
  hessians_agree<ad::InverseDynamics<robots::DoublePendulum>>(2);
}
TEST(AdHessian, Iiwa7InverseDynamics) {
  hessians_agree<ad::InverseDynamics<robots::Iiwa7>>(3);
}
TEST(AdHessian, KinovaGen3ForwardDynamics) {
  hessians_agree<ad::ForwardDynamics<robots::KinovaGen3>>(4);
}
TEST(AdHessian, KinovaGen3InverseDynamics) {
  hessians_agree<ad::InverseDynamics<robots::KinovaGen3>>(5);
}

TEST(AdJacobianProviders, AgreeForDynamicsAndFramePositions) {
  jacobian_providers_agree<ad::ForwardDynamics<robots::Iiwa7>>(6);
  jacobian_providers_agree<ad::InverseDynamics<robots::Iiwa7>>(7);
  jacobian_providers_agree<ad::FramePosition<robots::KinovaGen3, robots::KinovaGen3::nf - 1>>(8);
  jacobian_providers_agree<ad::FramePosition<robots::KinovaGen3, 3>>(9);
}

}  // namespace
