// Dual<double, C> through rnea of Atlas against the reference values (Pinocchio's analytical
// derivatives) and finite differences.
#include <robots/atlas.hpp>

#include "dual_checks.hpp"

namespace {
using arbor::test::dual_checks::Algo;
TEST(DualReference_Atlas, RneaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::Atlas, Algo::Rnea,
                                                                  false>("atlas", 1e-9, 1e-6);
}
}  // namespace
