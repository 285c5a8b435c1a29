// The 2-DoF arm of the NMPC tests (examples/robots/double_pendulum.urdf: two revolute joints about
// the x axis, motion in the y-z plane, q = 0 upright), written twice: with the expression layer
// and arbor's RBD function objects (what the controller takes, Jacobians from provider Tag), and
// as plain double code on the independent textbook RBD (support/textbook_rbd.hpp: aba and frame
// placements; what IPOPT and the KKT checks take).
//   x = [q1, q2, v1, v2], u = [tau1, tau2];  xdot = [v; aba(q, v, tau)]
//   end effector: the point L = 0.2 m along link2's z axis, p_ee = p_link2 + R_link2 [0, 0, L]
//                 (the joints turn about x, so R_link2 [0, 0, L] = L [0, -sin(q1+q2), cos(q1+q2)])
//   task: from hanging at rest (q = [pi, 0]) to q_ref = [pi/2, 0] (the arm horizontal), with
//         |tau_i| <= tau_max and a wall y_ee >= y_wall that q_ref violates (the tip ends pressed
//         against it, the elbow bent): torque bounds and the path constraint are both active.
// Cost: weighted squares of q - q_ref, v, tau on the path, of q - q_ref and v at the end.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>

#include <robots/double_pendulum.hpp>
#include "arbor/ad/expr.hpp"
#include "arbor/ad/rbd_functions.hpp"
#include "arbor/ocp/problem.hpp"
#include "arbor/ocp/rk4.hpp"
#include "plain_ocp.hpp"
#include "problems.hpp"
#include "textbook_rbd.hpp"

namespace nmpc_test {

struct ArmData {
  using Robot = arbor::robots::DoublePendulum;
  static constexpr int ee_frame = Robot::frame_id::link2;
  static constexpr double L = 0.2;                                  // tip offset along link2's z
  static constexpr double h = 0.05;                                 // shooting interval
  static constexpr double tau_max = 1.0;                            // |tau_i| bound
  static constexpr double y_wall = -0.22;                           // y_ee >= y_wall
  static constexpr std::array<double, 2> q_ref{M_PI / 2, 0.0};      // target configuration
  static constexpr std::array<double, 4> wx{10.0, 10.0, 0.1, 0.1};  // path weights of x - x_ref
  static constexpr std::array<double, 2> wu{0.1, 0.1};              // path weights of tau
};

using ArmFd = ad::ForwardDynamics<ArmData::Robot>;
using ArmEe = ad::FramePosition<ArmData::Robot, ArmData::ee_frame>;

/// The workspace of the arm's expressions with provider Tag: values at double, Jacobians at
/// double (SCQP), and, with exact Hessians, Jacobians at Dual<double, nx + nu>.
template <class Tag, bool exact>
using ArmWorkspace = std::conditional_t<
    exact,
    ad::MergedWorkspace<ad::ValueWorkspace<ArmFd>, ad::JacobianWorkspace<ArmFd, Tag>,
                        ad::JacobianWorkspace<ArmEe, Tag>,
                        ad::JacobianWorkspace<ArmFd, Tag, ad::Dual<double, 6>>,
                        ad::JacobianWorkspace<ArmEe, Tag, ad::Dual<double, 6>>>,
    ad::MergedWorkspace<ad::ValueWorkspace<ArmFd>, ad::JacobianWorkspace<ArmFd, Tag>,
                        ad::JacobianWorkspace<ArmEe, Tag>>>;

/// The arm OCP with N intervals, M RK4 steps, RBD Jacobians from provider Tag on workspace ws
/// (caller-owned; it must outlive the problem and the controller).
template <int N, int M, class Tag, class W>
auto arm_problem(W& ws, double w_terminal = 100.0) {
  using P = ArmData;
  using D = ocp::Dims<4, 2, 1, N>;
  const auto q = ad::segment<0, 2>(D::x);
  const auto v = ad::segment<2, 2>(D::x);
  const auto ode = ad::cat(v, ad::call<Tag>(ad::bind<ArmFd>(ws), q, v, D::u));
  const auto a = ad::element<0>(D::x) + ad::element<1>(D::x);
  const auto ee = ad::call<Tag>(ad::bind<ArmEe>(ws), q) +
                  ad::cat(ad::constant(0.0), (-P::L) * ad::sin(a), P::L * ad::cos(a));
  const Eigen::Vector4d x_ref(P::q_ref[0], P::q_ref[1], 0.0, 0.0);
  auto problem = ocp::make_problem<D>(
      ocp::rk4<M>(ode, P::h),
      ocp::path_costs(ocp::least_squares(D::x - ad::constant(x_ref), P::wx),
                      ocp::least_squares(D::u, P::wu)),
      ocp::terminal_costs(ocp::least_squares(D::x - ad::constant(x_ref), w_terminal)),
      ocp::path_constraints(ocp::constraint(ad::element<1>(ee), P::y_wall, ocp::inf)));
  problem.lbu.fill(-P::tau_max);
  problem.ubu.fill(P::tau_max);
  return problem;
}

/// Plain arm ODE on the textbook RBD model m.
inline Eigen::Vector4d arm_ode(const arbor::textbook::Model& m, const Eigen::Vector4d& x,
                               const Eigen::Vector2d& tau) {
  const VecX q = x.head<2>(), v = x.tail<2>(), t = tau;
  const VecX a = arbor::textbook::aba(m, q, v, t, Eigen::Vector3d(0, 0, -9.81));
  return {x[2], x[3], a[0], a[1]};
}

/// Plain end-effector position: link2's world placement (textbook FK) and the tip offset.
inline Eigen::Vector3d arm_ee(const arbor::textbook::Model& m, const Eigen::Vector2d& q) {
  const auto f = arbor::textbook::frame_placements(m, VecX(q));
  const auto& T = f[std::size_t(ArmData::ee_frame)];
  return T.p + T.R * Eigen::Vector3d(0, 0, ArmData::L);
}

/// The same OCP in plain code (plain_ocp.hpp), from x0.
inline PlainOcp plain_arm(int N, int M, double w_terminal, const Eigen::Vector4d& x0) {
  using P = ArmData;
  constexpr double inf = std::numeric_limits<double>::infinity();
  const auto model =
      std::make_shared<arbor::textbook::Model>(arbor::textbook::make_model<ArmData::Robot>());
  const Eigen::Vector4d x_ref(P::q_ref[0], P::q_ref[1], 0.0, 0.0);
  PlainOcp o;
  o.nx = 4;
  o.nu = 2;
  o.N = N;
  o.nc = 1;
  o.F = [M, model](const VecX& x, const VecX& u) {
    return VecX(rk4_plain(
        [&](const Eigen::Vector4d& y, const Eigen::Vector2d& t) { return arm_ode(*model, y, t); },
        Eigen::Vector4d(x), Eigen::Vector2d(u), P::h, M));
  };
  o.stage_cost = [x_ref](const VecX& x, const VecX& u) {
    double c = 0;
    for (int i = 0; i < 4; ++i)
      c += P::wx[std::size_t(i)] * (x[i] - x_ref[i]) * (x[i] - x_ref[i]);
    for (int i = 0; i < 2; ++i)
      c += P::wu[std::size_t(i)] * u[i] * u[i];
    return c;
  };
  o.terminal_cost = [x_ref, w_terminal](const VecX& x) {
    return w_terminal * (x - x_ref).squaredNorm();
  };
  o.path_constraint = [model](const VecX& x, const VecX&) {
    return VecX::Constant(1, arm_ee(*model, x.head<2>())[1]);
  };
  o.lc = VecX::Constant(1, P::y_wall);
  o.uc = VecX::Constant(1, inf);
  o.lbx = VecX::Constant(4, -inf);
  o.ubx = VecX::Constant(4, inf);
  o.lbu = VecX::Constant(2, -P::tau_max);
  o.ubu = VecX::Constant(2, P::tau_max);
  o.x0 = x0;
  return o;
}

}  // namespace nmpc_test
