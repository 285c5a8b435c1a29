// The cart-pole swing-up of the NMPC tests, written twice: with the expression layer (what the
// controller takes) and as plain double code (what IPOPT and the KKT checks take; it shares
// nothing with the library).
//   x = [p, theta, v, omega] (cart position, pole angle from hanging, their rates), u = force
//   p'' = (f + m_p s (l w^2 + g c)) / (m_c + m_p s^2)
//   theta'' = (-f c - m_p l w^2 c s - (m_c + m_p) g s) / (l (m_c + m_p s^2)),  s, c of theta
// (a point-mass pole on a massless rod, Tedrake's "Underactuated Robotics", ch. 3). Cost: weighted
// squares of x - [0, pi, 0, 0] and of f on the path, of x - [0, pi, 0, 0] at the end; bounds
// |f| <= f_max and |p| <= p_max (stages 1..N). M RK4 steps per interval h.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "arbor/ad/expr.hpp"
#include "arbor/ocp/problem.hpp"
#include "arbor/ocp/rk4.hpp"
#include "plain_ocp.hpp"
#include "problems.hpp"

namespace nmpc_test {

struct CartPoleData {
  static constexpr double mc = 1.0, mp = 0.3, l = 0.5, g = 9.81;  // cart, pole mass; length
  static constexpr double h = 0.05;                               // shooting interval
  static constexpr double f_max = 8.0;                            // |force| bound
  static constexpr double p_max = 0.6;                            // |cart position| bound
  static constexpr std::array<double, 4> wx{2.0, 2.0, 0.1, 0.1};  // path weights of x - up
  static constexpr double wu = 0.01;                              // path weight of f
};

/// The cart-pole swing-up OCP with N intervals and M RK4 steps per interval.
template <int N, int M = 2>
auto cartpole_problem(double w_terminal = 100.0) {
  using P = CartPoleData;
  using D = ocp::Dims<4, 1, 1, N>;
  const auto th = ad::element<1>(D::x);
  const auto om = ad::element<3>(D::x);
  const auto f = ad::element<0>(D::u);
  const auto s = ad::sin(th);
  const auto c = ad::cos(th);
  const auto den = P::mc + P::mp * s * s;
  const auto pdd = (f + P::mp * s * (P::l * om * om + P::g * c)) / den;
  const auto thdd =
      (-1.0 * f * c - (P::mp * P::l) * om * om * c * s - ((P::mc + P::mp) * P::g) * s) /
      (P::l * den);
  const auto ode = ad::cat(ad::element<2>(D::x), om, pdd, thdd);
  const Eigen::Vector4d up(0.0, M_PI, 0.0, 0.0);
  auto problem = ocp::make_problem<D>(
      ocp::rk4<M>(ode, P::h),
      ocp::path_costs(ocp::least_squares(D::x - ad::constant(up), P::wx),
                      ocp::least_squares(D::u, P::wu)),
      ocp::terminal_costs(ocp::least_squares(D::x - ad::constant(up), w_terminal)));
  problem.lbu.fill(-P::f_max);
  problem.ubu.fill(P::f_max);
  problem.lbx[0] = -P::p_max;
  problem.ubx[0] = P::p_max;
  return problem;
}

/// Plain cart-pole ODE.
inline Eigen::Vector4d cartpole_ode(const Eigen::Vector4d& x, double f) {
  using P = CartPoleData;
  const double s = std::sin(x[1]), c = std::cos(x[1]), w = x[3];
  const double den = P::mc + P::mp * s * s;
  return {x[2], w, (f + P::mp * s * (P::l * w * w + P::g * c)) / den,
          (-f * c - P::mp * P::l * w * w * c * s - (P::mc + P::mp) * P::g * s) / (P::l * den)};
}

/// The same OCP in plain code (plain_ocp.hpp), from x0.
inline PlainOcp plain_cartpole(int N, int M, double w_terminal, const Eigen::Vector4d& x0) {
  using P = CartPoleData;
  constexpr double inf = std::numeric_limits<double>::infinity();
  PlainOcp o;
  o.nx = 4;
  o.nu = 1;
  o.N = N;
  o.F = [M](const VecX& x, const VecX& u) {
    return VecX(rk4_plain([](const Eigen::Vector4d& y, double f) { return cartpole_ode(y, f); },
                          Eigen::Vector4d(x), u[0], P::h, M));
  };
  o.stage_cost = [](const VecX& x, const VecX& u) {
    const Eigen::Vector4d e = x - Eigen::Vector4d(0, M_PI, 0, 0);
    double c = P::wu * u[0] * u[0];
    for (int i = 0; i < 4; ++i)
      c += P::wx[std::size_t(i)] * e[i] * e[i];
    return c;
  };
  o.terminal_cost = [w_terminal](const VecX& x) {
    return w_terminal * (x - Eigen::Vector4d(0, M_PI, 0, 0)).squaredNorm();
  };
  o.lbx = VecX::Constant(4, -inf);
  o.ubx = VecX::Constant(4, inf);
  o.lbx[0] = -P::p_max;
  o.ubx[0] = P::p_max;
  o.lbu = VecX::Constant(1, -P::f_max);
  o.ubu = VecX::Constant(1, P::f_max);
  o.x0 = x0;
  return o;
}

}  // namespace nmpc_test
