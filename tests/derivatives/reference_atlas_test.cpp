// Atlas derivatives against the reference values (drnea_dq, drnea_dv, daba_dq, daba_dv).
#include <robots/atlas.hpp>

#include "derivative_checks.hpp"

namespace {
TEST(DerivativesReference_Atlas, MatchesReference) {
  arbor::test::derivative_checks::matches_reference<arbor::robots::Atlas>("atlas", 1e-9, 1e-8);
}
TEST(DerivativesReference_Atlas, FrameDerivativesMatchFiniteDifferences) {
  arbor::test::derivative_checks::frame_derivatives_match_finite_differences<arbor::robots::Atlas>(
      5u);
}
}  // namespace
