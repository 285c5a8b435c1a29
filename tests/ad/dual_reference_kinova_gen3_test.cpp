// Dual<double, C> through rnea and aba of KinovaGen3: the reference values, the analytical
// derivatives and finite differences.
#include <robots/kinova_gen3.hpp>

#include "dual_checks.hpp"

namespace {
using arbor::test::dual_checks::Algo;
TEST(DualReference_KinovaGen3, RneaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::KinovaGen3,
                                                                  Algo::Rnea>("kinova_gen3", 1e-9,
                                                                              1e-6);
}
TEST(DualReference_KinovaGen3, AbaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::KinovaGen3,
                                                                  Algo::Aba>("kinova_gen3", 1e-9,
                                                                             1e-6);
}
}  // namespace
