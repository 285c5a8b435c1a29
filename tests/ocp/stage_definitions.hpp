// Problem definitions whose stages the test build generates (arbor_add_stage_ad,
// tests/ocp/CMakeLists.txt) for generated_stage_test.cpp: the contour example's OCP-FD (hard
// tunnel, the demo's problem; RK4 sensitivities exact unless CONTOUR_FROZEN_SENSITIVITY) and
// OCP-ID (hard general rows: inverse-dynamics torque bounds), and the end-effector task of the
// NMPC matrix on a random 3-joint robot with a soft tunnel (a slack), RK4 frozen: nx = 6,
// nu = 3 (+ 1 slack), N = 7.
#pragma once

#include "random_robot.hpp"
#include "random_task.hpp"
#include "stage_definition.hpp"

namespace ocp_test {

using Robot3 = arbor::test::RandomRobot<13, 3>;
using Task3 = nmpc_test::RandomTask<Robot3, Robot3::nb - 1, 7>;

/// Task3 with a soft tunnel, frozen RK4 sensitivities, analytical RBD derivatives.
struct RandomSoftStage {
  template <class T>
  using Workspace = Task3::Workspace<arbor::ad::Analytical, T, false>;
  template <class W>
  static auto problem(W& ws) {
    return Task3::problem<arbor::ad::Analytical, true, arbor::ocp::Sensitivity::frozen>(ws);
  }
};

}  // namespace ocp_test
