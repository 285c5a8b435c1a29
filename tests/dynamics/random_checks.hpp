// Test bodies: cross-checks every arbor algorithm on random compile-time robots (branching trees,
// prismatic joints, unaligned axes, rotated frames, massless links) against the independent
// textbook implementation, plus identities, float instantiations and zero allocations.
#pragma once

#include <gtest/gtest.h>

#include <arbor/dynamics/dynamics.hpp>
#include <memory>
#include <random>

#include "alloc_guard.hpp"
#include "check_helpers.hpp"
#include "random_draw.hpp"
#include "random_robot.hpp"
#include "textbook_rbd.hpp"

namespace arbor::test::random_checks {

using arbor::ReferenceFrame;
using arbor::test::NoAllocScope;
namespace tb = arbor::textbook;

template <int N>
struct State {
  Eigen::Matrix<double, N, 1> q, v, a, tau;
  Eigen::Vector3d g;
};

template <int N>
State<N> random_state(std::mt19937& gen) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  State<N> s;
  for (int i = 0; i < N; ++i) {
    s.q[i] = u(gen);
    s.v[i] = u(gen);
    s.a[i] = u(gen);
    s.tau[i] = 5 * u(gen);
  }
  s.g = arbor::test::draw3([&] { return u(gen); }) + Eigen::Vector3d(0, 0, -9.81);
  return s;
}

template <class R>
void matches_textbook() {
  constexpr int n = R::nv;
  const tb::Model model = tb::make_model<R>();
  auto d = std::make_unique<arbor::Data<R, double>>();
  std::mt19937 gen(42 + n);
  for (int trial = 0; trial < 5; ++trial) {
    const State<n> s = random_state<n>(gen);
    const Eigen::VectorXd q = s.q, v = s.v, a = s.a, tau = s.tau;
    std::vector<tb::Vec6> fext_tb(n);
    arbor::ForceArray<R, double> fext;
    std::uniform_real_distribution<double> u(-2, 2);
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 6; ++k)
        fext_tb[i][k] = u(gen);
      fext[i] = arbor::Force<double>::from(fext_tb[i]);
    }
    // rnea, with and without external forces, default gravity
    {
      NoAllocScope guard;
      arbor::rnea<R>(*d, s.q, s.v, s.a);
    }
    ARBOR_EXPECT_REL(d->tau, tb::rnea(model, q, v, a, Eigen::Vector3d(0, 0, -9.81)), 1e-11);
    {
      NoAllocScope guard;
      arbor::rnea<R>(*d, s.q, s.v, s.a, s.g, fext);
    }
    ARBOR_EXPECT_REL(d->tau, tb::rnea(model, q, v, a, s.g, fext_tb), 1e-11);
    // gravity and nle
    {
      NoAllocScope guard;
      arbor::gravity<R>(*d, s.q, s.g);
    }
    ARBOR_EXPECT_REL(d->tau, tb::rnea(model, q, 0 * v, 0 * a, s.g), 1e-11);
    {
      NoAllocScope guard;
      arbor::nle<R>(*d, s.q, s.v, s.g);
    }
    ARBOR_EXPECT_REL(d->tau, tb::rnea(model, q, v, 0 * a, s.g), 1e-11);
    // crba
    {
      NoAllocScope guard;
      arbor::crba<R>(*d, s.q);
    }
    const Eigen::MatrixXd M = tb::crba(model, q);
    ARBOR_EXPECT_REL(d->M, M, 1e-11);
    // aba, with and without external forces
    {
      NoAllocScope guard;
      arbor::aba<R>(*d, s.q, s.v, s.tau, s.g);
    }
    ARBOR_EXPECT_REL(d->ddq, tb::aba(model, q, v, tau, s.g), 1e-8);
    {
      NoAllocScope guard;
      arbor::aba<R>(*d, s.q, s.v, s.tau, s.g, fext);
    }
    ARBOR_EXPECT_REL(d->ddq, tb::aba(model, q, v, tau, s.g, fext_tb), 1e-8);
    // minverse
    {
      NoAllocScope guard;
      arbor::minverse<R>(*d, s.q);
    }
    const Eigen::MatrixXd Minv = M.inverse();
    ARBOR_EXPECT_REL(d->Minv, Minv, 1e-8);
    // cholesky
    {
      NoAllocScope guard;
      arbor::crba<R>(*d, s.q);
      arbor::cholesky_factor<R>(*d);
    }
    Eigen::Matrix<double, n, 1> x;
    {
      NoAllocScope guard;
      x = arbor::cholesky_solve<R>(*d, s.tau);
    }
    ARBOR_EXPECT_REL(x, Minv * tau, 1e-8);
    // placements
    {
      NoAllocScope guard;
      arbor::forward_kinematics<R>(*d, s.q);
      arbor::update_frame_placements<R>(*d);
    }
    const auto ob = tb::body_placements(model, q);
    const auto of = tb::frame_placements(model, q);
    for (int i = 0; i < n; ++i) {
      ARBOR_EXPECT_REL(d->oMi[i].R, ob[i].R, 1e-12);
      ARBOR_EXPECT_REL(d->oMi[i].p, ob[i].p, 1e-12);
      const auto l = tb::joint_transform(model, i, q[i]);
      ARBOR_EXPECT_REL(d->liMi[i].R, l.R, 1e-12);
      ARBOR_EXPECT_REL(d->liMi[i].p, l.p, 1e-12);
    }
    for (int f = 0; f < R::nf; ++f) {
      ARBOR_EXPECT_REL(d->oMf[f].R, of[f].R, 1e-12);
      ARBOR_EXPECT_REL(d->oMf[f].p, of[f].p, 1e-12);
    }
    // velocities
    {
      NoAllocScope guard;
      arbor::forward_kinematics<R>(*d, s.q, s.v);
    }
    const auto vel = tb::body_velocities(model, q, v);
    for (int i = 0; i < n; ++i)
      ARBOR_EXPECT_REL(d->v[i].vector(), vel[i], 1e-12);
    // joint jacobians
    {
      NoAllocScope guard;
      arbor::compute_joint_jacobians<R>(*d, s.q);
    }
    ARBOR_EXPECT_REL(d->J, tb::joint_jacobians(model, q), 1e-12);
  }
}

template <class R>
void identities() {
  constexpr int n = R::nv;
  auto d = std::make_unique<arbor::Data<R, double>>();
  std::mt19937 gen(7 + n);
  for (int trial = 0; trial < 5; ++trial) {
    const State<n> s = random_state<n>(gen);
    Eigen::Matrix<double, n, n> M, Minv;
    Eigen::Matrix<double, n, 1> tau, ddq;
    {
      NoAllocScope guard;
      M = arbor::crba<R>(*d, s.q);
      Minv = arbor::minverse<R>(*d, s.q);
      tau = arbor::rnea<R>(*d, s.q, s.v, s.a, s.g);
      ddq = arbor::aba<R>(*d, s.q, s.v, tau, s.g);
    }
    ARBOR_EXPECT_REL(M * Minv, (Eigen::Matrix<double, n, n>::Identity()), 1e-9);
    ARBOR_EXPECT_REL(ddq, s.a, 1e-9);
    ARBOR_EXPECT_REL(M, M.transpose(), 0.0);
    // Jacobian * v = frame velocity, for every frame and reference frame
    Eigen::Matrix<double, 6, n> J;
    for (int f = 0; f < R::nf; ++f) {
      for (ReferenceFrame rf :
           {ReferenceFrame::world, ReferenceFrame::local, ReferenceFrame::local_world_aligned}) {
        arbor::Motion<double> vf;
        {
          NoAllocScope guard;
          arbor::compute_frame_jacobian<R>(*d, s.q, f, rf, J);
          arbor::forward_kinematics<R>(*d, s.q, s.v);
          arbor::frame_placement<R>(*d, f);
          vf = arbor::frame_velocity<R>(*d, f, rf);
        }
        ARBOR_EXPECT_REL(J * s.v, vf.vector(), 1e-11);
      }
      // finite differences of the frame placement against the LocalWorldAligned Jacobian
      {
        NoAllocScope guard;
        arbor::compute_frame_jacobian<R>(*d, s.q, f, ReferenceFrame::local_world_aligned, J);
      }
      const double h = 1e-6;
      Eigen::Matrix<double, 6, n> Jfd;
      for (int k = 0; k < n; ++k) {
        Eigen::Matrix<double, n, 1> qp = s.q, qm = s.q;
        qp[k] += h;
        qm[k] -= h;
        arbor::SE3<double> Xp, Xm;
        {
          NoAllocScope guard;
          arbor::forward_kinematics<R>(*d, qp);
          Xp = arbor::frame_placement<R>(*d, f);
          arbor::forward_kinematics<R>(*d, qm);
          Xm = arbor::frame_placement<R>(*d, f);
        }
        Jfd.col(k).template head<3>() = (Xp.p - Xm.p) / (2 * h);
        // angular: vee(dR R^T)
        const Eigen::Matrix3d W = (Xp.R - Xm.R) / (2 * h) * (0.5 * (Xp.R + Xm.R)).transpose();
        Jfd.col(k).template tail<3>() =
            Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1)) / 2;
      }
      ARBOR_EXPECT_REL(J, Jfd, 1e-7);
    }
  }
}

template <class R>
void float_matches_double() {
  constexpr int n = R::nv;
  auto d = std::make_unique<arbor::Data<R, double>>();
  auto df = std::make_unique<arbor::Data<R, float>>();
  std::mt19937 gen(99 + n);
  for (int trial = 0; trial < 3; ++trial) {
    const State<n> s = random_state<n>(gen);
    const Eigen::Matrix<float, n, 1> qf = s.q.template cast<float>(),
                                     vf = s.v.template cast<float>(),
                                     af = s.a.template cast<float>(),
                                     tf = s.tau.template cast<float>();
    const Eigen::Vector3f gf = s.g.template cast<float>();
    // Tolerances: float epsilon ~1.2e-7, amplified by depth and conditioning (M^-1, aba).
    {
      NoAllocScope guard;
      arbor::rnea<R>(*d, s.q, s.v, s.a, s.g);
      arbor::rnea<R>(*df, qf, vf, af, gf);
    }
    ARBOR_EXPECT_REL(df->tau, d->tau, 2e-5);
    {
      NoAllocScope guard;
      arbor::crba<R>(*d, s.q);
      arbor::crba<R>(*df, qf);
    }
    ARBOR_EXPECT_REL(df->M, d->M, 2e-5);
    {
      NoAllocScope guard;
      arbor::minverse<R>(*d, s.q);
      arbor::minverse<R>(*df, qf);
    }
    const double cond = (d->M.norm() * d->Minv.norm());
    ARBOR_EXPECT_REL(df->Minv, d->Minv, 1e-6 * cond);
    {
      NoAllocScope guard;
      arbor::aba<R>(*d, s.q, s.v, s.tau, s.g);
      arbor::aba<R>(*df, qf, vf, tf, gf);
    }
    ARBOR_EXPECT_REL(df->ddq, d->ddq, 1e-6 * cond);
    {
      NoAllocScope guard;
      arbor::gravity<R>(*d, s.q, s.g);
      arbor::gravity<R>(*df, qf, gf);
    }
    ARBOR_EXPECT_REL(df->tau, d->tau, 2e-5);
    {
      NoAllocScope guard;
      arbor::forward_kinematics<R>(*d, s.q);
      arbor::update_frame_placements<R>(*d);
      arbor::forward_kinematics<R>(*df, qf);
      arbor::update_frame_placements<R>(*df);
    }
    for (int f = 0; f < R::nf; ++f) {
      ARBOR_EXPECT_REL(df->oMf[f].R, d->oMf[f].R, 1e-5);
      ARBOR_EXPECT_REL(df->oMf[f].p, d->oMf[f].p, 1e-5);
    }
    Eigen::Matrix<float, 6, n> Jf;
    Eigen::Matrix<double, 6, n> J;
    {
      NoAllocScope guard;
      arbor::compute_frame_jacobian<R>(*d, s.q, 0, ReferenceFrame::local, J);
      arbor::compute_frame_jacobian<R>(*df, qf, 0, ReferenceFrame::local, Jf);
    }
    ARBOR_EXPECT_REL(Jf, J, 1e-5);
  }
}

}  // namespace arbor::test::random_checks
