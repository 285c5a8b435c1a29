// Random compile-time robots against the textbook implementation, identities, float.
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
TEST(RandomRobot_3_9, FloatMatchesDouble) {
  float_matches_double<R_3_9>();
}

using R_7_12 = arbor::test::RandomRobot<7, 12>;
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
