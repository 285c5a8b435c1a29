// The pendulum's real-time-iteration closed loop on every target (host and AArch64 in double and
// float, Cortex-M7 in double, Cortex-M4F in float: the precision of each FPU), with the
// controllers in static storage and no heap. The plant is plain double code (problems.hpp's
// pendulum_ode, integrated with plain RK4 at 10 steps per sample; the controller's model takes 2),
// so the controller meets a (small) model mismatch.
//
// Scenario: the pendulum starts at rest 0.2 rad from upright. The gravity torque there,
// m g l sin(0.2) = 1.95 N m, is below the bound |u| <= 3 N m, but bringing it back fast saturates
// the input during the first samples. (From 0.5 rad the gravity torque, 4.7 N m, exceeds the
// bound: the pendulum falls whatever the controller does.) Each sample follows the real-time
// protocol: the preparation phase (shift(), prepare()) runs before the next state is measured,
// the feedback phase (feedback(x)) after, and its control is applied. Checked at every sample:
// status step_taken (prepared for the preparation), a finite control within the bounds; at one
// sample the state is kicked after the preparation, and that sample's control reacts to it; after
// 4 s the pendulum is upright. The same with the feedback's QP bounded to 2 iterations
// (step_taken or step_limited, at most 2 QP iterations per sample).
#include <cmath>

#include "arbor/nmpc/controller.hpp"
#include "arbor_test.hpp"
#include "status_names.hpp"
// problems.hpp uses M_PI, which newlib's <cmath> (bare metal, strict C++20) does not define
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include "problems.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {

using arbor::nmpc::Nmpc;
using arbor::nmpc::NmpcStatus;
using Data = nmpc_test::PendulumData;

// Shooting intervals (h = 0.05 s: a 2 s horizon). ARBOR_NMPC_PORTABLE_HORIZON overrides it.
#ifdef ARBOR_NMPC_PORTABLE_HORIZON
constexpr int horizon = ARBOR_NMPC_PORTABLE_HORIZON;
#else
constexpr int horizon = 40;
#endif
constexpr double pi = 3.14159265358979323846;
constexpr double offset = 0.2;   // initial angle from upright [rad]
constexpr int samples = 80;      // 4 s closed loop
constexpr int plant_steps = 10;  // RK4 steps of the plant per sample
constexpr int kick_sample = 40;  // the state measured at this sample is kicked ...
constexpr double kick = 0.3;     // ... by this angular velocity [rad/s]

using Problem = decltype(nmpc_test::pendulum_problem<horizon>());
template <class S>
using Controller = Nmpc<Problem, S>;

/// The controller of scalar S, in static storage (constructed at the first call).
template <class S>
Controller<S>& controller() {
  static Controller<S> ctrl(nmpc_test::pendulum_problem<horizon>());
  return ctrl;
}

/// The closed loop; bound > 0: the feedback's QP is bounded to that many iterations
/// (NmpcSettings::feedback_qp_iterations; step_limited when it stops there).
template <class S>
void rti_closed_loop(int bound = 0) {
  using Vu = typename Controller<S>::Vu;
  // the QP's primal tolerance (relative to 1 + |u|) and the rounding of u + du in S
  constexpr double tol_u = sizeof(S) == 8 ? 1e-7 : 1e-4 * (1 + Data::u_max);
  Controller<S>& ctrl = controller<S>();
  Eigen::Vector2d x(pi - offset, 0.0);  // the plant's state
  ctrl.settings().feedback_qp_iterations = bound;
  arbor::test::NoAllocScope guard;
  ASSERT_EQ(ctrl.set_initial_guess(x.cast<S>(), Vu::Zero()), NmpcStatus::accepted);
  ASSERT_EQ(ctrl.feedback(x.cast<S>()), NmpcStatus::not_prepared);  // no preparation yet
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  int at_bound = 0;
  for (int k = 0; k < samples; ++k) {
    if (k == kick_sample)
      x[1] += kick;  // a disturbance the preparation could not know about
    const double u_prepared = double(ctrl.control()[0]);  // the plan's u_0 before the feedback
    // the measurement arrives: the feedback phase alone gives the control
    const NmpcStatus fb = ctrl.feedback(x.cast<S>());
    if (bound > 0) {
      EXPECT_TRUE(fb == NmpcStatus::step_taken || fb == NmpcStatus::step_limited)
          << fb << " at sample " << k;
      EXPECT_LE(ctrl.info().qp_iterations, bound) << " at sample " << k;
    } else {
      EXPECT_EQ(fb, NmpcStatus::step_taken) << " at sample " << k;
    }
    const double u = double(ctrl.control()[0]);
    ASSERT_TRUE(std::isfinite(u)) << " at sample " << k;
    EXPECT_LE(std::fabs(u), Data::u_max + tol_u) << " at sample " << k;
    if (std::fabs(u) >= Data::u_max - tol_u)
      ++at_bound;
    if (k == 0) {  // one QP per preparation: a second feedback is refused, the control kept
      EXPECT_EQ(ctrl.feedback(x.cast<S>()), NmpcStatus::not_prepared);
      EXPECT_EQ(double(ctrl.control()[0]), u);
    }
    if (k == kick_sample) {  // positive omega drives theta past pi: the torque must drop
      EXPECT_LT(u, u_prepared - 0.1) << " the control did not react to the kick";
    }
    // until the next sample: the plant moves under u while the controller prepares
    ctrl.shift();
    EXPECT_EQ(ctrl.prepare(), NmpcStatus::prepared) << " at sample " << k;
    x = nmpc_test::rk4_plain(nmpc_test::pendulum_ode, x, u, Data::h, plant_steps);
    ASSERT_TRUE(std::isfinite(x[0]) && std::isfinite(x[1])) << " at sample " << k;
  }
  EXPECT_GE(at_bound, 1);  // the bound was active (and held)
  EXPECT_NEAR(x[0], pi, 1e-3);
  EXPECT_NEAR(x[1], 0.0, 1e-2);
}

}  // namespace

// The scalars of this build (ARBOR_TEST_DOUBLE, ARBOR_TEST_FLOAT: tests/CMakeLists.txt), each
// Cortex-M its FPU's precision.
#if ARBOR_TEST_DOUBLE
TEST(NmpcPortable, PendulumRtiClosedLoopDouble) {
  rti_closed_loop<double>();
}
#endif
#if ARBOR_TEST_FLOAT
TEST(NmpcPortable, PendulumRtiClosedLoopFloat) {
  rti_closed_loop<float>();
}
#endif
// the same with the feedback's QP bounded to 2 iterations (the NMPC's bounded feedback)
#if ARBOR_TEST_DOUBLE
TEST(NmpcPortable, PendulumRtiClosedLoopBoundedFeedbackDouble) {
  rti_closed_loop<double>(2);
}
#endif
#if ARBOR_TEST_FLOAT
TEST(NmpcPortable, PendulumRtiClosedLoopBoundedFeedbackFloat) {
  rti_closed_loop<float>(2);
}
#endif
