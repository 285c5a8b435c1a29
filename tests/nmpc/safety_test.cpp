// What the controller does when the measured state is outside its bounds, and when its QP keeps
// failing (issue 36), on the pendulum of problems.hpp (|u| <= 3, h = 0.05 s):
//   - a measured velocity 0.6 rad/s above its bound, which no admissible torque removes within one
//     stage: without relaxation the QP is infeasible (qp_failed); with it the controller returns
//     recovering, a plan whose violated bound follows the straight line back to the bound by
//     stage recovery_stages + 1, and in closed loop (plant in plain code) the velocity is back
//     inside within that many samples;
//   - a QP that keeps failing (a hard constraint the measured state violates: infeasible; a QP
//     iteration cap of 1): qp_failed and the stale plan until the max_failed_samples-th
//     consecutive failure, then the fallback: the relaxed QP (fallback_relaxed) or the stop law
//     clipped to the input bounds (fallback_stop); stale_plan keeps failing. No allocation, the
//     control finite in every case;
//   - a bound on the feedback's QP iterations (issue 38): step_limited, the swing-up still done;
//   - the interior-point cold start of the QP (issue 38): the same converged plan from a cold
//     guess with fewer active-set iterations, and the same statuses when every QP is infeasible
//     (the interior point gives up, the active set finds the certificate).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <type_traits>
#include <vector>

#include "alloc_guard.hpp"
#include "arbor/nmpc/controller.hpp"
#include "problems.hpp"
#include "status_names.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}
namespace arbor::qp {
using ::arbor::test::status_names::operator<<;
}

namespace {
namespace ad = arbor::ad;
namespace ocp = arbor::ocp;
using arbor::nmpc::FallbackPolicy;
using arbor::nmpc::NmpcStatus;
using arbor::qp::QpStatus;
using nmpc_test::PendulumData;
constexpr int N = 30;
using D = ocp::Dims<2, 1, 1, N>;
using U1 = Eigen::Matrix<double, 1, 1>;
constexpr double kOmegaMax = 1.0;

/// The swing-up of problems.hpp with |omega| <= 1 as state bounds.
auto bounded_pendulum() {
  auto p = nmpc_test::pendulum_problem<N>();
  p.lbx[1] = -kOmegaMax;
  p.ubx[1] = kOmegaMax;
  return p;
}
using Bounded = decltype(bounded_pendulum());

Eigen::Vector2d plant_step(const Eigen::Vector2d& x, double u) {
  return nmpc_test::rk4_plain(
      [](const Eigen::Vector2d& y, double v) { return nmpc_test::pendulum_ode(y, v); }, x, u,
      PendulumData::h, 10);
}

TEST(NmpcRecovery, StateOutsideItsBoundIsBroughtBack) {
  static const auto p = bounded_pendulum();
  static arbor::nmpc::Nmpc<Bounded> ctrl(p);
  const Eigen::Vector2d x0(0.3, kOmegaMax + 0.6);
  // no admissible torque removes 0.6 rad/s in one stage: |omega'| <= 3 + 9.81 sin(0.3) + 0.16
  ASSERT_GT(0.6, PendulumData::h * (PendulumData::u_max + 9.81 * std::sin(0.4) + 0.2));
  ctrl.settings().recovery_stages = 0;
  ctrl.settings().fallback = FallbackPolicy::stale_plan;
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  EXPECT_EQ(ctrl.solve(x0), NmpcStatus::qp_failed);
  EXPECT_EQ(ctrl.info().qp_status, QpStatus::infeasible);

  const int K = 3;
  ctrl.settings().recovery_stages = K;
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  NmpcStatus st;
  {
    arbor::test::NoAllocScope guard;
    st = ctrl.solve(x0);
  }
  ASSERT_EQ(st, NmpcStatus::recovering) << ctrl.info().qp_status;
  EXPECT_NEAR(ctrl.info().state_violation, 0.6, 1e-12);
  EXPECT_EQ(ctrl.state(0), x0);  // the plan starts at the measurement, violation included
  for (int k = 1; k <= N; ++k) {
    const double bound = kOmegaMax + (k <= K ? 0.6 * double(K + 1 - k) / (K + 1) : 0.0);
    EXPECT_LE(ctrl.state(k)[1], bound + 1e-7) << "stage " << k;
  }
  EXPECT_LT(ctrl.state(1)[1], x0[1]);                          // it decelerates at once
  EXPECT_NEAR(ctrl.control()[0], -PendulumData::u_max, 1e-7);  // as hard as it can

  // closed loop (real-time iteration): inside again within K + 1 samples, then step_taken; the
  // recovering feedbacks keep the presolved QP (settings().presolve_feedback, the default): a
  // twin controller without it sees the same measurements and takes the same steps
  static arbor::nmpc::Nmpc<Bounded> twin(p);
  twin.settings() = ctrl.settings();
  twin.settings().presolve_feedback = false;
  ASSERT_TRUE(ctrl.settings().presolve_feedback);
  ASSERT_EQ(twin.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  ASSERT_EQ(twin.solve(x0), NmpcStatus::recovering);
  ASSERT_LE((twin.control() - ctrl.control()).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::Vector2d x = x0;
  int recovered_presolved = 0;
  for (int t = 1; t <= 12; ++t) {
    x = plant_step(x, ctrl.control()[0]);
    ctrl.shift();
    ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
    {
      arbor::test::NoAllocScope guard;
      st = ctrl.feedback(x);
    }
    ASSERT_TRUE(st == NmpcStatus::step_taken || st == NmpcStatus::recovering) << st;
    ASSERT_TRUE(ctrl.control().allFinite());
    twin.shift();
    ASSERT_EQ(twin.prepare(), NmpcStatus::prepared);
    EXPECT_EQ(twin.feedback(x), st) << "sample " << t;
    EXPECT_FALSE(twin.info().qp_presolved);
    EXPECT_EQ(twin.info().qp_iterations, ctrl.info().qp_iterations) << "sample " << t;
    EXPECT_LE((twin.control() - ctrl.control()).cwiseAbs().maxCoeff(), 1e-9) << "sample " << t;
    recovered_presolved += st == NmpcStatus::recovering && ctrl.info().qp_presolved;
    if (t >= K + 1) {
      EXPECT_LE(x[1], kOmegaMax + 1e-3) << "sample " << t;  // (plant: finer RK4 than the model)
    }
    if (t >= K + 3) {
      EXPECT_EQ(st, NmpcStatus::step_taken) << "sample " << t;
    }
  }
  EXPECT_GE(recovered_presolved, 1);  // a recovering feedback took its prepared step
}

/// The stop law of the tests: damping, u = -20 omega (clipped by the controller); counts calls.
Eigen::Matrix<double, 1, 1> damp(const Eigen::Vector2d& x, void* calls) {
  ++*static_cast<int*>(calls);
  return U1(-20.0 * x[1]);
}

/// The pendulum with the hard path constraint |theta| <= 0.1, which x0 = (0.5, 0) violates at
/// stage 0: every QP is infeasible.
auto infeasible_pendulum() {
  const auto th = ad::element<0>(D::x);
  auto p = nmpc_test::pendulum_problem<N>();
  auto q = ocp::make_problem<D>(p.dynamics, p.path_costs, p.terminal_costs,
                                ocp::path_constraints(ocp::constraint(th, -0.1, 0.1)));
  q.lbu = p.lbu;  // |u| <= 3
  q.ubu = p.ubu;
  return q;
}

template <class Ctrl>
void run_failures(Ctrl& ctrl, const Eigen::Vector2d& x0, int samples,
                  std::vector<NmpcStatus>& out) {
  out.clear();
  Eigen::Vector2d x = x0;
  for (int t = 0; t < samples; ++t) {
    ctrl.shift();
    NmpcStatus st = ctrl.prepare();
    ASSERT_EQ(st, NmpcStatus::prepared);
    {
      arbor::test::NoAllocScope guard;
      st = ctrl.feedback(x);
    }
    out.push_back(st);
    ASSERT_TRUE(ctrl.control().allFinite());
    EXPECT_LE(std::fabs(ctrl.control()[0]), PendulumData::u_max);
    x = plant_step(x, ctrl.control()[0]);
  }
}

TEST(NmpcFallback, InfeasibleQpSwitchesToTheFallbackAfterTheSetCount) {
  static const auto p = infeasible_pendulum();
  static arbor::nmpc::Nmpc<std::remove_const_t<decltype(p)>> ctrl(p);
  const Eigen::Vector2d x0(0.5, 0.0);
  std::vector<NmpcStatus> sts;
  sts.reserve(16);

  // stale plan: fails every sample
  ctrl.settings().fallback = FallbackPolicy::stale_plan;
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Constant(0.5)), NmpcStatus::accepted);
  run_failures(ctrl, x0, 4, sts);
  for (auto s : sts)
    EXPECT_EQ(s, NmpcStatus::qp_failed);
  EXPECT_EQ(ctrl.info().failed_samples, 4);

  // relax (the default), after 3 failures: the relaxed QP's control
  ctrl.settings().fallback = FallbackPolicy::relax;
  ctrl.settings().max_failed_samples = 3;
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Constant(0.5)), NmpcStatus::accepted);
  run_failures(ctrl, x0, 1, sts);  // (the count goes on from the stale-plan run: 5 failures)
  EXPECT_EQ(sts[0], NmpcStatus::fallback_relaxed);
  EXPECT_EQ(ctrl.info().qp_status, QpStatus::solved);

  // stop, with a stop law, after 2 failures: the law clipped to |u| <= 3
  int calls = 0;
  ctrl.set_stop_law(&damp, &calls);
  ctrl.settings().fallback = FallbackPolicy::stop;
  ctrl.settings().max_failed_samples = 2;
  // a success resets the count: the relaxed fallback is not one, so the count is still on
  run_failures(ctrl, x0, 2, sts);
  EXPECT_EQ(sts[0], NmpcStatus::fallback_stop);
  EXPECT_EQ(sts[1], NmpcStatus::fallback_stop);
  EXPECT_EQ(calls, 2);
}

TEST(NmpcFallback, QpIterationCapEscalatesFromRelaxToStop) {
  static const auto p = nmpc_test::pendulum_problem<N>();
  static arbor::nmpc::Nmpc<std::remove_const_t<decltype(p)>> ctrl(p);
  const Eigen::Vector2d x0(0.2, 0.0);  // hanging: the swing-up saturates the torque
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  ctrl.settings().qp.max_iter = 1;  // no QP from this guess ends within one iteration
  std::vector<NmpcStatus> sts;
  sts.reserve(8);
  // relax without a stop law: the relaxed QP hits the cap too: qp_failed (stale plan)
  ASSERT_EQ(ctrl.settings().fallback, FallbackPolicy::relax);  // the default
  ASSERT_EQ(ctrl.settings().max_failed_samples, 2);            // the default
  run_failures(ctrl, x0, 3, sts);
  for (auto s : sts)
    EXPECT_EQ(s, NmpcStatus::qp_failed);
  // with a stop law: from the next failure on, the stop law
  int calls = 0;
  ctrl.set_stop_law(&damp, &calls);
  const Eigen::Vector2d x(0.2, 0.2);
  ctrl.shift();
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  EXPECT_EQ(ctrl.feedback(x), NmpcStatus::fallback_stop);
  EXPECT_EQ(ctrl.control()[0], -3.0);  // -20 * 0.2 = -4, clipped to the bound
  EXPECT_EQ(calls, 1);
  // the QP recovers: step_taken and the count back at zero
  ctrl.settings().qp.max_iter = 5000;
  ctrl.shift();
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  EXPECT_EQ(ctrl.feedback(x), NmpcStatus::step_taken);
  EXPECT_EQ(ctrl.info().failed_samples, 0);
}

// Bounded feedback (NmpcSettings::feedback_qp_iterations): the pendulum balanced upright from
// 0.2 rad off and pushed twice (0.8 rad/s), so that the torque saturates again and the QPs change
// their working sets (up to 8 iterations per sample unbounded). With a bound of K = 2 and 3
// iterations every feedback ends within K QP iterations; the samples the bound cut short return
// step_limited with a control within |u| <= 3; and the closed loop (plant in plain code) is
// upright and at rest 3 s in, as the unbounded loop is.
TEST(NmpcBoundedFeedback, CutShortQpsStillBalanceAfterPushes) {
  static const auto p = nmpc_test::pendulum_problem<N>();
  static arbor::nmpc::Nmpc<std::remove_const_t<decltype(p)>> ctrl(p);
  const double pi = std::numbers::pi;
  constexpr double kPush = 0.8;        // [rad/s]
  for (const int k_max : {0, 2, 3}) {  // 0: no bound (the reference run)
    SCOPED_TRACE("feedback_qp_iterations " + std::to_string(k_max));
    Eigen::Vector2d x(pi - 0.2, 0.0);  // 0.2 rad from upright: the torque saturates at first
    ASSERT_EQ(ctrl.set_initial_guess(x, U1::Zero()), NmpcStatus::accepted);
    ASSERT_EQ(ctrl.solve(x), NmpcStatus::converged);  // the plan of the first sample
    ctrl.settings().feedback_qp_iterations = k_max;
    int limited = 0, most = 0;
    double late = 0;  // largest distance from upright (either way round) after 3 s
    for (int t = 0; t < 100; ++t) {
      ctrl.shift();
      ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
      NmpcStatus st;
      {
        arbor::test::NoAllocScope guard;
        st = ctrl.feedback(x);
      }
      ASSERT_TRUE(st == NmpcStatus::step_taken || st == NmpcStatus::step_limited) << st;
      EXPECT_TRUE(arbor::nmpc::succeeded(st));
      most = std::max(most, ctrl.info().qp_iterations);
      if (st == NmpcStatus::step_limited) {
        ++limited;
        EXPECT_EQ(ctrl.info().qp_status, QpStatus::iteration_limit);
        EXPECT_GT(ctrl.info().qp_merit, 1.0);  // not solved, and said so
      }
      ASSERT_TRUE(ctrl.control().allFinite());
      EXPECT_LE(std::fabs(ctrl.control()[0]), PendulumData::u_max);
      x = plant_step(x, ctrl.control()[0]);
      if (t == 10 || t == 30)
        x[1] += t == 10 ? kPush : -kPush;  // pushes: the torque saturates again
      if (t >= 60)
        late = std::max(late, std::hypot(std::remainder(x[0] - pi, 2 * pi), x[1]));
    }
    if (k_max > 0) {
      EXPECT_LE(most, k_max);
      EXPECT_GT(limited, 0);  // the bound was applied (and reported)
      std::printf("bound %d: %d samples step_limited\n", k_max, limited);
    } else {
      EXPECT_GT(most, 3);  // unbounded, some QPs need more than the bounds allow
      std::printf("unbounded: at most %d QP iterations per sample\n", most);
    }
    EXPECT_LT(late, 0.05);  // upright and at rest at the end
  }
  ctrl.settings().feedback_qp_iterations = 0;
}

/// Two controllers of the bounded pendulum: the QP's cold starts by the active set alone
/// (plain), and by the interior point and its crossover (crossed).
struct ColdStartPair {
  using Ctrl = arbor::nmpc::Nmpc<Bounded>;
  Ctrl plain, crossed;
  Ctrl::ColdStart ipm;
  explicit ColdStartPair(const Bounded& p) : plain(p), crossed(p) {
    crossed.set_cold_start_workspace(&ipm);
  }
  /// Largest difference of the two plans' inputs.
  double input_distance() const {
    double d = 0;
    for (int k = 0; k < N; ++k)
      d = std::max(d, (plain.input(k) - crossed.input(k)).cwiseAbs().maxCoeff());
    return d;
  }
};
ColdStartPair& cold_start_pair() {
  static ColdStartPair pair(bounded_pendulum());  // big: static storage
  return pair;
}

TEST(NmpcColdStart, InteriorPointCrossoverGivesTheSamePlanWithFewerQpIterations) {
  auto& plain = cold_start_pair().plain;
  auto& crossed = cold_start_pair().crossed;
  const Eigen::Vector2d x0(0.0, 0.0);  // hanging: the swing-up saturates torque and velocity
  ASSERT_EQ(plain.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  ASSERT_EQ(crossed.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  NmpcStatus s1, s2;
  s1 = plain.solve(x0);
  {
    arbor::test::NoAllocScope guard;
    s2 = crossed.solve(x0);
  }
  ASSERT_EQ(s1, NmpcStatus::converged);
  ASSERT_EQ(s2, NmpcStatus::converged);
  double dx = 0;
  for (int k = 0; k <= N; ++k)
    dx = std::max(dx, (plain.state(k) - crossed.state(k)).cwiseAbs().maxCoeff());
  const double du = cold_start_pair().input_distance();
  EXPECT_LT(dx, 1e-5);
  EXPECT_LT(du, 1e-5);
  EXPECT_EQ(plain.info().qp_ipm_iterations, 0);
  EXPECT_GT(crossed.info().qp_ipm_iterations, 0);  // the first QP only (the others are warm)
  EXPECT_LE(crossed.info().qp_ipm_iterations, crossed.settings().cold_start.max_iter);
  std::printf(
      "cold SQP solve: %d SQP iterations, %d active-set iterations; with the interior "
      "point: %d SQP iterations, %d interior-point + %d active-set iterations; plans "
      "%.1e / %.1e apart\n",
      plain.info().iterations, plain.info().qp_iterations, crossed.info().iterations,
      crossed.info().qp_ipm_iterations, crossed.info().qp_iterations, dx, du);
  EXPECT_LT(crossed.info().qp_iterations, plain.info().qp_iterations);
}

TEST(NmpcColdStart, RealTimeIterationAfterAResetTakesTheSameStep) {
  // set_initial_guess() resets the multipliers: the next feedback's QP starts cold, after
  // prepare() prefactorized it for the empty working set (the crossover names another one)
  auto& plain = cold_start_pair().plain;
  auto& crossed = cold_start_pair().crossed;
  const Eigen::Vector2d x0(0.3, -0.2);
  for (ColdStartPair::Ctrl* c : {&plain, &crossed}) {
    ASSERT_EQ(c->set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
    ASSERT_EQ(c->prepare(), NmpcStatus::prepared);
    NmpcStatus st;
    {
      arbor::test::NoAllocScope guard;
      st = c->feedback(x0);
    }
    ASSERT_EQ(st, NmpcStatus::step_taken);
    EXPECT_EQ(c->info().qp_status, QpStatus::solved);
  }
  EXPECT_EQ(plain.info().qp_ipm_iterations, 0);
  EXPECT_GT(crossed.info().qp_ipm_iterations, 0);
  const double du = cold_start_pair().input_distance();
  EXPECT_LT(du, 1e-6);  // the same QP solution (unique: the stage costs are strictly convex)
  std::printf(
      "RTI feedback from a reset: %d active-set iterations; with the interior point %d + "
      "%d; inputs %.1e apart\n",
      plain.info().qp_iterations, crossed.info().qp_ipm_iterations, crossed.info().qp_iterations,
      du);
}

TEST(NmpcColdStart, InfeasibleQpsFailAsWithoutTheInteriorPoint) {
  static const auto p = infeasible_pendulum();
  using Ctrl = arbor::nmpc::Nmpc<std::remove_const_t<decltype(p)>>;
  static Ctrl ctrl(p);
  static Ctrl::ColdStart ipm;
  ctrl.set_cold_start_workspace(&ipm);
  ctrl.settings().fallback = FallbackPolicy::stale_plan;
  const Eigen::Vector2d x0(0.5, 0.0);
  std::vector<NmpcStatus> sts;
  sts.reserve(4);
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Constant(0.5)), NmpcStatus::accepted);
  run_failures(ctrl, x0, 3, sts);
  for (auto s : sts)
    EXPECT_EQ(s, NmpcStatus::qp_failed);
  EXPECT_EQ(ctrl.info().qp_status, QpStatus::infeasible);
  EXPECT_GT(ctrl.info().qp_ipm_iterations, 0);  // tried (the multipliers were reset)
}

}  // namespace
