// The Gauss-Newton products of ocp/linearize.hpp (add_gauss_newton_lower): scale J' grad^2 phi J
// added to the lower triangle, by rank-one updates over the nonzeros of J's rows within a row
// pattern for outer functions with a diagonal Hessian (WeightedSquares, Ball) and by H J
// otherwise, and the gradient J' g over the pattern (add_transposed_product), against the dense
// products written out as plain loops here, on sparse and dense random Jacobians, with a dense
// and a sparse pattern.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/ocp/linearize.hpp"

namespace {
namespace ocp = arbor::ocp;
template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

/// A test-only outer function with a full (non-diagonal) positive definite Hessian r' A r.
template <int M>
struct FullQuadratic {
  Mat<M> a;  ///< symmetric positive definite
  template <class T, int K>
  Mat<K> hessian(const Vec<K>&) const {
    return T(2) * a;
  }
};

/// sum_ij J_ia H_ij J_jb, plain loops.
template <int m, int n>
Mat<n> dense_product(const Eigen::Matrix<double, m, n>& J, const Mat<m>& H, double scale) {
  Mat<n> out;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      double s = 0;
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j)
          s += J(i, a) * H(i, j) * J(j, b);
      out(a, b) = scale * s;
    }
  return out;
}

/// Row patterns (ad::detail::RowPattern: the columns of each row that may be nonzero): every
/// column, or a sparse one (row i: the columns k with (k + i) % 3 != 0, and row 1 empty).
template <int m, int n>
constexpr auto dense_pattern() {
  std::array<std::array<bool, std::size_t(n)>, std::size_t(m)> d{};
  for (auto& row : d)
    for (auto& b : row)
      b = true;
  return arbor::ad::detail::row_pattern<m, n>(d);
}
template <int m, int n>
constexpr auto sparse_pattern() {
  std::array<std::array<bool, std::size_t(n)>, std::size_t(m)> d{};
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < n; ++k)
      d[std::size_t(i)][std::size_t(k)] = i != 1 && (k + i) % 3 != 0;
  return arbor::ad::detail::row_pattern<m, n>(d);
}

/// A random m x n Jacobian with about `fill` of the entries in the pattern nonzero (the others
/// zero).
template <auto Pat, int m, int n>
Eigen::Matrix<double, m, n> random_jacobian(std::mt19937& gen, double fill) {
  std::uniform_real_distribution<double> u(-2.0, 2.0), p(0.0, 1.0);
  Eigen::Matrix<double, m, n> J = Eigen::Matrix<double, m, n>::Zero();
  for (int i = 0; i < m; ++i)
    for (int a = 0; a < Pat.count[std::size_t(i)]; ++a)
      J(i, Pat.cols[std::size_t(i)][std::size_t(a)]) = p(gen) < fill ? u(gen) : 0.0;
  return J;
}

/// Two terms accumulated (scales 0.7 and 1.3) into a lower triangle whose strict upper triangle
/// holds a sentinel, then symmetrised; against the dense products of the same terms. And the
/// gradient over the pattern (add_transposed_product) against J' g.
template <class Phi, int m, int n, auto Pat>
void matches_dense(const Phi& phi, const Mat<m>& H, double fill, unsigned seed) {
  std::mt19937 gen(seed);
  const auto J1 = random_jacobian<Pat, m, n>(gen, fill);
  const auto J2 = random_jacobian<Pat, m, n>(gen, fill);
  const Vec<m> r = Vec<m>::Random();
  Mat<n> hess = Mat<n>::Zero();
  Vec<n> grad = Vec<n>::Constant(0.25);
  for (int b = 0; b < n; ++b)
    for (int a = 0; a < b; ++a)
      hess(a, b) = 12345.0;  // strict upper triangle: must stay untouched
  {
    arbor::test::NoAllocScope guard;
    ocp::detail::add_gauss_newton_lower<Pat, Phi, double, m, n>(hess, phi, r, J1, 0.7);
    ocp::detail::add_gauss_newton_lower<Pat, Phi, double, m, n>(hess, phi, r, J2, 1.3);
    ocp::detail::add_transposed_product<Pat, double, m, n>(grad, J1, r);
  }
  const Vec<n> grad_ref = Vec<n>::Constant(0.25) + J1.transpose() * r;
  for (int k = 0; k < n; ++k)
    EXPECT_NEAR(grad[k], grad_ref[k], 1e-13 * (1.0 + std::abs(grad_ref[k]))) << k;
  for (int b = 0; b < n; ++b)
    for (int a = 0; a < b; ++a)
      ASSERT_EQ(hess(a, b), 12345.0) << "upper (" << a << ", " << b << ") written";
  ocp::detail::symmetrize_lower<double, n>(hess);
  const Mat<n> ref = dense_product<m, n>(J1, H, 0.7) + dense_product<m, n>(J2, H, 1.3);
  const double tol = 1e-13 * (1.0 + ref.cwiseAbs().maxCoeff());
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      EXPECT_NEAR(hess(a, b), ref(a, b), tol) << "(" << a << ", " << b << ") fill " << fill;
}

TEST(GaussNewton, WeightedSquaresSparseAndDense) {
  static_assert(ocp::DiagonalHessian<ocp::WeightedSquares<5>, double, 5>);
  const ocp::WeightedSquares<5> phi{{1.0, 0.0, 2.5, 1e-3, 40.0}};  // a zero weight too
  Mat<5> H = Mat<5>::Zero();
  for (int i = 0; i < 5; ++i)
    H(i, i) = 2 * phi.w[std::size_t(i)];
  for (double fill : {0.0, 0.2, 0.5, 1.0}) {
    matches_dense<ocp::WeightedSquares<5>, 5, 9, dense_pattern<5, 9>()>(phi, H, fill, 11u);
    matches_dense<ocp::WeightedSquares<5>, 5, 9, sparse_pattern<5, 9>()>(phi, H, fill, 21u);
  }
}

TEST(GaussNewton, BallSparseAndDense) {
  static_assert(ocp::DiagonalHessian<ocp::Ball<3>, double, 3>);
  const ocp::Ball<3> phi{0.01};
  const Mat<3> H = 2 * Mat<3>::Identity();
  for (double fill : {0.3, 1.0}) {
    matches_dense<ocp::Ball<3>, 3, 24, dense_pattern<3, 24>()>(phi, H, fill, 12u);
    matches_dense<ocp::Ball<3>, 3, 24, sparse_pattern<3, 24>()>(phi, H, fill, 22u);
  }
}

TEST(GaussNewton, FullHessianTakesTheGeneralPath) {
  static_assert(!ocp::DiagonalHessian<FullQuadratic<4>, double, 4>);
  Eigen::Matrix<double, 4, 4> b = Eigen::Matrix<double, 4, 4>::Random();
  FullQuadratic<4> phi{b * b.transpose() + Mat<4>::Identity()};
  for (double fill : {0.4, 1.0}) {
    matches_dense<FullQuadratic<4>, 4, 7, dense_pattern<4, 7>()>(phi, 2 * phi.a, fill, 13u);
    matches_dense<FullQuadratic<4>, 4, 7, sparse_pattern<4, 7>()>(phi, 2 * phi.a, fill, 23u);
  }
}

}  // namespace
