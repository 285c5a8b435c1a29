// A run-time payload on the KinovaGen3's end_effector_link against the KinovaGen3 generated with the payload in its
// URDF (payload_checks.hpp), double and float.
#include <robots/kinova_gen3.hpp>
#include <robots/kinova_gen3_payload.hpp>

#include "payload_checks.hpp"

namespace {
using namespace arbor::test::payload_checks;
using Plain = arbor::robots::KinovaGen3;
using Merged = arbor::robots::KinovaGen3Payload;
constexpr int frame = Plain::frame_id::end_effector_link;

TEST(Payload_KinovaGen3, MatchesMergedModelDouble) {
  const Errors e = compare_with_merged<Plain, Merged, double>(frame);
  e.print("kinova_gen3", "double");
  EXPECT_LT(e.max(), 1e-11);
}

TEST(Payload_KinovaGen3, MatchesMergedModelFloat) {
  const Errors e = compare_with_merged<Plain, Merged, float>(frame);
  e.print("kinova_gen3", "float");
  EXPECT_LT(e.max(), 1e-3);
}

}  // namespace
