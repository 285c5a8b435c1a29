// Dual<double, C> through rnea and aba of Iiwa7: the reference values, the analytical
// derivatives and finite differences.
#include <robots/iiwa7.hpp>

#include "dual_checks.hpp"

namespace {
using arbor::test::dual_checks::Algo;
TEST(DualReference_Iiwa7, RneaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::Iiwa7, Algo::Rnea>(
      "iiwa7", 1e-9, 1e-6);
}
TEST(DualReference_Iiwa7, AbaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::Iiwa7, Algo::Aba>(
      "iiwa7", 1e-9, 1e-6);
}
}  // namespace
