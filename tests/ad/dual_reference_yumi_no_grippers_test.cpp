// Dual<double, C> through rnea and aba of YumiNoGrippers: the reference values, the analytical
// derivatives and finite differences.
#include <robots/yumi_no_grippers.hpp>

#include "dual_checks.hpp"

namespace {
using arbor::test::dual_checks::Algo;
TEST(DualReference_YumiNoGrippers, RneaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::YumiNoGrippers,
                                                                  Algo::Rnea>("yumi_no_grippers",
                                                                              1e-9, 1e-6);
}
TEST(DualReference_YumiNoGrippers, AbaJacobian) {
  arbor::test::dual_checks::dual_matches_reference_and_analytical<arbor::robots::YumiNoGrippers,
                                                                  Algo::Aba>("yumi_no_grippers",
                                                                             1e-9, 1e-6);
}
}  // namespace
