// A run-time payload on random robots (all joint kinds, rotated frames, massless links): the
// dynamics against the textbook implementation (tests/support/textbook_rbd.hpp) whose body
// inertia gets the payload's 6x6 inertia added, built here independently of arbor's payload code;
// the first-order derivatives against central differences of the payload dynamics, and the
// second-order routines against central differences of the first-order derivatives.
#include <gtest/gtest.h>

#include <algorithm>
#include <arbor/derivatives/aba_second_order.hpp>
#include <arbor/derivatives/derivatives.hpp>
#include <arbor/derivatives/rnea_second_order.hpp>
#include <arbor/dynamics/dynamics.hpp>
#include <arbor/dynamics/payload.hpp>
#include <cstdio>
#include <random>

#include "../dynamics/random_robot.hpp"
#include "alloc_guard.hpp"
#include "textbook_rbd.hpp"

namespace {

namespace tb = arbor::textbook;
using arbor::Data;
using arbor::DerivativeData;
using arbor::SecondOrderData;

double rel_err(const Eigen::MatrixXd& x, const Eigen::MatrixXd& ref) {
  return (x - ref).cwiseAbs().maxCoeff() / std::max(1.0, ref.cwiseAbs().maxCoeff());
}

/// The payload's 6x6 inertia in the frame ([v; w] ordering), moved to the frame's body:
/// I_body = X^T I_frame X with X the motion transform body -> frame.
tb::Mat6 payload_in_body(const tb::Model& m, int frame, double mass, const tb::Vec3& c,
                         const tb::Mat3& Ic) {
  tb::Mat6 I = tb::Mat6::Zero();
  const tb::Mat3 C = tb::skew(c);
  I.topLeftCorner<3, 3>() = mass * tb::Mat3::Identity();
  I.topRightCorner<3, 3>() = -mass * C;
  I.bottomLeftCorner<3, 3>() = mass * C;
  I.bottomRightCorner<3, 3>() = Ic - mass * C * C;
  const tb::Mat6 X = tb::motion_parent_to_child(m.frame_placement[frame]);
  return X.transpose() * I * X;
}

template <class R>
void check_random(int frame) {
  constexpr int n = R::nv;
  using V = arbor::VecN<double, n>;
  const int body = R::frames[frame].body;
  ASSERT_GE(body, 0);
  const double mass = 0.7;
  const tb::Vec3 c(0.05, -0.03, 0.08);
  tb::Mat3 Ic;
  Ic << 3e-3, 2e-4, -1e-4, 2e-4, 4e-3, 3e-4, -1e-4, 3e-4, 2.5e-3;
  static Data<R, double> d, e;
  static DerivativeData<R, double> dd, de;
  static SecondOrderData<R, double> so;
  ASSERT_TRUE(arbor::set_payload(d, frame, mass, c, Ic));
  ASSERT_TRUE(arbor::set_payload(e, frame, mass, c, Ic));
  tb::Model m = tb::make_model<R>();
  const tb::Model plain = m;
  m.inertia[body] += payload_in_body(m, frame, mass, c, Ic);
  const tb::Vec3 g(0.3, -0.2, -9.81);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rnd = [&] {
    V x;
    for (int k = 0; k < n; ++k)
      x[k] = u(rng);
    return x;
  };
  double err_dyn = 0, err_d = 0, err_so = 0, effect = 0;
  for (int s = 0; s < 3; ++s) {
    const V q = rnd(), v = rnd(), a = rnd(), tau = rnd() * 5.0, lam = rnd();
    const tb::VecX qx = q, vx = v, ax = a, tx = tau;
    {
      arbor::test::NoAllocScope guard;
      arbor::rnea<R>(d, q, v, a, g);
    }
    err_dyn = std::max(err_dyn, rel_err(d.tau, tb::rnea(m, qx, vx, ax, g)));
    effect = std::max(effect, rel_err(d.tau, tb::rnea(plain, qx, vx, ax, g)));
    arbor::gravity<R>(d, q, g);
    err_dyn = std::max(err_dyn, rel_err(d.tau, tb::rnea(m, qx, 0 * vx, 0 * ax, g)));
    arbor::nle<R>(d, q, v, g);
    err_dyn = std::max(err_dyn, rel_err(d.tau, tb::rnea(m, qx, vx, 0 * ax, g)));
    const tb::MatX M = tb::crba(m, qx);
    {
      arbor::test::NoAllocScope guard;
      arbor::crba<R>(d, q);
    }
    err_dyn = std::max(err_dyn, rel_err(d.M, M));
    {
      arbor::test::NoAllocScope guard;
      arbor::aba<R>(d, q, v, tau, g);
    }
    err_dyn = std::max(err_dyn, rel_err(d.ddq, tb::aba(m, qx, vx, tx, g)));
    {
      arbor::test::NoAllocScope guard;
      arbor::minverse<R>(d, q);
    }
    err_dyn = std::max(err_dyn, rel_err(d.Minv, M.inverse()));

    // first order against central differences of the payload rnea and aba
    const double h = 1e-6;
    Eigen::MatrixXd Dq(n, n), Dv(n, n), Fq(n, n), Fv(n, n);
    for (int k = 0; k < n; ++k) {
      V qp = q, qm = q, vp = v, vm = v;
      qp[k] += h, qm[k] -= h, vp[k] += h, vm[k] -= h;
      const V t1 = arbor::rnea<R>(e, qp, v, a, g), t2 = arbor::rnea<R>(e, qm, v, a, g);
      Dq.col(k) = (t1 - t2) / (2 * h);
      const V t3 = arbor::rnea<R>(e, q, vp, a, g), t4 = arbor::rnea<R>(e, q, vm, a, g);
      Dv.col(k) = (t3 - t4) / (2 * h);
      const V f1 = arbor::aba<R>(e, qp, v, tau, g), f2 = arbor::aba<R>(e, qm, v, tau, g);
      Fq.col(k) = (f1 - f2) / (2 * h);
      const V f3 = arbor::aba<R>(e, q, vp, tau, g), f4 = arbor::aba<R>(e, q, vm, tau, g);
      Fv.col(k) = (f3 - f4) / (2 * h);
    }
    {
      arbor::test::NoAllocScope guard;
      arbor::rnea_derivatives<R>(d, dd, q, v, a, g);
    }
    err_d = std::max({err_d, rel_err(dd.dtau_dq, Dq), rel_err(dd.dtau_dv, Dv), rel_err(d.M, M)});
    {
      arbor::test::NoAllocScope guard;
      arbor::aba_derivatives<R>(d, dd, q, v, tau, g);
    }
    err_d = std::max(
        {err_d, rel_err(dd.ddq_dq, Fq), rel_err(dd.ddq_dv, Fv), rel_err(d.Minv, M.inverse())});

    // second order against central differences of the gradients from the first-order routines
    // (ID: [dtau_dq' lam; dtau_dv' lam; M lam] over (q, v, a); FD likewise over (q, v, tau))
    auto grad_id = [&](const V& qq, const V& vv, const V& aa) {
      arbor::rnea_derivatives<R>(e, de, qq, vv, aa, g);
      Eigen::VectorXd gr(3 * n);
      gr << de.dtau_dq.transpose() * lam, de.dtau_dv.transpose() * lam, e.M * lam;
      return gr;
    };
    auto grad_fd = [&](const V& qq, const V& vv, const V& tt) {
      arbor::aba_derivatives<R>(e, de, qq, vv, tt, g);
      Eigen::VectorXd gr(3 * n);
      gr << de.ddq_dq.transpose() * lam, de.ddq_dv.transpose() * lam, e.Minv * lam;
      return gr;
    };
    Eigen::MatrixXd Hid(3 * n, 3 * n), Hfd(3 * n, 3 * n);
    for (int k = 0; k < 3 * n; ++k) {
      V z[3] = {q, v, a}, w[3] = {q, v, a}, zt[3] = {q, v, tau}, wt[3] = {q, v, tau};
      z[k / n][k % n] += h, w[k / n][k % n] -= h;
      zt[k / n][k % n] += h, wt[k / n][k % n] -= h;
      Hid.col(k) = (grad_id(z[0], z[1], z[2]) - grad_id(w[0], w[1], w[2])) / (2 * h);
      Hfd.col(k) = (grad_fd(zt[0], zt[1], zt[2]) - grad_fd(wt[0], wt[1], wt[2])) / (2 * h);
    }
    {
      arbor::test::NoAllocScope guard;
      arbor::rnea_second_order_derivatives<R>(d, so, q, v, a, lam, g);
    }
    err_so = std::max(err_so, rel_err(so.hessian, Hid));
    {
      arbor::test::NoAllocScope guard;
      arbor::aba_second_order_derivatives<R>(d, dd, so, q, v, tau, lam, g);
    }
    err_so = std::max(err_so, rel_err(so.hessian, Hfd));
  }
  std::printf(
      "payload random robot (frame %d, body %d%s): dynamics vs textbook %.2e, first order vs "
      "differences %.2e, second order vs differences %.2e (payload's effect on tau %.2e)\n",
      frame, body, arbor::detail::body_massless<R>(body) ? ", massless" : "", err_dyn, err_d,
      err_so, effect);
  EXPECT_LT(err_dyn, 1e-10);
  EXPECT_LT(err_d, 1e-6);
  EXPECT_LT(err_so, 1e-6);
  EXPECT_GT(effect, 1e-3);
}

using R_6_7 = arbor::test::RandomRobot<6, 7>;
using R_3_9 = arbor::test::RandomRobot<3, 9>;

TEST(PayloadRandom, LastBody) {
  check_random<R_6_7>(R_6_7::nb - 1);
}
TEST(PayloadRandom, MidTreeBody) {
  check_random<R_3_9>(3);
}
// Body 7 of RandomRobot<3, 9> has no mass of its own (its terms are skipped at compile time).
TEST(PayloadRandom, MasslessBody) {
  static_assert(arbor::detail::body_massless<R_3_9>(7) && R_3_9::frames[7].body == 7);
  check_random<R_3_9>(7);
}

}  // namespace
