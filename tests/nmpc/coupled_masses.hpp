// The coupled masses of tests/nmpc (lqr_test.cpp, inner_loop_test.cpp): a discretised
// mass-spring-damper with a second, coupled mass (nx = 4, nu = 2, N = 20) as an OCP written with
// the expression layer (linear_problem()), and the same numbers written out as LQR data for the
// plain Riccati recursion of support/lqr_reference.hpp (lqr_data()).
#pragma once

#include <Eigen/Dense>
#include <array>

#include "arbor/ad/expr.hpp"
#include "arbor/ocp/problem.hpp"
#include "lqr_reference.hpp"

namespace arbor::test::coupled_masses {

namespace ad = arbor::ad;
namespace ocp = arbor::ocp;

constexpr int N = 20;
constexpr double h = 0.1, k1 = 2.0, k2 = 1.0, c = 0.3;  // step, springs, damping
// x = [p1, p2, v1, v2], u = [f1, f2]; explicit Euler of two coupled masses (a linear map)
constexpr double A[4][4] = {{1, 0, h, 0},
                            {0, 1, 0, h},
                            {-h * (k1 + k2), h* k2, 1 - h* c, 0},
                            {h * k2, -h* k2, 0, 1 - h* c}};
constexpr double B[4][2] = {{0, 0}, {0, 0}, {h, 0}, {0, h}};
constexpr std::array<double, 4> wx{1.0, 2.0, 0.1, 0.1};  // stage weights (sum w x^2)
constexpr std::array<double, 2> wu{0.05, 0.02};
constexpr double wN = 5.0;

inline auto linear_problem() {
  using D = ocp::Dims<4, 2, 1, N>;
  const auto x = D::x;
  const auto u = D::u;
  auto row = [&](auto i) {
    constexpr int r = decltype(i)::value;
    return A[r][0] * ad::element<0>(x) + A[r][1] * ad::element<1>(x) + A[r][2] * ad::element<2>(x) +
           A[r][3] * ad::element<3>(x) + B[r][0] * ad::element<0>(u) + B[r][1] * ad::element<1>(u);
  };
  const auto F =
      ad::cat(row(std::integral_constant<int, 0>{}), row(std::integral_constant<int, 1>{}),
              row(std::integral_constant<int, 2>{}), row(std::integral_constant<int, 3>{}));
  return ocp::make_problem<D>(F,
                              ocp::path_costs(ocp::least_squares(x, wx), ocp::least_squares(u, wu)),
                              ocp::terminal_costs(ocp::least_squares(x, wN)));
}

inline arbor::test::LqrProblem lqr_data(const Eigen::Vector4d& x0) {
  arbor::test::LqrProblem p;
  p.N = N;
  Eigen::MatrixXd a(4, 4), b(4, 2);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j)
      a(i, j) = A[i][j];
    for (int j = 0; j < 2; ++j)
      b(i, j) = B[i][j];
  }
  p.A = {a};
  p.B = {b};
  // sum w_i x_i^2 = 1/2 x' (2 W) x
  p.Q = {Eigen::MatrixXd(2.0 * Eigen::Vector4d(wx[0], wx[1], wx[2], wx[3]).asDiagonal())};
  p.R = {Eigen::MatrixXd(2.0 * Eigen::Vector2d(wu[0], wu[1]).asDiagonal())};
  p.P_N = 2.0 * wN * Eigen::MatrixXd::Identity(4, 4);
  p.x0 = x0;
  return p;
}

}  // namespace arbor::test::coupled_masses
