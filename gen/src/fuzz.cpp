// libFuzzer target for the generator's front end: arbitrary bytes as URDF text through urdfdom,
// the tree builder, the emitter and the summary. The first byte, when the input is long enough,
// picks the options (--lock-mimic, --strict-inertia or --fix-inertia, --snap with one of four
// tolerances, --summary), so that every policy path is fuzzed too. Any GenError is an expected
// outcome; crashes, sanitizer reports and hangs are bugs. Run with scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <string>

#include "generator.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  arbor::gen::Options opt;
  opt.input = "fuzz.urdf";
  opt.output = "-";
  // A URDF starts with '<' or whitespace: other first bytes are option bits, then dropped.
  if (size > 1 && data[0] != '<' && data[0] != ' ' && data[0] != '\n' && data[0] != '\t') {
    const std::uint8_t bits = data[0];
    constexpr double kTolerances[] = {1e-9, 1e-6, 1e-5, 0.05};
    opt.lock_mimic = bits & 1;
    opt.strict_inertia = (bits & 6) == 2;
    opt.fix_inertia = (bits & 6) == 4;
    if (bits & 8)
      opt.snap = kTolerances[(bits >> 4) & 3];
    opt.summary = bits & 64;
    ++data;
    --size;
  }
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const arbor::gen::RobotDesc robot = arbor::gen::build_robot(text, opt, opt.input);
    const std::string header = arbor::gen::emit_header(robot, opt, {"fuzz.urdf", "0"});
    if (header.empty())
      __builtin_trap();
    if (opt.summary && arbor::gen::summary_text(robot, opt, {"fuzz.urdf", "0"}).empty())
      __builtin_trap();
  } catch (const arbor::gen::GenError&) {
  }
  return 0;
}
