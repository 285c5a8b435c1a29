// Second order: H = d^2 (lambda^T f) / dx^2 of forward and inverse dynamics by nested duals
// through the RBD templates (H^c) and by duals through the analytical first-order routines (H^a).
// Both must be symmetric, agree with each other, and match central finite differences of the
// gradient lambda^T J(x) (J from the analytical routine in double). The first-order providers
// (Analytical, AutoDiff) must agree too, for the dynamics and the frame positions. Compiled at
// -O0 (the whole set: 61 s of compiler CPU, 136 s at -O1; runs in 0.2 s); the Kinova's forward
// and inverse dynamics Hessians are in units of their own (compiler memory: 2.2 GB in one).
#include <gtest/gtest.h>

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <memory>
#include <random>
#include <robots/double_pendulum.hpp>
#include <robots/iiwa7.hpp>
#include <robots/kinova_gen3.hpp>

#include "../derivatives/derivative_checks.hpp"
#include "hessian_checks.hpp"
#include "provider_checks.hpp"

namespace {

using namespace arbor;
using arbor::test::NoAllocScope;
namespace pc = arbor::test::provider_checks;
using arbor::test::hessian_checks::hessians_agree;

template <class F>
void jacobian_providers_agree(unsigned seed) {
  constexpr int n = F::nin;
  constexpr int m = F::nout;
  std::mt19937 gen(seed);
  const VecN<double, n> x = pc::random_input<n>(gen);
  VecN<double, m> ya, yc;
  Eigen::Matrix<double, m, n> Ja, Jc;
  pc::value_and_jacobian<F, ad::Analytical>(x, ya, Ja);
  pc::value_and_jacobian<F, ad::AutoDiff>(x, yc, Jc);
  const VecN<double, m> y = pc::value<F>(x);
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
// KinovaGen3ForwardDynamics (seed 4) and KinovaGen3InverseDynamics (seed 5):
// hessian_kinova_fd_test.cpp and hessian_kinova_id_test.cpp, units of their own.

TEST(AdJacobianProviders, AgreeForDynamicsAndFramePositions) {
  jacobian_providers_agree<ad::ForwardDynamics<robots::Iiwa7>>(6);
  jacobian_providers_agree<ad::InverseDynamics<robots::Iiwa7>>(7);
  jacobian_providers_agree<ad::FramePosition<robots::KinovaGen3, robots::KinovaGen3::nf - 1>>(8);
  jacobian_providers_agree<ad::FramePosition<robots::KinovaGen3, 3>>(9);
}

}  // namespace
