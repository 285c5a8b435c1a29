// The NMPC's behaviour on the pendulum of problems.hpp: soft constraints (zero slack when the hard
// problem is feasible, a feasible answer with positive slack when it is not), statuses on bad
// input (each with a finite control, the plan unchanged and no allocation), superlinear
// convergence of the exact-Hessian SQP, and the real-time-iteration closed loop in double and
// float against a plant simulated here in plain code (finer RK4 than the controller's).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
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
using arbor::nmpc::NmpcStatus;
using arbor::ocp::HessianKind;
using arbor::qp::QpStatus;
using nmpc_test::PendulumData;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int N = 30;
using D = ocp::Dims<2, 1, 1, N>;
using U1 = Eigen::Matrix<double, 1, 1>;

/// The pendulum of problems.hpp with one path constraint on its state.
template <class Con>
auto constrained_pendulum(const Con& con) {
  const auto th = ad::element<0>(D::x);
  const auto om = ad::element<1>(D::x);
  const auto ode = ad::cat(om, -(PendulumData::g / PendulumData::l) * ad::sin(th) -
                                   PendulumData::b * om + ad::element<0>(D::u));
  const Eigen::Vector2d up(M_PI, 0.0);
  auto p = ocp::make_problem<D>(
      ocp::rk4<2>(ode, PendulumData::h),
      ocp::path_costs(ocp::least_squares(D::x - ad::constant(up), std::array<double, 2>{1.0, 0.1}),
                      ocp::least_squares(D::u, 0.01)),
      ocp::terminal_costs(ocp::least_squares(D::x - ad::constant(up), 100.0)),
      ocp::path_constraints(con));
  p.lbu.fill(-PendulumData::u_max);
  p.ubu.fill(PendulumData::u_max);
  return p;
}

const auto omega_max = [] { return ocp::constraint(ad::element<1>(D::x), -1.0, 1.0); };
const auto theta_box = [] { return ocp::constraint(ad::element<0>(D::x), -0.1, 0.1); };

// ---- soft constraints ---------------------------------------------------------------------------
TEST(NmpcSoft, ZeroSlackWhenTheHardProblemIsFeasible) {
  static auto hard_p = constrained_pendulum(omega_max());
  static auto soft_p = constrained_pendulum(ocp::soft(omega_max(), 1e3));
  static arbor::nmpc::Nmpc<decltype(hard_p)> hard(hard_p);
  static arbor::nmpc::Nmpc<decltype(soft_p)> soft(soft_p);
  const Eigen::Vector2d x0(0, 0);
  ASSERT_EQ(hard.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  ASSERT_EQ(soft.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  NmpcStatus sh, ss;
  {
    arbor::test::NoAllocScope guard;
    sh = hard.solve(x0);
    ss = soft.solve(x0);
  }
  ASSERT_EQ(sh, NmpcStatus::converged);
  ASSERT_EQ(ss, NmpcStatus::converged)
      << ss << " it " << soft.info().iterations << " stat " << soft.info().stationarity << " pr "
      << soft.info().primal_residual << " comp " << soft.info().complementarity;
  bool active = false;
  for (int k = 0; k < N; ++k) {
    EXPECT_LE(std::fabs(soft.slack(k)[0]), 1e-8) << "stage " << k;
    EXPECT_LE(std::fabs(hard.state(k)[1]), 1.0 + 1e-8);
    EXPECT_NEAR(hard.input(k)[0], soft.input(k)[0], 1e-6) << "stage " << k;
    active = active || std::fabs(hard.state(k)[1]) > 1.0 - 1e-6;
  }
  EXPECT_TRUE(active) << "the test needs the velocity bound active somewhere";
}

TEST(NmpcSoft, PositiveSlackWhenTheHardProblemIsInfeasible) {
  static auto hard_p = constrained_pendulum(theta_box());
  static auto soft_p = constrained_pendulum(ocp::soft(theta_box(), 1e3, 1.0));
  static arbor::nmpc::Nmpc<decltype(hard_p)> hard(hard_p);
  static arbor::nmpc::Nmpc<decltype(soft_p)> soft(soft_p);
  const Eigen::Vector2d x0(0.5, 0);  // violates |theta| <= 0.1 at stage 0: no control helps
  ASSERT_EQ(hard.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  ASSERT_EQ(soft.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  NmpcStatus sh, ss;
  {
    arbor::test::NoAllocScope guard;
    sh = hard.solve(x0);
    ss = soft.solve(x0);
  }
  EXPECT_EQ(sh, NmpcStatus::qp_failed);
  EXPECT_EQ(hard.info().qp_status, QpStatus::infeasible);
  EXPECT_TRUE(hard.control().allFinite());
  ASSERT_EQ(ss, NmpcStatus::converged)
      << ss << " it " << soft.info().iterations << " stat " << soft.info().stationarity << " pr "
      << soft.info().primal_residual << " comp " << soft.info().complementarity;
  EXPECT_NEAR(soft.slack(0)[0], 0.4, 1e-8);  // theta_0 = 0.5 is 0.4 beyond the bound
  for (int k = 0; k < N; ++k) {
    EXPECT_GE(soft.slack(k)[0], -1e-10);
    const double th = soft.state(k)[0], s = soft.slack(k)[0];
    EXPECT_LE(th, 0.1 + s + 1e-8);
    EXPECT_GE(th, -0.1 - s - 1e-8);
  }
  EXPECT_LT(soft.slack(N - 1)[0], soft.slack(0)[0]);  // the controller brings theta back
}

// ---- bad input ----------------------------------------------------------------------------------
TEST(NmpcBadInput, EveryFailureHasItsStatusAFiniteControlAndNoAllocation) {
  static auto p = nmpc_test::pendulum_problem<N>();
  static arbor::nmpc::Nmpc<decltype(p)> ctrl(p);
  const Eigen::Vector2d x0(0.2, 0);
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Constant(0.5)), NmpcStatus::accepted);
  arbor::test::NoAllocScope guard;
  EXPECT_EQ(ctrl.solve(Eigen::Vector2d(kNaN, 0)), NmpcStatus::non_finite_input);
  EXPECT_EQ(ctrl.solve(Eigen::Vector2d(0, std::numeric_limits<double>::infinity())),
            NmpcStatus::non_finite_input);
  EXPECT_EQ(ctrl.control()[0], 0.5);  // plan unchanged
  ctrl.set_parameter(3, Eigen::Matrix<double, 1, 1>(kNaN));
  EXPECT_EQ(ctrl.solve(x0), NmpcStatus::non_finite_input);
  EXPECT_EQ(ctrl.prepare(), NmpcStatus::non_finite_input);
  ctrl.set_parameter(3, Eigen::Matrix<double, 1, 1>(0.0));
  EXPECT_EQ(ctrl.feedback(x0), NmpcStatus::not_prepared);
  EXPECT_EQ(ctrl.set_input_guess(2, U1(kNaN)), NmpcStatus::non_finite_input);
  ctrl.settings().qp.max_iter = 1;  // a QP iteration cap
  EXPECT_EQ(ctrl.solve(x0), NmpcStatus::qp_failed);
  EXPECT_EQ(ctrl.info().qp_status, QpStatus::iteration_limit);
  EXPECT_EQ(ctrl.control()[0], 0.5);
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  EXPECT_EQ(ctrl.feedback(Eigen::Vector2d(kNaN, 0)), NmpcStatus::non_finite_input);
  EXPECT_EQ(ctrl.feedback(x0), NmpcStatus::qp_failed);  // the preparation survived the NaN
  EXPECT_EQ(ctrl.control()[0], 0.5);
  ctrl.settings().qp.max_iter = 200;
  ctrl.settings().max_iter = 1;  // an SQP iteration cap
  EXPECT_EQ(ctrl.solve(x0), NmpcStatus::iteration_limit);
  EXPECT_TRUE(ctrl.control().allFinite());
  // a setter's status says the value was stored, not that the controller is prepared
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  EXPECT_EQ(ctrl.set_input_guess(2, U1(0.5)), NmpcStatus::accepted);
  EXPECT_TRUE(arbor::nmpc::succeeded(NmpcStatus::accepted));
  EXPECT_EQ(ctrl.feedback(x0), NmpcStatus::not_prepared);
}

TEST(NmpcBadInput, NonFiniteEvaluation) {
  // sqrt(theta + 1) is NaN below theta = -1
  const auto cost = ocp::least_squares(ad::sqrt(ad::element<0>(D::x) + 1.0), 1.0);
  static auto p = ocp::make_problem<D>(ocp::rk4<1>(ad::cat(ad::element<1>(D::x), D::u), 0.1),
                                       ocp::path_costs(cost), ocp::terminal_costs(cost));
  static arbor::nmpc::Nmpc<decltype(p)> ctrl(p);
  const Eigen::Vector2d x0(-2, 0);
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Constant(0.25)), NmpcStatus::accepted);
  arbor::test::NoAllocScope guard;
  EXPECT_EQ(ctrl.solve(x0), NmpcStatus::non_finite_evaluation);
  EXPECT_EQ(ctrl.prepare(), NmpcStatus::non_finite_evaluation);
  EXPECT_EQ(ctrl.control()[0], 0.25);
  // a custom loop that solves the QP after a failed linearisation, the QP set up by an earlier
  // preparation: the QP reports the NaN (the controller lets its update skip the matrices'
  // check only after a linearisation that checked them; its factorization would find it too)
  ASSERT_EQ(ctrl.set_initial_guess(Eigen::Vector2d(0, 0), U1::Constant(0.25)),
            NmpcStatus::accepted);
  ASSERT_EQ(ctrl.prepare(), NmpcStatus::prepared);
  ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Constant(0.25)), NmpcStatus::accepted);
  EXPECT_EQ(ctrl.linearize(), NmpcStatus::non_finite_evaluation);
  ctrl.embed(x0);
  EXPECT_EQ(ctrl.solve_qp(), NmpcStatus::qp_failed);
  EXPECT_EQ(ctrl.info().qp_status, QpStatus::non_finite);
  EXPECT_EQ(ctrl.control()[0], 0.25);
}

// ---- convergence --------------------------------------------------------------------------------
/// Step norms |d_k|_inf of a full solve taken one iteration per call.
template <HessianKind H>
std::vector<double> step_norms(bool* converged) {
  static auto p = nmpc_test::pendulum_problem<N>();
  static arbor::nmpc::Nmpc<decltype(p), double, H> ctrl(p);
  const Eigen::Vector2d x0(0, 0);
  EXPECT_EQ(ctrl.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
  ctrl.settings().max_iter = 1;
  std::vector<double> d;
  *converged = false;
  for (int i = 0; i < 40 && !*converged; ++i) {
    NmpcStatus st;
    {
      arbor::test::NoAllocScope guard;
      st = ctrl.solve(x0);
    }
    *converged = st == NmpcStatus::converged;
    if (!*converged) {
      EXPECT_EQ(st, NmpcStatus::iteration_limit);
      d.push_back(ctrl.info().step_norm);
    }
  }
  return d;
}

TEST(NmpcConvergence, ExactHessianSqpConvergesSuperlinearly) {
  bool converged = false;
  const std::vector<double> d = step_norms<HessianKind::exact>(&converged);
  ASSERT_TRUE(converged);
  ASSERT_GE(d.size(), 3u);
  for (std::size_t i = 0; i < d.size(); ++i)
    printf("exact: |d_%zu| = %.3e%s\n", i, d[i],
           i > 0 && d[i - 1] > 0 ? (" ratio " + std::to_string(d[i] / d[i - 1])).c_str() : "");
  // the last steps above round-off: each ratio |d_{k+1}| / |d_k| far below the previous one
  std::vector<double> r;
  for (std::size_t i = 1; i < d.size(); ++i)
    if (d[i] > 1e-9 && d[i - 1] > 1e-9)
      r.push_back(d[i] / d[i - 1]);
  ASSERT_GE(r.size(), 1u);
  EXPECT_LT(r.back(), 0.05);
  // q-superlinear: |d_{k+1}| / |d_k|^2 stays bounded (quadratic) in the last steps
  for (std::size_t i = d.size() - 2; i + 1 < d.size(); ++i)
    if (d[i] > 1e-9 && d[i + 1] > 1e-12) {
      EXPECT_LT(d[i + 1] / (d[i] * d[i]), 1e3) << "step " << i;
    }
}

TEST(NmpcConvergence, ScqpConvergesOnThePendulum) {
  bool converged = false;
  const std::vector<double> d = step_norms<HessianKind::gauss_newton>(&converged);
  EXPECT_TRUE(converged);
  for (std::size_t i = 0; i < d.size(); ++i)
    printf("scqp: |d_%zu| = %.3e\n", i, d[i]);
  EXPECT_LE(d.size(), 15u);
}

// ---- real-time iteration ------------------------------------------------------------------------
/// shift() moves the plan one stage; the multipliers stay where they are by default (the next
/// QP's warm start is the last solution's working set stage by stage) and move with the plan when
/// settings().shift_multipliers is set. (Keeping them took the contour closed loop from a median
/// of 14 QP iterations per sample to 4: settings.hpp, bench/nmpc/RESULTS.md.) The swing-up from
/// rest with |omega| <= 1 and |u| <= u_max leaves constraint and bound multipliers nonzero on
/// some stages and zero on others, so that a shifted and an unshifted copy differ.
TEST(NmpcRealTime, ShiftMovesThePlanAndKeepsOrMovesTheMultipliers) {
  static auto p = constrained_pendulum(omega_max());
  using Ctrl = arbor::nmpc::Nmpc<decltype(p)>;
  static Ctrl ctrl(p);
  const Eigen::Vector2d x0(0, 0);
  for (const bool move : {false, true}) {
    ASSERT_EQ(ctrl.set_initial_guess(x0, U1::Zero()), NmpcStatus::accepted);
    ctrl.settings().shift_multipliers = move;
    NmpcStatus st;
    {
      arbor::test::NoAllocScope guard;
      st = ctrl.solve(x0);
    }
    ASSERT_EQ(st, NmpcStatus::converged);
    std::vector<Eigen::Vector2d> xs, lam_dyn, lam_xb;
    std::vector<double> us, lam_g, lam_ub;
    for (int k = 0; k <= N; ++k) {
      xs.push_back(ctrl.state(k));
      lam_xb.push_back(ctrl.state_bound_multiplier(k));
    }
    for (int k = 0; k < N; ++k) {
      us.push_back(ctrl.input(k)[0]);
      lam_dyn.push_back(ctrl.dynamics_multiplier(k));
      lam_g.push_back(ctrl.constraint_multiplier(k)[0]);
      lam_ub.push_back(ctrl.input_bound_multiplier(k)[0]);
    }
    // the multipliers differ between neighbouring stages (else the test could not tell)
    int differ = 0;
    for (int k = 0; k + 1 < N; ++k)
      differ += (lam_g[std::size_t(k)] != 0) != (lam_g[std::size_t(k + 1)] != 0) ? 1 : 0;
    ASSERT_GE(differ, 1) << "the velocity constraint must be active on some stages only";
    bool input_bound_active = false;
    for (double l : lam_ub)
      input_bound_active = input_bound_active || l != 0;
    ASSERT_TRUE(input_bound_active) << "the test needs an active input bound";
    {
      arbor::test::NoAllocScope guard;
      ctrl.shift();
    }
    for (int k = 0; k < N; ++k) {
      const std::size_t i = std::size_t(k), j = std::size_t(move ? k + 1 : k);
      EXPECT_EQ(ctrl.state(k), xs[i + 1]) << "stage " << k;
      if (k + 1 < N) {
        EXPECT_EQ(ctrl.input(k)[0], us[i + 1]) << "stage " << k;
        EXPECT_EQ(ctrl.dynamics_multiplier(k), lam_dyn[j]) << "stage " << k << " move " << move;
        EXPECT_EQ(ctrl.constraint_multiplier(k)[0], lam_g[j]) << "stage " << k << " move " << move;
        EXPECT_EQ(ctrl.input_bound_multiplier(k)[0], lam_ub[j]) << "stage " << k;
        EXPECT_EQ(ctrl.state_bound_multiplier(k), lam_xb[j]) << "stage " << k;
      }
    }
    EXPECT_EQ(ctrl.input(N - 1)[0], us[N - 1]);  // the last input repeats
  }
  ctrl.settings().shift_multipliers = false;
}

/// Closed loop: one full solve, then prepare / measure / feedback / apply / shift per sample.
/// A twin controller without the presolved feedback (settings().presolve_feedback) sees the same
/// measurements: the same statuses, QP iterations and, to round-off, controls.
template <class Scalar>
void closed_loop() {
  static auto p = nmpc_test::pendulum_problem<N>();
  using Ctrl = arbor::nmpc::Nmpc<decltype(p), Scalar>;
  static Ctrl ctrl(p), twin(p);
  ctrl.settings().qp.max_iter = 5000;  // the first, cold QP from a constant guess
  ctrl.settings().presolve_feedback = true;
  twin.settings().qp.max_iter = 5000;
  twin.settings().presolve_feedback = false;
  using Vu = typename Ctrl::Vu;
  Eigen::Vector2d x(M_PI - 0.3, 0.2);  // the plant's state
  ASSERT_EQ(ctrl.set_initial_guess(Eigen::Vector2d(M_PI, 0).cast<Scalar>(), Vu::Zero()),
            NmpcStatus::accepted);
  ASSERT_EQ(twin.set_initial_guess(Eigen::Vector2d(M_PI, 0).cast<Scalar>(), Vu::Zero()),
            NmpcStatus::accepted);
  NmpcStatus st;
  {
    arbor::test::NoAllocScope guard;
    st = ctrl.solve(x.cast<Scalar>());
  }
  ASSERT_EQ(st, NmpcStatus::converged) << ctrl.info().qp_status << " it " << ctrl.info().iterations;
  ASSERT_EQ(twin.solve(x.cast<Scalar>()), NmpcStatus::converged);
  const double tol = std::is_same_v<Scalar, float> ? 1e-5 : 1e-10;
  int presolved = 0;
  for (int t = 0; t < 80; ++t) {
    NmpcStatus prep, fb;
    Vu before;
    {
      arbor::test::NoAllocScope guard;
      ctrl.shift();
      prep = ctrl.prepare();  // before the measurement
      before = ctrl.input(0);
      fb = ctrl.feedback(x.cast<Scalar>());  // after it
    }
    presolved += ctrl.qp_solver().info().presolved;
    twin.shift();
    ASSERT_EQ(twin.prepare(), NmpcStatus::prepared);
    ASSERT_EQ(twin.feedback(x.cast<Scalar>()), fb) << "sample " << t;
    EXPECT_FALSE(twin.qp_solver().info().presolved);
    EXPECT_EQ(twin.info().qp_iterations, ctrl.info().qp_iterations) << "sample " << t;
    EXPECT_LE(
        (twin.control() - ctrl.control()).cwiseAbs().maxCoeff(),
        (std::is_same_v<Scalar, float> ? 1e-4 : 1e-9) * (1 + std::fabs(double(ctrl.control()[0]))))
        << "sample " << t;
    ASSERT_EQ(prep, NmpcStatus::prepared) << "sample " << t;
    ASSERT_EQ(fb, NmpcStatus::step_taken) << "sample " << t;
    const Vu u = ctrl.control();
    ASSERT_TRUE(u.allFinite());
    // the control is the prepared plan's u_0 plus the feedback QP's first input step
    EXPECT_LT((u - before - ctrl.qp_solver().input(0).template head<1>()).cwiseAbs().maxCoeff(),
              tol);
    EXPECT_LE(std::fabs(double(u[0])), PendulumData::u_max * (1 + tol)) << "sample " << t;
    // plant: RK4 with 10 steps per sample, plain code
    x = nmpc_test::rk4_plain(
        [](const Eigen::Vector2d& y, double v) { return nmpc_test::pendulum_ode(y, v); }, x,
        double(u[0]), PendulumData::h, 10);
  }
  EXPECT_NEAR(x[0], M_PI, 0.02);
  EXPECT_NEAR(x[1], 0.0, 0.05);
  // most feedbacks took the presolved step (a first iteration that drops a wrong-sign multiplier
  // computes its step as usual: 79 of 80 in float with Clang -O1, 80 with GCC -O3)
  EXPECT_GE(presolved, 72);
}

TEST(NmpcRealTime, ClosedLoopStabilisesDouble) {
  closed_loop<double>();
}
TEST(NmpcRealTime, ClosedLoopStabilisesFloat) {
  closed_loop<float>();
}

}  // namespace
