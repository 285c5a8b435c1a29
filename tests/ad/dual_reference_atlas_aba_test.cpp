// Dual<double, C> through aba of Atlas against the reference values (Pinocchio's analytical
// derivatives) and finite differences.
#include <robots/atlas.hpp>

#include "dual_checks.hpp"

namespace {
using arbor::test::dual_checks::Algo;
TEST(DualReference_Atlas, AbaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::Atlas, Algo::Aba,
                                                                  false>("atlas", 1e-8, 1e-6);
}
}  // namespace
