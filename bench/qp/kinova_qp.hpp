// A QP with the size and structure of the paper's Kinova Gen3 contour-following NMPC subproblem
// (N = 16, x = [q(7), qd(7), s, sd], u = [tau(7) or qdd(7), sdd]), filled with deterministic
// pseudo-random data of a plausible shape: discretised second-order dynamics, a tracking cost of
// rank 3 in (q, s) (so s has no cost of its own), one linearised path constraint per stage, bounds
// on every variable, and for the OCP-ID variant 7 more rows (linearised torque limits).
// Not the real robot: the real subproblems come with the NMPC issue.
#pragma once

#include <cmath>
#include <limits>
#include <random>

#include "arbor/qp/problem.hpp"

namespace arbor::bench {

/// OCP-FD sized QP (one path row per stage) or OCP-ID (NG = 8: path row + 7 torque rows).
template <typename Scalar, int NG>
using KinovaQp = qp::OcpQp<Scalar, 16, 16, 8, NG, 1>;

template <typename Qp>
void make_kinova_qp(Qp& qp, unsigned seed, double x0_shift = 0.0, double cost_noise = 0.0) {
  using Scalar = typename decltype(qp.terminal.q)::Scalar;
  constexpr int N = Qp::horizon, NG = Qp::ng;
  constexpr double dt = 0.05;
  std::mt19937 rng(seed);
  std::mt19937 noise(seed + 1000);
  std::normal_distribution<double> nd(0.0, 1.0);
  auto noisy = [&](double v) { return static_cast<Scalar>(v * (1 + cost_noise * nd(noise))); };
  for (int k = 0; k < N; ++k) {
    auto& s = qp.stage[k];
    s.A.setIdentity();
    s.B.setZero();
    for (int i = 0; i < 7; ++i) {
      s.A(i, 7 + i) = static_cast<Scalar>(dt);
      for (int j = 0; j < 7; ++j) {
        s.A(7 + i, j) = static_cast<Scalar>(dt * 0.1 * nd(rng));
        s.A(7 + i, 7 + j) += static_cast<Scalar>(dt * 0.05 * nd(rng));
        const double minv = (i == j ? 2.0 : 0.0) + 0.2 * nd(rng);
        s.B(7 + i, j) = static_cast<Scalar>(dt * minv);
        s.B(i, j) = static_cast<Scalar>(0.5 * dt * dt * minv);
      }
    }
    s.A(14, 15) = static_cast<Scalar>(dt);
    s.B(14, 7) = static_cast<Scalar>(0.5 * dt * dt);
    s.B(15, 7) = static_cast<Scalar>(dt);
    for (int i = 0; i < 16; ++i)
      s.b(i) = static_cast<Scalar>(0.001 * nd(rng));
    // tracking error e = Jq q - Js s (3 rows): cost 10 |e|^2, rank 3 in (q, s)
    Eigen::Matrix<double, 3, 16> J = Eigen::Matrix<double, 3, 16>::Zero();
    for (int r = 0; r < 3; ++r) {
      for (int j = 0; j < 7; ++j)
        J(r, j) = 0.3 * nd(rng);
      J(r, 14) = -0.5 * nd(rng);
    }
    const Eigen::Matrix<double, 16, 16> Q = 10.0 * J.transpose() * J;
    s.Q = Q.cast<Scalar>();
    for (int i = 0; i < 7; ++i)
      s.Q(i, i) += Scalar(0.01);  // joint positions (regularisation)
    for (int i = 7; i < 14; ++i)
      s.Q(i, i) += Scalar(0.1);  // joint velocities
    s.S.setZero();
    s.R.setIdentity();
    s.R *= Scalar(1e-3);
    s.R(7, 7) = Scalar(1e-2);
    // gradient of the tracking cost at a reference posture (linearisation point offsets)
    Eigen::Matrix<double, 16, 1> xref;
    for (int i = 0; i < 16; ++i)
      xref(i) = i < 7 ? 0.3 * nd(rng) : 0.1 * nd(rng);
    xref(14) = 0.1 * k;
    const Eigen::Matrix<double, 16, 1> grad = -(Q * xref);
    for (int i = 0; i < 16; ++i)
      s.q(i) = noisy(grad(i));
    s.q(15) = noisy(-0.5);  // make progress
    for (int i = 0; i < 8; ++i)
      s.r(i) = noisy(0.01 * nd(rng));
    // path constraint |e|^2 <= rho^2, linearised: 2 e0' J dx <= rho^2 - |e0|^2
    // drawn z, y, x: the order GCC for x86-64 evaluated the constructor's arguments in (it is
    // unspecified; Clang's differs), the data of every figure in bench/qp/RESULTS.md
    const double ez = 0.005 * nd(rng), ey = 0.005 * nd(rng), ex = 0.005 * nd(rng);
    const Eigen::Vector3d e0(ex, ey, ez);
    const Eigen::Matrix<double, 1, 16> row = 2.0 * e0.transpose() * J;
    s.C.setZero();
    s.D.setZero();
    s.C.row(0) = row.cast<Scalar>();
    for (int r = 1; r < NG; ++r) {  // OCP-ID: tau = M qdd + dID/dq q + dID/dqd qd within limits
      for (int j = 0; j < 14; ++j)
        s.C(r, j) = static_cast<Scalar>(0.5 * nd(rng));
      for (int j = 0; j < 7; ++j)
        s.D(r, j) = static_cast<Scalar>((j == r - 1 ? 1.5 : 0.0) + 0.1 * nd(rng));
    }
    for (int i = 0; i < 7; ++i) {
      s.lbx(i) = Scalar(-2.5);
      s.ubx(i) = Scalar(2.5);
      s.lbx(7 + i) = Scalar(-1.2);
      s.ubx(7 + i) = Scalar(1.2);
      s.lbu(i) = Scalar(-6);
      s.ubu(i) = Scalar(6);
    }
    s.lbx(14) = Scalar(0);
    s.ubx(14) = Scalar(1);
    s.lbx(15) = Scalar(0);
    s.ubx(15) = Scalar(0.6);
    s.lbu(7) = Scalar(-5);
    s.ubu(7) = Scalar(5);
  }
  // x_0, and a nominal trajectory that satisfies every constraint: the stage rows are placed
  // around it (the path row 1e-4 above it, so that it is active at the solution now and then)
  Eigen::Matrix<Scalar, 16, 1> x;
  for (int i = 0; i < 16; ++i) {
    const double v = i < 7 ? 0.3 * std::sin(i + 1.0) : (i < 14 ? 0.1 * std::cos(i + 1.0) : 0.0);
    x(i) = static_cast<Scalar>(v);
  }
  for (int k = 0; k < N; ++k) {
    auto& s = qp.stage[k];
    Eigen::Matrix<Scalar, 8, 1> u;
    for (int i = 0; i < 7; ++i)
      u(i) = static_cast<Scalar>(-0.5 * x(7 + i) / dt);  // brake
    u(7) = Scalar(0.5);
    const Eigen::Matrix<Scalar, NG, 1> row = s.C * x + s.D * u;
    s.lg(0) = -std::numeric_limits<Scalar>::infinity();
    s.ug(0) = row(0) + Scalar(1e-4);
    for (int r = 1; r < NG; ++r) {
      s.lg(r) = row(r) - Scalar(8);
      s.ug(r) = row(r) + Scalar(8);
    }
    x = s.A * x + s.B * u + s.b;
  }
  auto& s0 = qp.stage[0];
  for (int i = 0; i < 16; ++i) {
    const double v = i < 7 ? 0.3 * std::sin(i + 1.0) : (i < 14 ? 0.1 * std::cos(i + 1.0) : 0.0);
    s0.lbx(i) = s0.ubx(i) = static_cast<Scalar>(v + (i < 14 ? x0_shift : 0.0));
  }
  auto& t = qp.terminal;
  t.Q = qp.stage[N - 1].Q;
  t.q = qp.stage[N - 1].q;
  t.q(14) = noisy(-5.0);
  t.C = qp.stage[N - 1].C.template topRows<1>();
  t.lg(0) = -std::numeric_limits<Scalar>::infinity();
  t.ug(0) = (t.C * x)(0) + Scalar(1e-4);
  t.lbx = qp.stage[N - 1].lbx;
  t.ubx = qp.stage[N - 1].ubx;
}

}  // namespace arbor::bench
