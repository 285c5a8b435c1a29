// Contracted second-order derivatives on random compile-time robots (branching trees, prismatic,
// unaligned and signed axes, massless links), part a: finite differences of the first-order
// derivatives, float against double, and the AD layer's nested-dual Hessian (H^c) and SecondOrder
// provider. Part b (second_order_random_b_test.cpp): a second robot.
#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>

#include "../dynamics/random_robot.hpp"
#include "second_order_checks.hpp"

namespace {
using namespace arbor::test::second_order_checks;

using R_2_5 = arbor::test::RandomRobot<2, 5>;
TEST(SecondOrderRandomRobot_2_5, MatchFiniteDifferences) {
  matches_finite_differences<R_2_5>(251u);
}
TEST(SecondOrderRandomRobot_2_5, FloatMatchesDouble) {
  float_matches_double<R_2_5>(252u);
}

// The analytical Hessian of lambda' ID, through the AD layer's SecondOrder provider, equals the
// nested-dual one (forward over forward through rnea: no code shared with the analytical sweeps)
// to rounding; the provider's FD Hessian is aba_second_order_derivatives'.
TEST(SecondOrderRandomRobot_2_5, ProviderMatchesNestedDualHessian) {
  using R = R_2_5;
  using ID = arbor::ad::InverseDynamics<R>;
  using FD = arbor::ad::ForwardDynamics<R>;
  using arbor::ad::AutoDiff;
  using arbor::ad::SecondOrder;
  constexpr int n = R::nv;
  auto ws = std::make_unique<arbor::ad::HessianWorkspace<ID, AutoDiff>>();
  auto ws2 = std::make_unique<arbor::ad::HessianWorkspace<ID, SecondOrder>>();
  auto d = std::make_unique<arbor::Data<R, double>>();
  auto dd = std::make_unique<arbor::DerivativeData<R, double>>();
  auto so = std::make_unique<arbor::SecondOrderData<R, double>>();
  std::mt19937 gen(253u);
  for (int trial = 0; trial < 3; ++trial) {
    const State<R> s = random_state<R>(gen);
    Vec<3 * n> x;
    x << s.q, s.v, s.a;
    Vec<n> yc, y;
    Mat<3 * n> Hc, H;
    {
      arbor::test::NoAllocScope guard;
      arbor::ad::contracted_hessian<AutoDiff>(arbor::ad::bind<ID>(*ws), x, s.lambda, yc, Hc);
      arbor::ad::contracted_hessian<SecondOrder>(arbor::ad::bind<ID>(*ws2), x, s.lambda, y, H);
    }
    ARBOR_EXPECT_REL(H, Hc, 1e-12);
    ARBOR_EXPECT_REL(y, yc, 1e-13);
    x << s.q, s.v, s.tau;
    {
      arbor::test::NoAllocScope guard;
      arbor::ad::contracted_hessian<SecondOrder>(arbor::ad::bind<FD>(*ws2), x, s.lambda, y, H);
      arbor::aba_second_order_derivatives<R>(*d, *dd, *so, s.q, s.v, s.tau, s.lambda);
    }
    EXPECT_TRUE(H == so->hessian);
    EXPECT_TRUE(y == d->ddq);
  }
}

}  // namespace
