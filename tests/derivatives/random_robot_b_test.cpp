// Derivatives on random compile-time robots: finite differences (with and without external
// forces), identities, frame derivatives, float against double (7_12).
#include "../dynamics/random_robot.hpp"
#include "derivative_checks.hpp"

namespace {
using namespace arbor::test::derivative_checks;

using R_3_9 = arbor::test::RandomRobot<3, 9>;
TEST(DerivativesRandomRobot_3_9, MatchFiniteDifferences) {
  matches_finite_differences<R_3_9>(39u);
}
TEST(DerivativesRandomRobot_3_9, FrameDerivativesMatchFiniteDifferences) {
  frame_derivatives_match_finite_differences<R_3_9>(39u + 1);
}

// Float: the float instantiations are the same templates as the double ones, so they run on two
// robots rather than seven (a compile-cost choice, issue 12): 2_5 (file a) and 7_12 (here), which
// has every joint kind and a branched forest (asserted below).
using R_7_12 = arbor::test::RandomRobot<7, 12>;
static_assert(arbor::test::has_every_joint_kind<R_7_12>() && arbor::test::is_branched<R_7_12>());
TEST(DerivativesRandomRobot_7_12, MatchFiniteDifferences) {
  matches_finite_differences<R_7_12>(712u);
}
TEST(DerivativesRandomRobot_7_12, FrameDerivativesMatchFiniteDifferences) {
  frame_derivatives_match_finite_differences<R_7_12>(712u + 1);
}
TEST(DerivativesRandomRobot_7_12, FloatMatchesDouble) {
  float_matches_double<R_7_12>(712u + 2);
}

}  // namespace
