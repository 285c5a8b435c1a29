// libFuzzer target for the generator's front end: arbitrary bytes as URDF text through urdfdom,
// the tree builder and the emitter. Any GenError is an expected outcome; crashes, sanitizer
// reports and hangs are bugs. Run with scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <string>

#include "generator.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  arbor::gen::Options opt;
  opt.input = "fuzz.urdf";
  opt.output = "-";
  try {
    const arbor::gen::RobotDesc robot = arbor::gen::build_robot(text, opt, opt.input);
    const std::string header = arbor::gen::emit_header(robot, opt, {"fuzz.urdf", "0"});
    if (header.empty())
      __builtin_trap();
  } catch (const arbor::gen::GenError&) {
  }
  return 0;
}
