// Random compile-time robots against the textbook implementation and identities; float on 2_5
// and 7_12 (file b).
#include "random_checks.hpp"

namespace {
using namespace arbor::test::random_checks;

using R_1_1 = arbor::test::RandomRobot<1, 1>;
static_assert(arbor::model::validate<R_1_1>());
TEST(RandomRobot_1_1, MatchesTextbook) {
  matches_textbook<R_1_1>();
}
TEST(RandomRobot_1_1, Identities) {
  identities<R_1_1>();
}

using R_2_5 = arbor::test::RandomRobot<2, 5>;
static_assert(arbor::model::validate<R_2_5>());
TEST(RandomRobot_2_5, MatchesTextbook) {
  matches_textbook<R_2_5>();
}
TEST(RandomRobot_2_5, Identities) {
  identities<R_2_5>();
}
TEST(RandomRobot_2_5, FloatMatchesDouble) {
  float_matches_double<R_2_5>();
}

using R_6_7 = arbor::test::RandomRobot<6, 7>;
static_assert(arbor::model::validate<R_6_7>());
TEST(RandomRobot_6_7, MatchesTextbook) {
  matches_textbook<R_6_7>();
}
TEST(RandomRobot_6_7, Identities) {
  identities<R_6_7>();
}

}  // namespace
