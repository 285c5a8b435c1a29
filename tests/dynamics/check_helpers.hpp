// Test helpers for the dynamics tests: comparisons with relative tolerances.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace arbor::test {

/// max |a - b| / max(1, max |b|): relative to the magnitude of the reference.
template <class A, class B>
double rel_err(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  const Eigen::MatrixXd ad = a.template cast<double>();
  const Eigen::MatrixXd bd = b.template cast<double>();
  const double scale = std::max(1.0, bd.cwiseAbs().maxCoeff());
  return (ad - bd).cwiseAbs().maxCoeff() / scale;
}

}  // namespace arbor::test

#define ARBOR_EXPECT_REL(a, b, tol) \
  EXPECT_LE(::arbor::test::rel_err((a), (b)), (tol)) << #a " vs " #b
