// Iiwa7 against the Pinocchio reference values (rnea, gravity, nle, crba, aba, minv, every frame).
#include <robots/iiwa7.hpp>

#include "reference_checks.hpp"

namespace {
using R = arbor::robots::Iiwa7;
static_assert(arbor::Robot<R>);

TEST(Reference_Iiwa7, MatchesPinocchio) {
  arbor::test::check_reference<R>("iiwa7", 1e-9);
}
}  // namespace
