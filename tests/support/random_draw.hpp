// Random vectors drawn in one fixed order under every compiler. The arguments of a call are
// evaluated in an unspecified order: Eigen::Vector3d(u(gen), u(gen), u(gen)) drew z first under
// GCC for x86-64 and x first under Clang and under GCC for AArch64, so a seeded test saw other
// data with each compiler (and the QP benchmark another problem). draw3 draws z, then y, then x:
// the order GCC for x86-64 used, the data the tests' seeds and tolerances were chosen with.
#pragma once

#include <Eigen/Core>

namespace arbor::test {

/// (x, y, z) = three calls of draw, made in the order z, y, x.
template <class Draw>
Eigen::Vector3d draw3(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  const double x = draw();
  return Eigen::Vector3d(x, y, z);
}

}  // namespace arbor::test
