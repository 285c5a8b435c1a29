// A tiny function for the hand-counted test of the AD generator (generated_count_test.cpp):
//   y0 = x0 * x1 + sin(x0),   y1 = x2 / x1.
// generated_tiny_adgen.cpp traces it with the generator's symbolic scalar and writes
// tiny_ad.hpp (GeneratedCode<TinyFunction>), the way arbor_add_robot_ad does for a robot.
#pragma once

#include <cmath>

namespace arbor::ad::test {

struct TinyFunction {
  static constexpr int nin = 3;
  static constexpr int nout = 2;
  template <class S>
  static void value(const S* x, S* y) {
    using std::sin;
    y[0] = x[0] * x[1] + sin(x[0]);
    y[1] = x[2] / x[1];
  }
};

/// The same function, its generated Jacobian emitted in parts of at most 2 operations (the
/// generator's chunking, gen/ad/adgen.hpp emit_function): the same operations, the same values.
struct TinyFunctionChunked : TinyFunction {};

}  // namespace arbor::ad::test
