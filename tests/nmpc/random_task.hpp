// An end-effector task on any robot, for the size and instruction-set matrix of the NMPC tests
// (random_matrix_test.cpp): OCP-FD (x = [q, qd], u = tau, one RK4 step of aba per interval), the
// end effector (frame F) driven to a target position p_ref inside a hard convex tunnel (a ball
// around the segment from the start to the target: one convex row per stage, the contour
// example's constraint shape), torque bounds from the gravity torque at the start.
//   nx = 2 nv, nu = nv; for a 7-DoF robot and N = 20 this is the QP OcpQp<., 20, 14, 7, 1, 1> of
//   the -march=native crash of issue 35.
// Everything is generic over the robot, the controller scalar, the Hessian kind and the provider.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <type_traits>

#include "arbor/ad/expr.hpp"
#include "arbor/ad/rbd_functions.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"
#include "arbor/ocp/outer.hpp"
#include "arbor/ocp/problem.hpp"
#include "arbor/ocp/rk4.hpp"

namespace nmpc_test {

/// The task on robot R (end effector: frame F), horizon N, shooting interval h.
template <class R, int F, int N>
struct RandomTask {
  static constexpr int nv = R::nv;
  static constexpr int nx = 2 * nv;
  static constexpr int nu = nv;
  static constexpr double h = 0.02;
  using Fd = arbor::ad::ForwardDynamics<R>;
  using Ee = arbor::ad::FramePosition<R, F>;
  using D = arbor::ocp::Dims<nx, nu, 1, N>;

  /// Workspace of every RBD call at controller scalar T with provider Tag: values, Jacobians at
  /// T and, for the exact Hessian, Jacobians at the duals the controller differentiates with
  /// (path stages: nx + nu directions; terminal: nx).
  template <class Tag, class T, bool exact>
  using Workspace = std::conditional_t<
      exact,
      arbor::ad::MergedWorkspace<arbor::ad::ValueWorkspace<Fd, T>, arbor::ad::ValueWorkspace<Ee, T>,
                                 arbor::ad::JacobianWorkspace<Fd, Tag, T>,
                                 arbor::ad::JacobianWorkspace<Ee, Tag, T>,
                                 arbor::ad::JacobianWorkspace<Fd, Tag, arbor::ad::Dual<T, nx + nu>>,
                                 arbor::ad::JacobianWorkspace<Ee, Tag, arbor::ad::Dual<T, nx + nu>>,
                                 arbor::ad::JacobianWorkspace<Ee, Tag, arbor::ad::Dual<T, nx>>>,
      arbor::ad::MergedWorkspace<arbor::ad::ValueWorkspace<Fd, T>, arbor::ad::ValueWorkspace<Ee, T>,
                                 arbor::ad::JacobianWorkspace<Fd, Tag, T>,
                                 arbor::ad::JacobianWorkspace<Ee, Tag, T>>>;

  /// End-effector position at q (plain double, for the task's data and the checks).
  static Eigen::Vector3d ee(const Eigen::Matrix<double, nv, 1>& q) {
    static arbor::Data<R, double> d;  // test-only scratch (not library code)
    arbor::forward_kinematics<R>(d, q);
    arbor::update_frame_placements<R>(d);
    return d.oMf[F].p;
  }

  /// Start configuration, target configuration (deterministic from the robot).
  static Eigen::Matrix<double, nv, 1> q_start() {
    Eigen::Matrix<double, nv, 1> q;
    for (int i = 0; i < nv; ++i)
      q[i] = 0.3 * std::sin(1.7 * i + 0.4);
    return q;
  }
  static Eigen::Matrix<double, nv, 1> q_target() {
    Eigen::Matrix<double, nv, 1> q = q_start();
    for (int i = 0; i < nv; ++i)
      q[i] += 0.25 * std::cos(0.9 * i + 0.2);
    return q;
  }

  /// The problem; its RBD calls run on ws (caller-owned, outlives the problem and controller).
  /// Soft: the tunnel as an exact penalty (slack cost 1e3 s + 1e3 s^2), so that a measured state
  /// outside it still has a feasible QP. Sens: the RK4 node's sensitivities (ocp/rk4.hpp).
  template <class Tag, bool Soft = false,
            arbor::ocp::Sensitivity Sens = arbor::ocp::Sensitivity::exact, class W>
  static auto problem(W& ws) {
    namespace ad = arbor::ad;
    namespace ocp = arbor::ocp;
    const Eigen::Vector3d p0 = ee(q_start()), p1 = ee(q_target());
    const Eigen::Vector3d centre = 0.5 * (p0 + p1);
    const double rho = 0.6 * (p1 - p0).norm() + 0.02;
    const auto q = ad::segment<0, nv>(D::x);
    const auto v = ad::segment<nv, nv>(D::x);
    const auto ode = ad::cat(v, ad::call<Tag>(ad::bind<Fd>(ws), q, v, D::u));
    const auto pe = ad::call<Tag>(ad::bind<Ee>(ws), q);
    const auto tunnel = ocp::convex_constraint(pe - ad::constant(centre), ocp::Ball<3>{rho});
    const auto con = [&] {
      if constexpr (Soft)
        return ocp::soft(tunnel, 1e3, 1e3);
      else
        return tunnel;
    }();
    auto p = ocp::make_problem<D>(
        ocp::rk4<1, Sens>(ode, h),
        ocp::path_costs(ocp::least_squares(pe - ad::constant(p1), 100.0),
                        ocp::least_squares(v, 0.1), ocp::least_squares(D::u, 1e-3)),
        ocp::terminal_costs(ocp::least_squares(pe - ad::constant(p1), 1000.0),
                            ocp::least_squares(v, 1.0)),
        ocp::path_constraints(con));
    const double t = tau_max();
    p.lbu.fill(-t);
    p.ubu.fill(t);
    return p;
  }

  /// Torque bound: three times the largest gravity torque at the start, at least 1 N m.
  static double tau_max() {
    static arbor::Data<R, double> d;
    const Eigen::Matrix<double, nv, 1> z = Eigen::Matrix<double, nv, 1>::Zero();
    const auto g = arbor::rnea<R>(d, q_start(), z, z);
    return std::max(1.0, 3.0 * g.cwiseAbs().maxCoeff());
  }

  /// Tunnel centre and radius (the checks recompute the constraint).
  static double tunnel_excess(const Eigen::Matrix<double, nv, 1>& q) {
    const Eigen::Vector3d p0 = ee(q_start()), p1 = ee(q_target());
    const double rho = 0.6 * (p1 - p0).norm() + 0.02;
    return (ee(q) - 0.5 * (p0 + p1)).norm() - rho;
  }
};

}  // namespace nmpc_test
