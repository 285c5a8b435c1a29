// A run-time payload on the Iiwa7's iiwa_link_ee against the Iiwa7 generated with the payload in its
// URDF (payload_checks.hpp), double and float.
#include <robots/iiwa7.hpp>
#include <robots/iiwa7_payload.hpp>

#include "payload_checks.hpp"

namespace {
using namespace arbor::test::payload_checks;
using Plain = arbor::robots::Iiwa7;
using Merged = arbor::robots::Iiwa7Payload;
constexpr int frame = Plain::frame_id::iiwa_link_ee;

TEST(Payload_Iiwa7, MatchesMergedModelDouble) {
  const Errors e = compare_with_merged<Plain, Merged, double>(frame);
  e.print("iiwa7", "double");
  EXPECT_LT(e.max(), 1e-11);
}

TEST(Payload_Iiwa7, MatchesMergedModelFloat) {
  const Errors e = compare_with_merged<Plain, Merged, float>(frame);
  e.print("iiwa7", "float");
  EXPECT_LT(e.max(), 1e-3);
}

}  // namespace
