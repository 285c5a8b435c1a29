// Derivatives on random compile-time robots: finite differences (with and without external
// forces), identities, frame derivatives; float against double on 2_5 and 7_12 (file b).
#include "../dynamics/random_robot.hpp"
#include "derivative_checks.hpp"

namespace {
using namespace arbor::test::derivative_checks;

using R_1_1 = arbor::test::RandomRobot<1, 1>;
TEST(DerivativesRandomRobot_1_1, MatchFiniteDifferences) {
  matches_finite_differences<R_1_1>(11u);
}
TEST(DerivativesRandomRobot_1_1, FrameDerivativesMatchFiniteDifferences) {
  frame_derivatives_match_finite_differences<R_1_1>(11u + 1);
}

using R_2_5 = arbor::test::RandomRobot<2, 5>;
TEST(DerivativesRandomRobot_2_5, MatchFiniteDifferences) {
  matches_finite_differences<R_2_5>(25u);
}
TEST(DerivativesRandomRobot_2_5, FrameDerivativesMatchFiniteDifferences) {
  frame_derivatives_match_finite_differences<R_2_5>(25u + 1);
}
TEST(DerivativesRandomRobot_2_5, FloatMatchesDouble) {
  float_matches_double<R_2_5>(25u + 2);
}

using R_6_7 = arbor::test::RandomRobot<6, 7>;
TEST(DerivativesRandomRobot_6_7, MatchFiniteDifferences) {
  matches_finite_differences<R_6_7>(67u);
}
TEST(DerivativesRandomRobot_6_7, FrameDerivativesMatchFiniteDifferences) {
  frame_derivatives_match_finite_differences<R_6_7>(67u + 1);
}

}  // namespace
