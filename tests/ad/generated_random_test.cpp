// The Generated provider (gen/ad) on a random robot (generated_random_robot.hpp: branched tree,
// prismatic and unaligned joints, rotated frames): Jacobians of FD, ID and every frame position
// against central differences of the value and against the analytical routines, every call under
// the allocation guard.
#include <gtest/gtest.h>

#include <arbor/ad/rbd_functions.hpp>
#include <generated_random_robot_ad.hpp>
#include <memory>
#include <random>
#include <utility>

#include "../derivatives/derivative_checks.hpp"
#include "generated_random_robot.hpp"

namespace {

using namespace arbor;
using arbor::test::NoAllocScope;
using R = arbor::test::AdRandomRobot;
static_assert(arbor::test::has_every_joint_kind<R>() && arbor::test::is_branched<R>());

template <class F>
void generated_equals_fd_and_analytical(unsigned seed) {
  constexpr int n = F::nin, m = F::nout;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  VecN<double, n> x;
  for (int i = 0; i < n; ++i)
    x[i] = u(gen);
  VecN<double, m> yg, ya, y;
  Eigen::Matrix<double, m, n> Jg, Ja;
  auto wg = std::make_unique<ad::JacobianWorkspace<F, ad::Generated>>();
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical>>();
  auto wv = std::make_unique<ad::ValueWorkspace<F>>();
  {
    NoAllocScope guard;
    ad::bind<F>(*wg).template value_and_jacobian<ad::Generated>(x, yg, Jg);
    ad::bind<F>(*wa).template value_and_jacobian<ad::Analytical>(x, ya, Ja);
    ad::bind<F>(*wv).value(x, y);
  }
  ARBOR_EXPECT_REL(yg, y, 1e-12);
  ARBOR_EXPECT_REL(Jg, Ja, 1e-9);
  const Eigen::Matrix<double, m, n> Jfd =
      arbor::test::derivative_checks::central_diff<m, n>(x, [&](const VecN<double, n>& xx) {
        VecN<double, m> yy;
        ad::bind<F>(*wv).value(xx, yy);
        return yy;
      });
  ARBOR_EXPECT_REL(Jg, Jfd, arbor::test::derivative_checks::kFdTol);
}

// Every frame through a table of the generated functions: the checks compile once, not per frame.
template <int... f>
void frames(std::integer_sequence<int, f...>, unsigned seed) {
  constexpr int nv = R::nv;
  using Fn = void (*)(const double*, double*, double*);
  constexpr Fn generated[] = {
      &ad::GeneratedCode<ad::FramePosition<R, f>>::template jacobian<double>...};
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  VecN<double, nv> q;
  for (int i = 0; i < nv; ++i)
    q[i] = u(gen);
  auto d = std::make_unique<Data<R, double>>();
  auto dfd = std::make_unique<Data<R, double>>();
  for (int i = 0; i < R::nf; ++i) {
    Vec3<double> yg, ya;
    Eigen::Matrix<double, 3, nv> Jg, Ja;
    {
      NoAllocScope guard;
      generated[i](q.data(), yg.data(), Jg.data());
      compute_frame_position_derivative<R>(*d, q, i, Ja);
      ya = d->oMf[i].p;
    }
    ARBOR_EXPECT_REL(yg, ya, 1e-12) << "frame " << i;
    ARBOR_EXPECT_REL(Jg, Ja, 1e-9) << "frame " << i;
    const Eigen::Matrix<double, 3, nv> Jfd =
        arbor::test::derivative_checks::central_diff<3, nv>(q, [&](const VecN<double, nv>& qq) {
          forward_kinematics<R>(*dfd, qq);
          return Vec3<double>(frame_placement<R>(*dfd, i).p);
        });
    ARBOR_EXPECT_REL(Jg, Jfd, arbor::test::derivative_checks::kFdTol) << "frame " << i;
  }
}

}  // namespace

TEST(AdGeneratedRandomRobot, JacobiansEqualFiniteDifferencesAndAnalytical) {
  for (unsigned seed = 11; seed <= 13; ++seed) {
    generated_equals_fd_and_analytical<ad::ForwardDynamics<R>>(seed);
    generated_equals_fd_and_analytical<ad::InverseDynamics<R>>(seed);
    frames(std::make_integer_sequence<int, R::nf>{}, seed);
  }
}
