// Random compile-time robots against the textbook implementation, identities, float (7_12).
#include "random_checks.hpp"

namespace {
using namespace arbor::test::random_checks;

using R_3_9 = arbor::test::RandomRobot<3, 9>;
static_assert(arbor::model::validate<R_3_9>());
TEST(RandomRobot_3_9, MatchesTextbook) {
  matches_textbook<R_3_9>();
}
TEST(RandomRobot_3_9, Identities) {
  identities<R_3_9>();
}

// Float: the float instantiations are the same templates as the double ones, so they run on two
// robots rather than seven (a compile-cost choice, issue 12): 2_5 (file a) and 7_12 (here), which
// has every joint kind and a branched forest (asserted below).
using R_7_12 = arbor::test::RandomRobot<7, 12>;
static_assert(arbor::test::has_every_joint_kind<R_7_12>() && arbor::test::is_branched<R_7_12>());
static_assert(arbor::model::validate<R_7_12>());
TEST(RandomRobot_7_12, MatchesTextbook) {
  matches_textbook<R_7_12>();
}
TEST(RandomRobot_7_12, Identities) {
  identities<R_7_12>();
}
TEST(RandomRobot_7_12, FloatMatchesDouble) {
  float_matches_double<R_7_12>();
}

}  // namespace
