// Two small user functions (arbor::ad::UserFunction) for generated_function_test.cpp, written as
// a user would: generic scalar code; their Jacobians are generated at build time
// (arbor_add_function_ad in tests/ad/CMakeLists.txt).
#pragma once

#include <arbor/core/math.hpp>

namespace arbor_test {

/// y0 = p0 x0 x1 + sin(x2), y1 = x0^2 / (p1 + x1^2) (p1 > 0).
struct TwoOutputs {
  static constexpr int nin = 3, nout = 2, nparam = 2;
  template <class S>
  static void eval(const S* x, const S* p, S* y) {
    y[0] = p[0] * x[0] * x[1] + arbor::sin(x[2]);
    y[1] = x[0] * x[0] / (p[1] + x[1] * x[1]);
  }
};

/// y = (x0 x1) p0 (the hand-counted case: 2 operations for the value, 2 for the Jacobian).
struct ScaledProduct {
  static constexpr int nin = 2, nout = 1, nparam = 1;
  template <class S>
  static void eval(const S* x, const S* p, S* y) {
    y[0] = x[0] * x[1] * p[0];
  }
};

/// y = sqrt(x0^2 + x1^2), no parameters.
struct Norm2 {
  static constexpr int nin = 2, nout = 1, nparam = 0;
  template <class S>
  static void eval(const S* x, const S*, S* y) {
    y[0] = arbor::sqrt(x[0] * x[0] + x[1] * x[1]);
  }
};

}  // namespace arbor_test
