// Random compile-time robots against the textbook implementation and identities (float: file b;
// the largest robot of the set, 20 joints in 5 trees).
#include "random_checks.hpp"

namespace {
using namespace arbor::test::random_checks;

using R_5_20 = arbor::test::RandomRobot<5, 20>;
static_assert(arbor::model::validate<R_5_20>());
TEST(RandomRobot_5_20, MatchesTextbook) {
  matches_textbook<R_5_20>();
}
TEST(RandomRobot_5_20, Identities) {
  identities<R_5_20>();
}

}  // namespace
