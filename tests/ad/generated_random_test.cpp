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
#include "provider_checks.hpp"

namespace {

using namespace arbor;
using arbor::test::NoAllocScope;
using R = arbor::test::AdRandomRobot;
namespace pc = arbor::test::provider_checks;
static_assert(arbor::test::has_every_joint_kind<R>() && arbor::test::is_branched<R>());

template <class F>
void generated_equals_fd_and_analytical(unsigned seed) {
  constexpr int n = F::nin, m = F::nout;
  std::mt19937 gen(seed);
  const VecN<double, n> x = pc::random_input<n>(gen);
  VecN<double, m> yg, ya;
  Eigen::Matrix<double, m, n> Jg, Ja;
  pc::value_and_jacobian<F, ad::Generated>(x, yg, Jg);
  pc::value_and_jacobian<F, ad::Analytical>(x, ya, Ja);
  ARBOR_EXPECT_REL(yg, pc::value<F>(x), 1e-12);
  ARBOR_EXPECT_REL(Jg, Ja, 1e-9);
  ARBOR_EXPECT_REL(Jg, pc::value_central_diff<F>(x), arbor::test::derivative_checks::kFdTol);
}

// Every frame through a table of the generated functions: the checks compile once, not per frame.
template <int... f>
void frames(std::integer_sequence<int, f...>, unsigned seed) {
  constexpr int nv = R::nv;
  using Fn = void (*)(const double*, double*, double*);
  constexpr Fn generated[] = {
      &ad::GeneratedCode<ad::FramePosition<R, f>>::template jacobian<double>...};
  std::mt19937 gen(seed);
  const VecN<double, nv> q = pc::random_input<nv>(gen);
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
