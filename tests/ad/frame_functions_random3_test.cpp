// The task-space function objects of ad/frame_functions.hpp on the random robot of 3 joints, in
// double and float (a unit of its own beside frame_functions_random_test.cpp: each random robot
// type costs GCC some 0.7 GB).
#include <gtest/gtest.h>

#include "../dynamics/random_robot.hpp"
#include "frame_functions_checks.hpp"

namespace {

using namespace arbor;
using namespace arbor::test::frame_checks;

using Rand3 = test::RandomRobot<11, 3>;

TEST(FrameFunctions, RandomRobot3) {
  check_all<Rand3, Rand3::nv - 1>(40);  // (frame nv: on the root)
}

}  // namespace
