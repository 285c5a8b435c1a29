// Host program (built and run at build time by tests/ad/CMakeLists.txt): arbor-adgen (gen/ad) on
// the random robot of generated_random_robot.hpp, as arbor_add_robot_ad runs it on a URDF robot:
// argv[1] receives GeneratedCode specialisations of its FD, ID and frame-position Jacobians.
#include "adgen_robot.hpp"
#include "generated_random_robot.hpp"

int main(int argc, char** argv) {
  return arbor::adgen::generate<arbor::test::AdRandomRobot>(
      argc, argv, "arbor::test::AdRandomRobot", "generated_random_robot.hpp");
}
