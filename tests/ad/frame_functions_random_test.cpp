// The task-space function objects of ad/frame_functions.hpp on the random robot of 13 joints
// (tests/dynamics/random_robot.hpp: branched trees, revolute and prismatic joints, rotated
// frames), at two frames: Analytical against AutoDiff and central differences in double (a unit of
// its own: compiler memory), and the frame velocity as the time derivative of the pose along qd.
#include <gtest/gtest.h>

#include "../dynamics/random_robot.hpp"
#include "frame_functions_checks.hpp"

namespace {

using namespace arbor;
using namespace arbor::test::frame_checks;

using Rand13 = test::RandomRobot<12, 13>;

TEST(FrameFunctions, RandomRobot13) {
  check_all<Rand13, Rand13::nv - 1, false>(50);  // (float: Kinova, Rand3; compiler memory)
}

/// The frame velocity is the time derivative of the pose along qd: v = d p(q + t qd)/dt,
/// [w]x = dR/dt R' (central differences in t).
TEST(FrameFunctions, VelocityIsPoseRate) {
  using R = Rand13;
  constexpr int f = R::nv - 1;
  constexpr int nv = R::nv;
  std::mt19937 gen(7);
  const auto x = random_input<ad::FrameVelocity<R, f>>(gen);
  const VecN<double, nv> q = x.head<nv>(), qd = x.tail<nv>();
  const double h = 1e-5;
  using P = ad::FramePose<R, f>;
  const auto yp = value<P>(VecN<double, nv>(q + h * qd)),
             ym = value<P>(VecN<double, nv>(q - h * qd));
  const auto y0 = value<P>(q);
  const VecN<double, 12> dy = (yp - ym) / (2 * h);
  Eigen::Matrix3d dR, R0;
  for (int k = 0; k < 9; ++k) {
    dR(k % 3, k / 3) = dy[3 + k];
    R0(k % 3, k / 3) = y0[3 + k];
  }
  const Eigen::Matrix3d W = dR * R0.transpose();
  const auto vel = value<ad::FrameVelocity<R, f>>(x);
  EXPECT_LT((vel.head<3>() - dy.head<3>()).norm(), 1e-8);
  EXPECT_LT((vel.tail<3>() - Eigen::Vector3d(W(2, 1), W(0, 2), W(1, 0))).norm(), 1e-8);
  EXPECT_LT((W + W.transpose()).norm(), 1e-8);
}

TEST(FrameFunctions, RandomRobot13MiddleFrame) {
  check_all<Rand13, Rand13::nv / 2, false>(60);
}

}  // namespace
