// Derivatives on random compile-time robots: finite differences (with and without external
// forces), identities, frame derivatives (float: file b).
#include "../dynamics/random_robot.hpp"
#include "derivative_checks.hpp"

namespace {
using namespace arbor::test::derivative_checks;

using R_4_14 = arbor::test::RandomRobot<4, 14>;
TEST(DerivativesRandomRobot_4_14, MatchFiniteDifferences) {
  matches_finite_differences<R_4_14>(414u);
}
TEST(DerivativesRandomRobot_4_14, FrameDerivativesMatchFiniteDifferences) {
  frame_derivatives_match_finite_differences<R_4_14>(414u + 1);
}

}  // namespace
