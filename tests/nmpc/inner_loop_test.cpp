// The controller's feedback gain and the torque-rate inner loop (issue 59 items 1, 2):
//   - linear dynamics, quadratic cost (the coupled masses of lqr_test.cpp): the gain of the
//     feedback()'s QP equals the finite-horizon LQR gain of a plain Riccati recursion
//     (support/lqr_reference.hpp), and the inner loop reproduces the closed-form law
//     u = K_0 x + k_0 for any measured x at the sample instant, double and float;
//   - clamping: an input bound active in the QP gives a zero gain row (the input stays on its
//     bound), a large deviation is clamped to the bounds;
//   - no gain: before a feedback(), after prepare() and after solve() the controller says
//     not_prepared, and the inner loop passes the status on and applies u_0 (clamped);
//   - the 2-DoF arm (double pendulum, torque bounds and a wall constraint; not the Kinova): the
//     gain against finite differences of two controllers with the same history whose feedback()
//     measures x and x + dx; the compensation of the estimate's change.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <memory>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/ad/expr.hpp"
#include "arbor/nmpc/controller.hpp"
#include "arbor/nmpc/inner_loop.hpp"
#include "coupled_masses.hpp"
#include "lqr_reference.hpp"
#include "status_names.hpp"
#if __has_include(<robots/double_pendulum.hpp>)
#include "arm.hpp"
#define INNER_LOOP_ARM 1
#endif

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}

namespace {
namespace ad = arbor::ad;
namespace ocp = arbor::ocp;
using arbor::nmpc::InnerLoop;
using arbor::nmpc::NmpcStatus;

using namespace arbor::test::coupled_masses;

/// The linear problem's controller after solve(x0) and one real-time iteration's prepare().
template <class Scalar>
struct LinearRti {
  using Ctrl = arbor::nmpc::Nmpc<decltype(linear_problem()), Scalar>;
  std::unique_ptr<Ctrl> ctrl;
  explicit LinearRti(const Eigen::Vector4d& x0) {
    ctrl = std::make_unique<Ctrl>(linear_problem());
    auto& s = ctrl->settings();
    if constexpr (sizeof(Scalar) == 8) {
      s.tol_stationarity = s.tol_primal = s.tol_complementarity = 1e-10;
      s.qp.tol_primal = s.qp.tol_dual = s.qp.tol_comp = 1e-10;
    }
    EXPECT_EQ(ctrl->set_initial_guess(Eigen::Vector4d::Zero().cast<Scalar>(),
                                      Eigen::Vector2d::Zero().cast<Scalar>()),
              NmpcStatus::accepted);
    EXPECT_EQ(ctrl->solve(x0.cast<Scalar>()), NmpcStatus::converged);
  }
};

template <class Scalar>
void check_lqr(double tol) {
  SCOPED_TRACE(sizeof(Scalar) == 8 ? "double" : "float");
  const Eigen::Vector4d x0(0.5, -0.3, 0.2, 0.1);
  LinearRti<Scalar> r(x0);
  auto& ctrl = *r.ctrl;
  Eigen::Matrix<Scalar, 2, 4> k;
  EXPECT_EQ(ctrl.feedback_gain(0, k), NmpcStatus::not_prepared);  // after solve(): none
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  EXPECT_EQ(ctrl.feedback_gain(0, k), NmpcStatus::not_prepared);  // after prepare(): none
  const Eigen::Vector4d xm = x0 + Eigen::Vector4d(0.05, 0.02, -0.1, 0.03);
  ASSERT_EQ(ctrl.feedback(xm.cast<Scalar>()), NmpcStatus::step_taken);
  NmpcStatus gs;
  {
    arbor::test::NoAllocScope guard;
    gs = ctrl.feedback_gain(0, k);
  }
  ASSERT_EQ(gs, NmpcStatus::accepted);
  // the closed form: u_k = K_k x_k + k_k, for every stage k of the plan
  const auto lqr = arbor::test::lqr_riccati(lqr_data(xm));
  for (int s : {0, 1, 7, N - 1}) {
    ASSERT_EQ(ctrl.feedback_gain(s, k), NmpcStatus::accepted);
    EXPECT_LE((k.template cast<double>() - lqr.K[std::size_t(s)]).cwiseAbs().maxCoeff(),
              tol * (1 + lqr.K[std::size_t(s)].cwiseAbs().maxCoeff()))
        << "stage " << s << "\n"
        << k << "\n"
        << lqr.K[std::size_t(s)];
  }
  // the inner loop at the sample instant, for measurements off the plan: the LQR law
  constexpr double inf = std::numeric_limits<double>::infinity();
  using Loop = InnerLoop<Scalar, 4, 2>;
  Loop loop;
  EXPECT_EQ(loop.status(), NmpcStatus::not_prepared);
  const typename Loop::Vu lb = Eigen::Vector2d::Constant(-inf).cast<Scalar>();
  const typename Loop::Vu ub = Eigen::Vector2d::Constant(inf).cast<Scalar>();
  ASSERT_EQ(loop.start(ctrl, Scalar(h), lb, ub), NmpcStatus::accepted);
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> ud(-0.2, 0.2);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Vector4d x(xm(0) + ud(gen), xm(1) + ud(gen), xm(2) + ud(gen), xm(3) + ud(gen));
    typename Loop::Vu u;
    {
      arbor::test::NoAllocScope guard;
      u = loop.control(Scalar(0), x.cast<Scalar>());
    }
    const Eigen::Vector2d ref = lqr.K[0] * x + lqr.k[0];
    EXPECT_LE((u.template cast<double>() - ref).cwiseAbs().maxCoeff(), tol * (1 + ref.norm()));
    // at the end of the sample, relative to the plan's x_1: u_0 + K_0 (x - x_1)
    const Eigen::Vector4d x1 = ctrl.state(1).template cast<double>() + (x - xm);
    const Eigen::Vector2d u1 = loop.control(Scalar(h), x1.cast<Scalar>()).template cast<double>();
    EXPECT_LE((u1 - ref).cwiseAbs().maxCoeff(), tol * (1 + ref.norm()));
    // mid-sample: the chord; beyond the sample: held at x_1
    EXPECT_LE((loop.predicted(Scalar(h / 2)).template cast<double>() -
               0.5 * (ctrl.state(0) + ctrl.state(1)).template cast<double>())
                  .cwiseAbs()
                  .maxCoeff(),
              tol);
    EXPECT_LE((loop.predicted(Scalar(3 * h)) - ctrl.state(1)).cwiseAbs().maxCoeff(), Scalar(tol));
  }
}

// (double: the QP's delta = reg_primal = 1e-8 on every diagonal against R = 0.04, 0.1 moves the
// gain by ~1e-7 relative: docs/qp.md, "Feedback gains")
TEST(InnerLoop, LqrGainAndLawDouble) {
  check_lqr<double>(1e-6);
}
TEST(InnerLoop, LqrGainAndLawFloat) {
  check_lqr<float>(2e-3);
}

template <class Scalar>
void check_clamp() {
  SCOPED_TRACE(sizeof(Scalar) == 8 ? "double" : "float");
  const Eigen::Vector4d x0(0.5, -0.3, 0.2, 0.1);
  LinearRti<Scalar> r(x0);
  auto& ctrl = *r.ctrl;
  // u_0's first input is about -1.17 unbounded: a bound at -1 makes it active at stage 0
  const Eigen::Vector2d u_free = ctrl.control().template cast<double>();
  ASSERT_LT(u_free(0), -1.1);
  const Eigen::Vector2d lbd(-1.0, -50.0), ubd(50.0, 50.0);
  for (int s = 0; s < N; ++s)
    ctrl.set_input_bounds(s, lbd.cast<Scalar>(), ubd.cast<Scalar>());
  for (int it = 0; it < 3; ++it) {  // a few samples at x0 to settle on the bound
    ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
    ASSERT_TRUE(arbor::nmpc::succeeded(ctrl.feedback(x0.cast<Scalar>())));
  }
  ASSERT_NEAR(double(ctrl.control()(0)), -1.0, 1e-5);
  Eigen::Matrix<Scalar, 2, 4> k;
  ASSERT_EQ(ctrl.feedback_gain(0, k), NmpcStatus::accepted);
  EXPECT_EQ(k.row(0).cwiseAbs().maxCoeff(), Scalar(0));  // on its bound: zero row
  EXPECT_GT(k.row(1).cwiseAbs().maxCoeff(), Scalar(0.1));
  using Loop = InnerLoop<Scalar, 4, 2>;
  Loop loop;
  ASSERT_EQ(loop.start(ctrl, Scalar(h), lbd.cast<Scalar>(), ubd.cast<Scalar>()),
            NmpcStatus::accepted);
  // small deviation: the first input stays on its bound, the second follows the gain
  const Eigen::Vector4d e(0.01, -0.02, 0.03, 0.01);
  const auto u = loop.control(Scalar(0), ctrl.state(0) + e.cast<Scalar>());
  EXPECT_EQ(u(0), Scalar(-1));
  EXPECT_NEAR(double(u(1)), double(ctrl.control()(1) + k.row(1) * e.cast<Scalar>()), 1e-5);
  // a large deviation: clamped to the bounds exactly
  const Eigen::Vector4d big(0, 0, 500, -500);
  const auto ub2 = loop.control(Scalar(0), ctrl.state(0) + big.cast<Scalar>());
  const Scalar raw = ctrl.control()(1) + k.row(1) * big.cast<Scalar>();
  ASSERT_GT(std::abs(double(raw)), 50.0);
  EXPECT_EQ(ub2(1), raw > 0 ? Scalar(50) : Scalar(-50));
  // no gain: status passed on, u_0 clamped
  Loop none;
  const typename Loop::Gain junk = Loop::Gain::Constant(Scalar(7));
  const typename Loop::Vu u0(Scalar(-3), Scalar(0.5));
  EXPECT_EQ(none.start(u0, ctrl.state(0), ctrl.state(1), Scalar(h), lbd.cast<Scalar>(),
                       ubd.cast<Scalar>(), NmpcStatus::qp_failed, junk),
            NmpcStatus::qp_failed);
  EXPECT_EQ(none.status(), NmpcStatus::qp_failed);
  const auto un = none.control(Scalar(0.01), ctrl.state(0) + big.cast<Scalar>());
  EXPECT_EQ(un(0), Scalar(-1));
  EXPECT_EQ(un(1), Scalar(0.5));
  // the controller's own no-gain status, through start(ctrl, ...)
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  EXPECT_EQ(none.start(ctrl, Scalar(h), lbd.cast<Scalar>(), ubd.cast<Scalar>()),
            NmpcStatus::not_prepared);
  EXPECT_EQ(none.gain(), Loop::Gain::Zero());
  // a non-finite value: rejected, the last law kept
  typename Loop::Vx bad = ctrl.state(1);
  bad(2) = std::numeric_limits<Scalar>::quiet_NaN();
  EXPECT_EQ(loop.start(ctrl.control(), ctrl.state(0), bad, Scalar(h), lbd.cast<Scalar>(),
                       ubd.cast<Scalar>(), NmpcStatus::accepted, k),
            NmpcStatus::non_finite_input);
  EXPECT_EQ(loop.status(), NmpcStatus::accepted);
}

TEST(InnerLoop, ClampAndNoGainDouble) {
  check_clamp<double>();
}
TEST(InnerLoop, ClampAndNoGainFloat) {
  check_clamp<float>();
}

TEST(InnerLoop, DisturbanceCompensation) {
  // the estimate's change since the sample, through the default map -I on the first ND inputs
  using Loop = InnerLoop<double, 5, 3, 2>;
  Loop loop;
  Loop::Gain k = Loop::Gain::Zero();
  k(2, 4) = 2.0;
  const Loop::Vd d0(0.3, -0.1);
  const Loop::Vu u0(1.0, 2.0, 3.0);
  const Loop::Vx x0 = Loop::Vx::Zero(), x1 = Loop::Vx::Ones();
  const Loop::Vu lb = Loop::Vu::Constant(-10), ub = Loop::Vu::Constant(10);
  ASSERT_EQ(loop.start(u0, x0, x1, 0.02, lb, ub, NmpcStatus::accepted, k, &d0),
            NmpcStatus::accepted);
  const Loop::Vd d(0.5, -0.4);
  const Loop::Vx x = Loop::Vx::Constant(0.75);  // at t = T / 2 the prediction is 0.5
  const Loop::Vu u = loop.control(0.01, x, d);
  EXPECT_NEAR(u(0), 1.0 - 0.2, 1e-15);
  EXPECT_NEAR(u(1), 2.0 + 0.3, 1e-15);
  EXPECT_NEAR(u(2), 3.0 + 2.0 * 0.25, 1e-15);
  EXPECT_EQ(loop.control(0.01, x), Loop::Vu(1.0, 2.0, 3.5));  // without an estimate: none
  Loop::DisturbanceMap g = Loop::DisturbanceMap::Zero();
  g(2, 0) = 1.0;
  loop.set_disturbance_map(g);
  EXPECT_NEAR(loop.control(0.01, x, d)(2), 3.5 + 0.2, 1e-15);
}

#ifdef INNER_LOOP_ARM
// the arm with torque bounds and the wall: two controllers with one history, their feedback()
// at x and x + dx; du_0 = K_0 dx while the working set holds
TEST(InnerLoop, ArmGainMatchesFiniteDifferences) {
  using namespace nmpc_test;
  using Tag = arbor::ad::Analytical;
  constexpr int NA = 20, M = 2;
  using Ws = ArmWorkspace<Tag, false>;
  const auto ws_a = std::make_unique<Ws>();
  const auto ws_b = std::make_unique<Ws>();
  const auto pa = arm_problem<NA, M, Tag>(*ws_a);
  const auto pb = arm_problem<NA, M, Tag>(*ws_b);
  using Ctrl = arbor::nmpc::Nmpc<std::remove_cvref_t<decltype(pa)>, double>;
  const auto ca = std::make_unique<Ctrl>(pa);
  const auto cb = std::make_unique<Ctrl>(pb);
  const Eigen::Vector4d x0(M_PI, 0, 0, 0);
  for (Ctrl* c : {ca.get(), cb.get()}) {
    c->settings().max_iter = 200;
    ASSERT_EQ(c->set_initial_guess(x0, Eigen::Vector2d::Zero()), NmpcStatus::accepted);
    ASSERT_EQ(c->solve(x0), NmpcStatus::converged);
    c->settings().qp.max_iter = 1000;
    // (the QP's error enters du = u_b - u_a undivided: tolerances well below |K dx| ~ 1e-5)
    c->settings().qp.tol_primal = c->settings().qp.tol_dual = c->settings().qp.tol_comp = 1e-11;
  }
  std::mt19937 gen(11);
  std::normal_distribution<double> nd(0.0, 1.0);
  int checked = 0, bound_rows = 0, infeasible = 0;
  Eigen::Vector4d x = x0;
  for (int sample = 0; sample < 30; ++sample) {
    // the plant: the plan's x_1 plus a deviation; both controllers see x (a), one also dx (b)
    // (noise on the velocities only: the wall row of stage 0 depends on q alone and is held
    // exactly there once the tip touches it; a q pushed into the wall makes the QP infeasible)
    x = ca->state(1) + 1e-3 * Eigen::Vector4d(0, 0, nd(gen), nd(gen));
    // dx moves q on even samples only (a q moved into the wall: b's QP is infeasible)
    const double dq = sample % 2 == 0 ? 1e-4 : 0.0;
    const Eigen::Vector4d dx(dq * nd(gen), dq * nd(gen), 1e-4 * nd(gen), 1e-4 * nd(gen));
    for (Ctrl* c : {ca.get(), cb.get()}) {
      c->shift();
      ASSERT_EQ(c->prepare(), NmpcStatus::prepared);
    }
    const NmpcStatus sa = ca->feedback(x), sb = cb->feedback(x + dx);
    ASSERT_TRUE(arbor::nmpc::succeeded(sa))
        << sa << " sample " << sample << " qp " << arbor::qp::to_string(ca->info().qp_status);
    if (!arbor::nmpc::succeeded(sb)) {  // x + dx inside the wall at stage 0: no comparison
      std::printf("arm: sample %d: b %s (QP %s)\n", sample, arbor::nmpc::to_string(sb),
                  arbor::qp::to_string(cb->info().qp_status));
      ++infeasible;
    }
    Eigen::Matrix<double, 2, 4> k;
    ASSERT_EQ(ca->feedback_gain(0, k), NmpcStatus::accepted);
    const auto la = ca->input_bound_multiplier(0), lb = cb->input_bound_multiplier(0);
    const auto ga = ca->constraint_multiplier(0), gb = cb->constraint_multiplier(0);
    bool same = true;
    for (int i = 0; i < 2; ++i) {
      same &= (la(i) != 0) == (lb(i) != 0);
      bound_rows += la(i) != 0;
      if (la(i) != 0)
        EXPECT_EQ(k.row(i).cwiseAbs().maxCoeff(), 0.0);
    }
    same &= (ga(0) != 0) == (gb(0) != 0) && arbor::nmpc::succeeded(sb);
    if (same) {
      const Eigen::Vector2d du = cb->control() - ca->control();
      EXPECT_LE((du - k * dx).cwiseAbs().maxCoeff(), 1e-3 * du.norm() + 1e-9)
          << "sample " << sample << " du " << du.transpose() << " K dx " << (k * dx).transpose();
      ++checked;
    }
    // the inner loop with this gain agrees with b's control at the sample instant
    InnerLoop<double, 4, 2> loop;
    ASSERT_EQ(loop.start(*ca, ArmData::h, Eigen::Vector2d::Constant(-ArmData::tau_max),
                         Eigen::Vector2d::Constant(ArmData::tau_max)),
              NmpcStatus::accepted);
    if (same)
      EXPECT_LE((loop.control(0.0, x + dx) - cb->control()).cwiseAbs().maxCoeff(),
                1e-3 * (k * dx).norm() + 1e-9);
    // b takes a's plan (the same linearisation point next sample; the QPs' warm starts differ
    // in multiplier values only, which do not change a strictly convex QP's solution)
    for (int kk = 0; kk <= NA; ++kk)
      ASSERT_EQ(cb->set_state_guess(kk, ca->state(kk)), NmpcStatus::accepted);
    for (int kk = 0; kk < NA; ++kk)
      ASSERT_EQ(cb->set_input_guess(kk, ca->input(kk)), NmpcStatus::accepted);
  }
  EXPECT_GE(checked, 15);
  EXPECT_LE(infeasible, 15);  // (8 in this run: b's q moved into the wall)
  std::printf("arm: %d samples checked, %d input-bound rows active\n", checked, bound_rows);
}
#endif

}  // namespace
