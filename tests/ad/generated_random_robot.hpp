// The random robot whose generated AD code generated_random_test.cpp checks against finite
// differences: RandomRobot<7, 12> (tests/dynamics/random_robot.hpp), a branched tree with every
// joint kind (revolute and prismatic, aligned, signed and unaligned axes) and rotated frames.
// generated_random_adgen.cpp runs the AD generator (gen/ad) on it at build time.
#pragma once

#include "../dynamics/random_robot.hpp"

namespace arbor::test {
using AdRandomRobot = RandomRobot<7, 12>;
}  // namespace arbor::test
