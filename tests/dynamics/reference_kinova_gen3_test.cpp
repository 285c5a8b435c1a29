// KinovaGen3 against the Pinocchio reference values (rnea, gravity, nle, crba, aba, minv, every
// frame).
#include <robots/kinova_gen3.hpp>

#include "reference_checks.hpp"

namespace {
using R = arbor::robots::KinovaGen3;
static_assert(arbor::Robot<R>);

TEST(Reference_KinovaGen3, MatchesPinocchio) {
  arbor::test::check_reference<R>("kinova_gen3", 1e-9);
}
}  // namespace
