// The hosted tests' precompiled header (tests/CMakeLists.txt, ARBOR_TEST_PCH): the Eigen test
// configuration first (it must precede every Eigen include; without the precompiled header it is
// force-included instead), then GoogleTest, Eigen and the standard headers most tests use. Parsing
// these took ~3 s of every test unit's compile; loaded precompiled, ~1 s. Only headers whose
// content no test configures by a macro: a unit that defines such a macro (Eigen's stack limit) or
// compiles at -O0 (__OPTIMIZE__) is built without it (arbor_test_sources_without_pch).
#pragma once

#include "eigen_test_config.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>
