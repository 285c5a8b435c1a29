// Dual<double, C> through rnea and aba of DoublePendulum: the reference values, the analytical
// derivatives and finite differences.
#include <robots/double_pendulum.hpp>

#include "dual_checks.hpp"

namespace {
using arbor::test::dual_checks::Algo;
TEST(DualReference_DoublePendulum, RneaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::DoublePendulum,
                                                                  Algo::Rnea>("double_pendulum",
                                                                              1e-9, 1e-6);
}
TEST(DualReference_DoublePendulum, AbaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::DoublePendulum,
                                                                  Algo::Aba>("double_pendulum",
                                                                             1e-9, 1e-6);
}
}  // namespace
