// Random compile-time robots against the textbook implementation and identities (float: file b).
#include "random_checks.hpp"

namespace {
using namespace arbor::test::random_checks;

using R_4_14 = arbor::test::RandomRobot<4, 14>;
static_assert(arbor::model::validate<R_4_14>());
TEST(RandomRobot_4_14, MatchesTextbook) {
  matches_textbook<R_4_14>();
}
TEST(RandomRobot_4_14, Identities) {
  identities<R_4_14>();
}

}  // namespace
