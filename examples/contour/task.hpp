// The contour-following task of the paper (section 5.2) on the Kinova Gen3, as specified in
// ../shared/CONTOUR.md (from the authors' task code): the end effector follows a 3-D contour
// p_ref(s) with its initial orientation held, while a path parameter s advances at a reference
// speed sd_ref(s); the position error stays in a tunnel |e_p| <= rho.
//
//   x = [q (7), qd (7), s, sd]   (nx = 16)
//   OCP-FD: u = [tau (7), sdd]   x+ = one RK4 step over h of [qd, FD(q, qd, tau), sd, sdd]
//   OCP-ID: u = [qdd (7), sdd]   x+ = exact double integrator; tau = ID(q, qd, qdd) within limits
//
// Everything here is generic over the RBD derivative provider Tag (ad::Analytical or
// ad::AutoDiff, for every RBD call node of the OCP; or ad::Generated, gen/ad's code-generated AD,
// for FD, ID and the tunnel's position, the pose, which has no generated code, falling back to
// AutoDiff: ad::ProviderOf) and over the controller's scalar. The RBD calls (ad::FramePose,
// ad::FramePosition, FD, ID) run on a caller-owned workspace (Workspace<Tag, T>, an
// nmpc::Workspace; static storage) whose PoseCache lets the tunnel's FramePosition reuse the
// stage cost's pose Jacobian at the same q. Generated needs <robots/kinova_gen3_ad.hpp> (CMake
// target arbor_robot_kinova_gen3_ad) included before this header.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <type_traits>

#include <robots/kinova_gen3.hpp>
#include "arbor/ad/expr.hpp"
#include "arbor/ad/frame_functions.hpp"
#include "arbor/ad/rbd_functions.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/nmpc/workspace.hpp"
#include "arbor/ocp/problem.hpp"
#include "arbor/ocp/rk4.hpp"

namespace contour {

namespace ad = arbor::ad;
namespace ocp = arbor::ocp;
using arbor::MatN;
using arbor::VecN;

using Robot = arbor::robots::KinovaGen3;
constexpr int ee_frame = Robot::frame_id::end_effector_link;
constexpr int nq = 7;        // joints
constexpr int nx = 16;       // [q, qd, s, sd]
constexpr int nu = 8;        // [tau or qdd, sdd]
constexpr int horizon = 16;  // N
constexpr double h = 0.02;   // shooting interval t_mpc [s]
constexpr double pi = std::numbers::pi;
constexpr double inf = std::numeric_limits<double>::infinity();

// ---- limits (the task code's model file, CONTOUR.md) --------------------------------------------
constexpr std::array<double, nq> tau_max{39, 39, 39, 39, 9, 9, 9};              // |tau| [N m]
constexpr double qd_max = 0.8727;                                               // |qd| [rad/s]
constexpr std::array<double, nq> q_max{inf, 2.2, inf, 2.5656, inf, 2.05, inf};  // |q| [rad]
constexpr double qdd_max = 240.0 * pi / 180.0;  // |qdd| (OCP-ID) [rad/s^2]
constexpr double rho = 0.01;                    // tunnel radius [m]
/// The controller's default tunnel back-off [m] (options.hpp's Options::backoff < 0): 1 mm, the
/// margin for the disturbances the plant meets in mid-task (a payload picked up or released, a
/// push, noise, a delay: README.md, "Disturbances in the middle of the task"; with 0.5 mm the
/// plant leaves rho + 1 mm when they come together), which also covers the linearisation error of
/// real-time iteration (0.1 mm) and float's looser QP tolerance (0.3 mm; README.md, "Float").
template <class Scalar>
constexpr double default_backoff = 1e-3;
/// Initial configuration q0 (qd0 = 0, s0 = sd0 = 0).
inline Eigen::Matrix<double, nq, 1> initial_q() {
  Eigen::Matrix<double, nq, 1> q;
  q << 0, pi / 6, 0, 2 * pi / 3, 0, -pi / 3, -pi / 2;
  return q;
}

enum class Formulation { fd, id };
constexpr const char* to_string(Formulation f) {
  return f == Formulation::fd ? "OCP-FD" : "OCP-ID";
}

// ---- reference path -----------------------------------------------------------------------------
/// The reference: p0, R0 (end-effector pose at q0) and the progress-speed scale c, as numbers of
/// type P (double; a symbolic scalar when the tracking residual's code is generated with the
/// reference as run-time parameters, bench/ad/fn_counts.cpp).
template <class P = double>
struct ReferenceT {
  std::array<P, 3> p0{};  ///< initial end-effector position [m]
  std::array<P, 9> R0{};  ///< initial end-effector rotation, column-major
  P c = P(0.2);           ///< sd_ref scale (the task code's two versions: 0.025, 0.2)
};
using Reference = ReferenceT<double>;

/// sd_ref(s) = c * (5.777783e-13 s^5 - 34.6153846154 s^4 + 69.2307692308 s^3
///                  - 46.7307692308 s^2 + 12.1153846154 s + 0.0515384615).
template <class S, class C>
S sd_ref(const C& c, const S& s) {
  S poly = S(5.777783e-13) * s + S(-34.6153846154);
  poly = poly * s + S(69.2307692308);
  poly = poly * s + S(-46.7307692308);
  poly = poly * s + S(12.1153846154);
  poly = poly * s + S(0.0515384615);
  return S(c) * poly;
}

/// p_ref(s) = p0 + [0.05 sin(4 pi s), 0.15 sin(2 pi s), 0.15 sin(2 pi s) cos(2 pi s)].
template <class S, class P>
VecN<S, 3> p_ref(const ReferenceT<P>& r, const S& s) {
  const S a = S(2 * pi) * s;
  const S sa = arbor::sin(a), ca = arbor::cos(a);
  VecN<S, 3> p;
  p[0] = S(r.p0[0]) + S(0.05) * arbor::sin(S(2) * a);
  p[1] = S(r.p0[1]) + S(0.15) * sa;
  p[2] = S(r.p0[2]) + S(0.15) * sa * ca;
  return p;
}

using OrientationError = ad::FrameOrientationError<Robot, ee_frame, ad::CrossSum>;

/// The reference rotation's columns as OrientationError's inputs x[nq + 3 c + i] (the inputs
/// x[0, nq), q, are not read by its error()).
template <class S, class P>
struct ReferenceColumns {
  const ReferenceT<P>& ref;
  S operator[](int k) const { return S(ref.R0[std::size_t(k - nq)]); }
};

/// e_R = 1/2 sum_c r_c x n_c over the columns r_c of R_ref and n_c of the end effector's rotation
/// Rf (zero when aligned): the library's CrossSum orientation error (ad/frame_functions.hpp).
template <class S, class P, class M>
VecN<S, 3> rotation_error(const ReferenceT<P>& r, const M& Rf) {
  return OrientationError::error<S>(ReferenceColumns<S, P>{r}, Rf);
}

using Fd = ad::ForwardDynamics<Robot>;
using Id = ad::InverseDynamics<Robot>;
using Pose = ad::FramePose<Robot, ee_frame>;          // q -> [p, columns of R]
using Position = ad::FramePosition<Robot, ee_frame>;  // q -> p (the tunnel)

// ---- the OCP's nonlinear pieces as generic functions (ad::fn bodies) ----------------------------
/// [sd - sd_ref(s), e_p (3), e_R (3), 1 - s, sd] from the pose (12) and [s, sd] (reference
/// numbers of type Num).
template <class Num = double>
struct TrackResidualT {
  ReferenceT<Num> ref;
  template <class P, class X>
  auto operator()(const P& pose, const X& ssd) const {
    using S = ad::ScalarOf<P>;
    const S s = ssd[0], sd = ssd[1];
    const VecN<S, 3> pr = p_ref(ref, s);
    Eigen::Matrix<S, 3, 3> Rf;
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i)
        Rf(i, c) = pose[3 + 3 * c + i];
    const VecN<S, 3> er = rotation_error<S>(ref, Rf);
    VecN<S, 9> r;
    r[0] = sd - sd_ref(ref.c, s);
    for (int i = 0; i < 3; ++i) {
      r[1 + i] = pose[i] - pr[i];
      r[4 + i] = er[i];
    }
    r[7] = S(1) - s;
    r[8] = sd;
    return r;
  }
};

using TrackResidual = TrackResidualT<double>;

/// The tunnel's e_p = p_ee - p_ref(s) times inv_radius (see make_problem's `scaled`), times the
/// stage parameter w = p[0] (1 on stages 1..N-1, 0 on stage 0: x_0 is the measurement, no decision can
/// change its error, and a hard tunnel that the measurement violates would make the QP
/// infeasible).
struct TunnelError {
  Reference ref;
  double inv_radius = 1;
  template <class P, class X, class W>
  auto operator()(const P& p, const X& s, const W& w) const {
    using S = ad::ScalarOf<P>;
    const VecN<S, 3> pr = p_ref(ref, S(s[0]));
    VecN<S, 3> e;
    for (int i = 0; i < 3; ++i)
      e[i] = (p[i] - pr[i]) * (S(inv_radius) * w[0]);
    return e;
  }
};

/// Weights of the stage cost's residual [track (9), u (8), q (7), qd (7)] (CONTOUR.md).
template <Formulation F>
constexpr std::array<double, 31> path_weights() {
  std::array<double, 31> w{};
  w[0] = 20;                   // (sd - sd_ref)^2
  for (int i = 1; i < 7; ++i)  // |e_p|^2, |e_R|^2
    w[std::size_t(i)] = 0.1;
  for (int i = 9; i < 16; ++i)  // |tau|^2 or |qdd|^2
    w[std::size_t(i)] = F == Formulation::fd ? 4e-5 : 1e-3;
  w[16] = 4e-5;                  // sdd^2
  for (int i = 17; i < 31; ++i)  // |q|^2, |qd|^2
    w[std::size_t(i)] = 1e-2;
  return w;
}
/// Terminal: 1e-5 |[1e-2 q, 10 qd, 1e-2 (1 - s), 10 sd, 10 e_p, 10 e_R]|^2 over the residual
/// [track (9), q (7), qd (7)].
constexpr std::array<double, 23> terminal_weights() {
  std::array<double, 23> w{};
  for (int i = 1; i < 7; ++i)
    w[std::size_t(i)] = 1e-5 * 100;  // e_p, e_R
  w[7] = 1e-5 * 1e-4;                // 1 - s
  w[8] = 1e-5 * 100;                 // sd
  for (int i = 9; i < 16; ++i)
    w[std::size_t(i)] = 1e-5 * 1e-4;  // q
  for (int i = 16; i < 23; ++i)
    w[std::size_t(i)] = 1e-5 * 100;  // qd
  return w;
}

/// Stage parameters p = [w, d (7)]: w the tunnel's weight (TunnelError), d the joint torque the
/// model lacks (OCP-FD: FD(q, qd, tau + d); zero unless a disturbance observer feeds it,
/// arbor/nmpc/momentum_observer.hpp; OCP-ID does not use it).
constexpr int np = 1 + nq;
using D = ocp::Dims<nx, nu, np, horizon>;

/// How OCP-FD's RK4 step is differentiated (arbor/ocp/rk4.hpp): exact, the default (FD's
/// Jacobian at the four stage states: 64 aba_derivatives per preparation), or, built with
/// -DCONTOUR_FROZEN_SENSITIVITY=1, frozen (FD's Jacobian at each interval's start only, aba's
/// value at the other three stages; an O(h^2) inexact Jacobian of the dynamics constraint): the
/// example's programs' default (CMakeLists.txt; README.md, "Configurations", compares the two).
#ifndef CONTOUR_FROZEN_SENSITIVITY
#define CONTOUR_FROZEN_SENSITIVITY 0
#endif
inline constexpr ocp::Sensitivity rk4_sensitivity =
    CONTOUR_FROZEN_SENSITIVITY ? ocp::Sensitivity::frozen : ocp::Sensitivity::exact;

/// The workspace of every RBD call of both formulations at controller scalar T with provider Tag
/// (SCQP): values and Jacobians at T, and the pose's position Jacobian for the tunnel (a
/// PoseCache, since the problem calls ad::FramePose).
template <class Tag, class T>
using Workspace =
    arbor::nmpc::Workspace<D, Tag, T, ocp::HessianKind::gauss_newton, Fd, Id, Pose, Position>;

/// The OCP of formulation F with provider Tag on workspace ws (caller-owned, outliving the
/// problem and its controller); Soft: the tunnel with an exact-penalty slack of weight
/// soft_weight (else hard). The controller's tunnel radius is `radius` (rho less a back-off
/// margin for the linearisation error of real-time iteration). `scaled`: the tunnel row is
/// |e_p / radius|^2 - 1 <= 0 (of order one), else |e_p|^2 - radius^2 <= 0 (of order 1e-4 m^2,
/// the default in real-time iteration). The SQP mode (mpc.hpp) scales it: its absolute
/// 1e-3 primal tolerance would admit |e_p| up to 33 mm on the unscaled row. In double RTI with
/// QP tolerances of 1e-8 the scaled row made the QP hit its iteration limit in 62 of 318 samples.
/// Float: README.md, "Float".
template <Formulation F, class Tag, bool Soft, class W>
auto make_problem(W& ws, const Reference& ref, double soft_weight = 100.0, double radius = rho,
                  bool scaled = false) {
  const auto q = ad::segment<0, nq>(D::x);
  const auto qd = ad::segment<nq, nq>(D::x);
  const auto s = ad::element<14>(D::x);
  const auto sd = ad::element<15>(D::x);
  const auto a = ad::segment<0, nq>(D::u);  // tau (FD) or qdd (ID)
  const auto sdd = ad::element<7>(D::u);

  const auto pose = ad::call<Tag>(ad::bind<Pose>(ws), q);
  const auto track = ad::fn<9>(TrackResidual{ref}, pose, ad::segment<14, 2>(D::x));
  const auto path_cost = ocp::least_squares(ad::cat(track, D::u, q, qd), path_weights<F>());
  const auto terminal_cost = ocp::least_squares(ad::cat(track, q, qd), terminal_weights());
  const auto e_p = ad::fn<3>(TunnelError{ref, scaled ? 1 / radius : 1.0},
                             ad::call<Tag>(ad::bind<Position>(ws), q), s, D::p);
  const auto hard_tunnel = ocp::convex_constraint(e_p, ocp::Ball<3>{scaled ? 1.0 : radius});
  const auto tunnel = [&] {
    if constexpr (Soft)
      return ocp::soft(hard_tunnel, soft_weight);
    else
      return hard_tunnel;
  }();

  auto dynamics = [&] {
    if constexpr (F == Formulation::fd) {
      const auto d = ad::segment<1, nq>(D::p);  // the disturbance estimate
      const auto ode = ad::cat(qd, ad::call<Tag>(ad::bind<Fd>(ws), q, qd, a + d), sd, sdd);
      return ocp::rk4<1, rk4_sensitivity>(ode, h);
    } else {  // exact discretisation of the double integrator
      constexpr double h2 = h * h / 2;
      return ad::cat(q + h * qd + h2 * a, qd + h * a, s + h * sd + h2 * sdd, sd + h * sdd);
    }
  }();
  auto constraints = [&] {
    if constexpr (F == Formulation::fd) {
      return ocp::path_constraints(tunnel);
    } else {
      std::array<double, nq> lo{};
      for (int i = 0; i < nq; ++i)
        lo[std::size_t(i)] = -tau_max[std::size_t(i)];
      return ocp::path_constraints(
          tunnel, ocp::constraint(ad::call<Tag>(ad::bind<Id>(ws), q, qd, a), lo, tau_max));
    }
  }();

  auto problem = ocp::make_problem<D>(dynamics, ocp::path_costs(path_cost),
                                      ocp::terminal_costs(terminal_cost), constraints);
  for (int i = 0; i < nq; ++i) {
    problem.lbx[i] = -q_max[std::size_t(i)];
    problem.ubx[i] = q_max[std::size_t(i)];
    problem.lbx[nq + i] = -qd_max;
    problem.ubx[nq + i] = qd_max;
    const double umax = F == Formulation::fd ? tau_max[std::size_t(i)] : qdd_max;
    problem.lbu[i] = -umax;
    problem.ubu[i] = umax;
  }
  problem.lbx[14] = 0;  // 0 <= s <= 1
  problem.ubx[14] = 1;
  problem.lbx[15] = 0;  // sd >= 0
  return problem;
}

/// The reference of the task from the end-effector pose at q0.
inline Reference make_reference(double c) {
  arbor::Data<Robot, double> d;
  arbor::forward_kinematics<Robot>(d, initial_q());
  const auto& M = arbor::frame_placement<Robot>(d, ee_frame);
  Reference r;
  for (int i = 0; i < 3; ++i)
    r.p0[std::size_t(i)] = M.p[i];
  for (int c2 = 0; c2 < 3; ++c2)
    for (int i = 0; i < 3; ++i)
      r.R0[std::size_t(3 * c2 + i)] = M.R(i, c2);
  r.c = c;
  return r;
}

}  // namespace contour
