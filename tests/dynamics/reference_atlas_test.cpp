// Atlas against the Pinocchio reference values (rnea, gravity, nle, crba, aba, minv, every frame).
#include <robots/atlas.hpp>

#include "reference_checks.hpp"

namespace {
using R = arbor::robots::Atlas;
static_assert(arbor::Robot<R>);

TEST(Reference_Atlas, MatchesPinocchio) {
  arbor::test::check_reference<R>("atlas", 1e-8);
}
}  // namespace
