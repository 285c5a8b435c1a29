// docs/tutorial.md, compiled and run: its code (extracted at configure time into
// tutorial_code.hpp) drives the iiwa7 through three targets with the tool held vertical, in
// real-time iteration on arbor's own forward dynamics. Checked: every sample's status is
// step_taken; the tool tip ends each target's 2 s within 5 mm of it and the tool axis within
// 0.01 rad of vertical, and the axis stays within 0.1 rad while moving between targets; torques, joint speeds and positions
// within the URDF's limits; the loop allocation-free.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "alloc_guard.hpp"
#include "tutorial_code.hpp"

namespace {

TEST(Tutorial, IiwaReachesTargetsWithToolVertical) {
  using namespace tutorial;
  using Pose = ad::FramePose<Robot, ee>;
  static ad::ValueWorkspace<Pose> ws;
  int samples = 0, steps = 0;
  double tip_end[3] = {}, tilt_end[3] = {}, max_axis = 0, max_torque = 0, max_speed = 0,
         max_position = 0;
  nmpc::NmpcStatus first_failure = nmpc::NmpcStatus::step_taken;
  {
    arbor::test::NoAllocScope guard;
    run([&](int t, const Vx& x, const Eigen::Matrix<double, n, 1>& tau, nmpc::NmpcStatus st) {
      ++samples;
      if (st == nmpc::NmpcStatus::step_taken)
        ++steps;
      else if (first_failure == nmpc::NmpcStatus::step_taken)
        first_failure = st;
      Eigen::Matrix<double, 12, 1> pose;
      ad::bind<Pose>(ws).value(Eigen::Matrix<double, n, 1>(x.head<n>()), pose);
      tip_end[t] = (pose.head<3>() - targets[t]).norm();
      const double axis = std::acos(std::min(1.0, -pose[11]));  // tool z against -world z
      tilt_end[t] = axis;
      if (samples > 40)
        max_axis = std::max(max_axis, axis);
      for (int j = 0; j < n; ++j) {
        const auto& l = Robot::limits[std::size_t(j)];
        max_torque = std::max(max_torque, std::abs(tau[j]) / l.effort);
        max_speed = std::max(max_speed, std::abs(x[n + j]) / l.velocity);
        max_position = std::max(max_position, std::abs(x[j]) / l.upper);
      }
    });
  }
  std::printf(
      "samples %d, step_taken %d; tip error at the end of each target %.2e %.2e %.2e m; "
      "tool tilt there %.1e %.1e %.1e rad, max %.2e rad; max |tau|, |qd|, |q| / limit: %.3f %.3f "
      "%.3f\n",
      samples, steps, tip_end[0], tip_end[1], tip_end[2], tilt_end[0], tilt_end[1], tilt_end[2],
      max_axis, max_torque, max_speed, max_position);
  EXPECT_EQ(samples, 120);
  EXPECT_EQ(steps, samples) << "first failure: " << nmpc::to_string(first_failure);
  for (int t = 0; t < 3; ++t) {
    EXPECT_LT(tip_end[t], 5e-3);
    EXPECT_LT(tilt_end[t], 0.01);
  }
  EXPECT_LT(max_axis, 0.1);
  EXPECT_LE(max_torque, 1.0 + 1e-9);
  EXPECT_LE(max_speed, 1.0);
  EXPECT_LE(max_position, 1.0);
}

}  // namespace
