// DoublePendulum derivatives against the reference values (drnea_dq, drnea_dv, daba_dq, daba_dv).
#include <robots/double_pendulum.hpp>

#include "derivative_checks.hpp"

namespace {
TEST(DerivativesReference_DoublePendulum, MatchesReference) {
  arbor::test::derivative_checks::matches_reference<arbor::robots::DoublePendulum>(
      "double_pendulum", 1e-9, 1e-9);
}
TEST(DerivativesReference_DoublePendulum, FrameDerivativesMatchFiniteDifferences) {
  arbor::test::derivative_checks::frame_derivatives_match_finite_differences<
      arbor::robots::DoublePendulum>(5u);
}
}  // namespace
