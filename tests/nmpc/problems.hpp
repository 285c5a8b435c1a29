// The small OCPs of the NMPC tests, each written twice: once with the expression layer (what the
// controller takes) and once as plain double code (what the independent references, IPOPT and
// the KKT checks of the tests, take). The plain versions share nothing with the library.
//   pendulum   x = [theta, omega], u = torque; swing-up from hanging (theta = 0) to upright
//   cart-pole  x = [pos, angle, vel, angvel], u = force; swing-up, cart position and force bounded
// Dynamics: one explicit RK4 step (M steps) per shooting interval h.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <numbers>

#include "arbor/ad/expr.hpp"
#include "arbor/ocp/problem.hpp"
#include "arbor/ocp/rk4.hpp"

namespace nmpc_test {
namespace ad = arbor::ad;
namespace ocp = arbor::ocp;

// ---- pendulum ---------------------------------------------------------------------------------
struct PendulumData {
  static constexpr double g = 9.81, l = 1.0, m = 1.0, b = 0.1;  // gravity, length, mass, damping
  static constexpr double h = 0.05;                             // shooting interval
  static constexpr double u_max = 3.0;                          // |torque| bound
};

/// The pendulum swing-up OCP with N intervals and M RK4 steps per interval.
template <int N, int M = 2>
auto pendulum_problem(double w_terminal = 100.0) {
  using P = PendulumData;
  using D = ocp::Dims<2, 1, 1, N>;
  const auto th = ad::element<0>(D::x);
  const auto om = ad::element<1>(D::x);
  const auto tau = ad::element<0>(D::u);
  const auto ode =
      ad::cat(om, -(P::g / P::l) * ad::sin(th) - P::b * om + (1.0 / (P::m * P::l * P::l)) * tau);
  const Eigen::Vector2d up(std::numbers::pi, 0.0);
  auto problem = ocp::make_problem<D>(
      ocp::rk4<M>(ode, P::h),
      ocp::path_costs(ocp::least_squares(D::x - ad::constant(up), std::array<double, 2>{1.0, 0.1}),
                      ocp::least_squares(D::u, 0.01)),
      ocp::terminal_costs(ocp::least_squares(D::x - ad::constant(up), w_terminal)));
  problem.lbu.fill(-P::u_max);
  problem.ubu.fill(P::u_max);
  return problem;
}

/// Plain pendulum ODE.
inline Eigen::Vector2d pendulum_ode(const Eigen::Vector2d& x, double u) {
  using P = PendulumData;
  return {x[1], -(P::g / P::l) * std::sin(x[0]) - P::b * x[1] + u / (P::m * P::l * P::l)};
}

/// Plain RK4 of an ODE f(x, u) over h with M steps.
template <class X, class U, class F>
X rk4_plain(const F& f, const X& x, const U& u, double h, int M) {
  X y = x;
  const double d = h / M;
  for (int i = 0; i < M; ++i) {
    const X k1 = f(y, u), k2 = f(X(y + 0.5 * d * k1), u), k3 = f(X(y + 0.5 * d * k2), u),
            k4 = f(X(y + d * k3), u);
    y = y + d / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return y;
}

}  // namespace nmpc_test
