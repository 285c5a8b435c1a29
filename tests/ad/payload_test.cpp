// The AD layer's RBD function objects with a payload set on their workspace (ad::set_payload) on
// the Kinova Gen3, against the Kinova generated with the payload in its URDF (no payload set):
// values and Jacobians of ForwardDynamics and InverseDynamics under Analytical, AutoDiff and
// Generated (which, with a payload set, runs the analytical routines of the workspace), and the
// contracted Hessians under SecondOrder and Generated (on a SecondOrderWorkspace: the same
// fallback). Double, under the allocation guard.
#include <gtest/gtest.h>

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <memory>
#include <random>
#include <robots/kinova_gen3.hpp>
#include <robots/kinova_gen3_ad.hpp>
#include <robots/kinova_gen3_ad_hessian.hpp>
#include <robots/kinova_gen3_payload.hpp>

#include "alloc_guard.hpp"
#include "payload_checks.hpp"

namespace {

using namespace arbor;
namespace pl = arbor::test::payload_checks;
using Plain = arbor::robots::KinovaGen3;
using Merged = arbor::robots::KinovaGen3Payload;
constexpr int frame = Plain::frame_id::end_effector_link;

template <template <class> class Fn>
void jacobians_with_payload() {
  using F = Fn<Plain>;
  using G = Fn<Merged>;
  constexpr int n = F::nin, m = F::nout;
  using X = VecN<double, n>;
  using Y = VecN<double, m>;
  using J = Eigen::Matrix<double, m, n>;
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical>>();
  auto wd = std::make_unique<ad::JacobianWorkspace<F, ad::AutoDiff>>();
  auto wm = std::make_unique<ad::JacobianWorkspace<G, ad::Analytical>>();
  const pl::Spec sp = pl::urdf_payload();
  ASSERT_TRUE(ad::set_payload(*wa, frame, sp.mass, sp.com, sp.Ic));
  ASSERT_TRUE(ad::set_payload(*wd, frame, sp.mass, sp.com, sp.Ic));
  const auto fa = ad::bind<F>(*wa);
  const auto fd = ad::bind<F>(*wd);
  const auto gm = ad::bind<G>(*wm);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double err = 0, effect = 0;
  for (int s = 0; s < 4; ++s) {
    X x;
    for (int k = 0; k < n; ++k)
      x[k] = u(rng);
    Y y_ref, y_a, y_d, y_g, y_v;
    J J_ref, J_a, J_d, J_g;
    gm.template value_and_jacobian<ad::Analytical>(x, y_ref, J_ref);
    {
      arbor::test::NoAllocScope guard;
      fa.template value_and_jacobian<ad::Analytical>(x, y_a, J_a);
      fd.template value_and_jacobian<ad::AutoDiff>(x, y_d, J_d);
      fa.template value_and_jacobian<ad::Generated>(x, y_g, J_g);
      fa.value(x, y_v);
    }
    err = std::max({err, pl::rel_err(y_a, y_ref), pl::rel_err(J_a, J_ref), pl::rel_err(y_d, y_ref),
                    pl::rel_err(J_d, J_ref), pl::rel_err(y_g, y_ref), pl::rel_err(J_g, J_ref),
                    pl::rel_err(y_v, y_ref)});
    // without the payload, Generated is the generated code again (the plain robot)
    ad::clear_payload(*wa);
    Y y_plain;
    J J_plain;
    fa.template value_and_jacobian<ad::Generated>(x, y_plain, J_plain);
    effect = std::max(effect, pl::rel_err(y_plain, y_ref));
    ASSERT_TRUE(ad::set_payload(*wa, frame, sp.mass, sp.com, sp.Ic));
  }
  std::printf(
      "payload AD %s kinova_gen3 double: Analytical/AutoDiff/Generated %.2e (effect %.2e)\n",
      std::is_same_v<F, ad::ForwardDynamics<Plain>> ? "FD" : "ID", err, effect);
  EXPECT_LT(err, 1e-11);
  EXPECT_GT(effect, 1e-3);
}

TEST(PayloadAd, ForwardDynamicsJacobians) {
  jacobians_with_payload<ad::ForwardDynamics>();
}
TEST(PayloadAd, InverseDynamicsJacobians) {
  jacobians_with_payload<ad::InverseDynamics>();
}

template <template <class> class Fn>
void hessians_with_payload() {
  using F = Fn<Plain>;
  using G = Fn<Merged>;
  constexpr int n = F::nin, m = F::nout;
  using X = VecN<double, n>;
  using Y = VecN<double, m>;
  using H = Eigen::Matrix<double, n, n>;
  auto ws = std::make_unique<ad::SecondOrderWorkspace<Plain, double>>();
  auto wm = std::make_unique<ad::SecondOrderWorkspace<Merged, double>>();
  const pl::Spec sp = pl::urdf_payload();
  ASSERT_TRUE(ad::set_payload(*ws, frame, sp.mass, sp.com, sp.Ic));
  const auto f = ad::bind<F>(*ws);
  const auto g = ad::bind<G>(*wm);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double err = 0;
  for (int s = 0; s < 3; ++s) {
    X x;
    Y lam;
    for (int k = 0; k < n; ++k)
      x[k] = u(rng);
    for (int k = 0; k < m; ++k)
      lam[k] = u(rng);
    Y y_ref, y_s, y_g;
    H H_ref, H_s, H_g;
    ad::contracted_hessian<ad::SecondOrder>(g, x, lam, y_ref, H_ref);
    {
      arbor::test::NoAllocScope guard;
      ad::contracted_hessian<ad::SecondOrder>(f, x, lam, y_s, H_s);
      ad::contracted_hessian<ad::Generated>(f, x, lam, y_g, H_g);
    }
    err = std::max({err, pl::rel_err(y_s, y_ref), pl::rel_err(H_s, H_ref), pl::rel_err(y_g, y_ref),
                    pl::rel_err(H_g, H_ref)});
  }
  std::printf("payload AD Hessian %s kinova_gen3 double: SecondOrder/Generated %.2e\n",
              std::is_same_v<F, ad::ForwardDynamics<Plain>> ? "FD" : "ID", err);
  EXPECT_LT(err, 1e-10);
}

TEST(PayloadAd, ForwardDynamicsHessians) {
  hessians_with_payload<ad::ForwardDynamics>();
}
TEST(PayloadAd, InverseDynamicsHessians) {
  hessians_with_payload<ad::InverseDynamics>();
}

}  // namespace
