// Iiwa7 derivatives against the reference values (drnea_dq, drnea_dv, daba_dq, daba_dv).
#include <robots/iiwa7.hpp>

#include "derivative_checks.hpp"

namespace {
TEST(DerivativesReference_Iiwa7, MatchesReference) {
  arbor::test::derivative_checks::matches_reference<arbor::robots::Iiwa7>("iiwa7", 1e-9, 1e-9);
}
TEST(DerivativesReference_Iiwa7, FrameDerivativesMatchFiniteDifferences) {
  arbor::test::derivative_checks::frame_derivatives_match_finite_differences<arbor::robots::Iiwa7>(
      5u);
}
}  // namespace
