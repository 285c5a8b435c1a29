// YumiNoGrippers derivatives against the reference values (drnea_dq, drnea_dv, daba_dq, daba_dv).
#include <robots/yumi_no_grippers.hpp>

#include "derivative_checks.hpp"

namespace {
TEST(DerivativesReference_YumiNoGrippers, MatchesReference) {
  arbor::test::derivative_checks::matches_reference<arbor::robots::YumiNoGrippers>(
      "yumi_no_grippers", 1e-9, 1e-9);
}
TEST(DerivativesReference_YumiNoGrippers, FrameDerivativesMatchFiniteDifferences) {
  arbor::test::derivative_checks::frame_derivatives_match_finite_differences<
      arbor::robots::YumiNoGrippers>(5u);
}
}  // namespace
