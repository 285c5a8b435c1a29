// Test helpers for ad/frame_functions.hpp (frame_functions_test.cpp,
// frame_functions_random_test.cpp): random inputs (a random reference rotation for the
// orientation errors), one provider's value and Jacobian at scalar T (workspace on the heap, the
// call under the allocation guard), and check_all: Analytical against AutoDiff and central
// differences in double, both providers in float against double.
#pragma once

#include <gtest/gtest.h>

#include <arbor/ad/frame_functions.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "../derivatives/derivative_checks.hpp"
#include "random_draw.hpp"

namespace arbor::test::frame_checks {

using arbor::test::NoAllocScope;
namespace dc = arbor::test::derivative_checks;

template <class F>
inline constexpr bool is_orientation = false;
template <class R, int Fr, class Form>
inline constexpr bool is_orientation<ad::FrameOrientationError<R, Fr, Form>> = true;

inline Eigen::Matrix3d rotation(const Eigen::Vector3d& axis, double angle) {
  const Eigen::Vector3d a = axis.normalized();
  Eigen::Matrix3d K;
  K << 0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0;
  return Eigen::Matrix3d::Identity() + std::sin(angle) * K + (1 - std::cos(angle)) * K * K;
}

/// A random input of F: joint values (and velocities) in [-1.2, 1.2], a random reference rotation.
template <class F>
VecN<double, F::nin> random_input(std::mt19937& gen) {
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  VecN<double, F::nin> x;
  for (int i = 0; i < F::nin; ++i)
    x[i] = u(gen);
  if constexpr (is_orientation<F>) {
    const double angle = 2.5 * u(gen);  // first: see random_draw.hpp
    const Eigen::Matrix3d Rr = rotation(arbor::test::draw3([&] { return u(gen); }), angle);
    for (int k = 0; k < 9; ++k)
      x[F::nv + k] = Rr(k % 3, k / 3);
  }
  return x;
}

/// y and J by provider Tag at scalar T (workspace on the heap, the call allocation-free).
template <class F, class Tag, class T>
void value_and_jacobian(const VecN<T, F::nin>& x, VecN<T, F::nout>& y,
                        Eigen::Matrix<T, F::nout, F::nin>& J) {
  auto w = std::make_unique<ad::JacobianWorkspace<F, Tag, T>>();
  y.setZero();
  J.setZero();
  NoAllocScope guard;
  ad::bind<F>(*w).template value_and_jacobian<Tag>(x, y, J);
}

/// F(x) at scalar T, allocation-free.
template <class F, class T = double>
VecN<T, F::nout> value(const VecN<T, F::nin>& x) {
  auto w = std::make_unique<ad::ValueWorkspace<F, T>>();
  VecN<T, F::nout> y = VecN<T, F::nout>::Zero();
  NoAllocScope guard;
  ad::bind<F>(*w).value(x, y);
  return y;
}

/// Analytical against AutoDiff and central differences (double), float against double, at
/// `trials` random inputs. Returns the largest relative deviation of Analytical from the
/// differences (printed by the caller).
template <class F>
double check(unsigned seed, bool with_float, int trials = 3) {
  constexpr int n = F::nin, m = F::nout;
  std::mt19937 gen(seed);
  double worst = 0;
  for (int t = 0; t < trials; ++t) {
    const VecN<double, n> x = random_input<F>(gen);
    VecN<double, m> ya, yc;
    Eigen::Matrix<double, m, n> Ja, Jc;
    value_and_jacobian<F, ad::Analytical, double>(x, ya, Ja);
    value_and_jacobian<F, ad::AutoDiff, double>(x, yc, Jc);
    const VecN<double, m> y = value<F>(x);
    ARBOR_EXPECT_REL(ya, y, 1e-13);
    ARBOR_EXPECT_REL(yc, y, 1e-13);
    ARBOR_EXPECT_REL(Ja, Jc, 1e-11);
    auto w = std::make_unique<ad::ValueWorkspace<F>>();
    const Eigen::Matrix<double, m, n> Jfd =
        dc::central_diff<m, n>(x, [&](const VecN<double, n>& xx) {
          VecN<double, m> yy;
          ad::bind<F>(*w).value(xx, yy);
          return yy;
        });
    ARBOR_EXPECT_REL(Ja, Jfd, dc::kFdTol);
    worst = std::max(worst,
                     (Ja - Jfd).cwiseAbs().maxCoeff() / std::max(1.0, Jfd.cwiseAbs().maxCoeff()));
    if (!with_float)
      continue;
    // float: both providers against the double Jacobian
    const VecN<float, n> xf = x.template cast<float>();
    VecN<float, m> yf;
    Eigen::Matrix<float, m, n> Jfa, Jfc;
    value_and_jacobian<F, ad::Analytical, float>(xf, yf, Jfa);
    ARBOR_EXPECT_REL(yf.template cast<double>(), y, 2e-5);
    ARBOR_EXPECT_REL(Jfa.template cast<double>(), Ja, 5e-5);
    value_and_jacobian<F, ad::AutoDiff, float>(xf, yf, Jfc);
    ARBOR_EXPECT_REL(Jfc.template cast<double>(), Ja, 5e-5);
    const VecN<double, m> yvf = value<F, float>(xf).template cast<double>();
    ARBOR_EXPECT_REL(yvf, y, 2e-5);
  }
  return worst;
}

/// Every function of frame Fr of robot R (float too when with_float: compile time).
template <class R, int Fr, bool with_float = true>
void check_all(unsigned seed) {
  const double e1 = check<ad::FramePose<R, Fr>>(seed, with_float);
  const double e2 = check<ad::FrameOrientationError<R, Fr, ad::LogMap>>(seed + 1, with_float);
  const double e3 = check<ad::FrameOrientationError<R, Fr, ad::CrossSum>>(seed + 2, with_float);
  const double e4 = check<ad::FrameVelocity<R, Fr>>(seed + 3, with_float);
  std::printf(
      "nv %2d frame %2d: Analytical - central differences, max rel.: pose %.1e, log %.1e, "
      "cross %.1e, velocity %.1e\n",
      R::nv, Fr, e1, e2, e3, e4);
}

}  // namespace arbor::test::frame_checks
