// KinovaGen3 derivatives against the reference values (drnea_dq, drnea_dv, daba_dq, daba_dv).
#include <robots/kinova_gen3.hpp>

#include "derivative_checks.hpp"

namespace {
TEST(DerivativesReference_KinovaGen3, MatchesReference) {
  arbor::test::derivative_checks::matches_reference<arbor::robots::KinovaGen3>("kinova_gen3", 1e-9,
                                                                               1e-9);
}
TEST(DerivativesReference_KinovaGen3, FrameDerivativesMatchFiniteDifferences) {
  arbor::test::derivative_checks::frame_derivatives_match_finite_differences<
      arbor::robots::KinovaGen3>(5u);
}
}  // namespace
