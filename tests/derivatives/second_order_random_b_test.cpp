// Contracted second-order derivatives on random compile-time robots, part b (part a:
// second_order_random_test.cpp): a robot with two chains from the root, prismatic and unaligned
// joints, against finite differences of the first-order derivatives.
#include "../dynamics/random_robot.hpp"
#include "second_order_checks.hpp"

namespace {
using namespace arbor::test::second_order_checks;

using R_6_7 = arbor::test::RandomRobot<6, 7>;
TEST(SecondOrderRandomRobot_6_7, MatchFiniteDifferences) {
  matches_finite_differences<R_6_7>(671u);
}

}  // namespace
