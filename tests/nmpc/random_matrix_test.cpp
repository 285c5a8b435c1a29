// The NMPC on random robots (tests/dynamics/random_robot.hpp: chains and branches, every joint
// kind) with the end-effector task of random_task.hpp, at the sizes of the size matrix (nv = 1,
// 7 (nx = 14, nu = 7: the QP of issue 35's -march=native crash), 12), built at the tests' flags
// and, for the crash sizes in double, at -O3 -march=native (tests/nmpc/CMakeLists.txt), in three
// parts (ARBOR_MATRIX_PART, below):
//   - the Gauss-Newton SCQP and the exact-Hessian SQP, from the same guess, converge to the same
//     optimum (same local minimiser: the plans agree to the tolerance of the scalar);
//   - a real-time-iteration closed loop against a plant simulated here (arbor's aba, RK4 at a
//     quarter of the controller's step), with a large jump of the measured state in the middle
//     (shoulder +0.5 rad): every control finite, the plant's state finite, and the loop back in
//     the tunnel at the end; the controller in double and in float (plant in double).
// Everything runs under the allocation guard (on bare metal: a link without a heap).
#include <cmath>

#include "arbor/dynamics/aba.hpp"
#include "arbor/nmpc/controller.hpp"
#include "arbor_test.hpp"
#include "isa.hpp"
#include "random_robot.hpp"
#include "random_task.hpp"
#include "status_names.hpp"
#include "test_log.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}
namespace arbor::qp {
using ::arbor::test::status_names::operator<<;
}

namespace {
namespace ad = arbor::ad;
namespace nmpc = arbor::nmpc;
using arbor::nmpc::NmpcStatus;
using arbor::ocp::HessianKind;

template <class R, int N>
using TaskOf = nmpc_test::RandomTask<R, R::nb - 1, N>;

/// GN and exact Hessian from the same guess: both converge, to the same optimum (the same cost,
/// to the scalar's accuracy; the same plan to plan_tol relative to its size: the torques of these
/// tasks are weakly determined, weight 1e-3, so points that meet the NLP tolerances differ there
/// by ~1e-5 relative in double). With exact_steps, the exact SQP must take exact-Hessian steps
/// (fewer Gauss-Newton fallbacks than iterations): else both ran Gauss-Newton and the comparison
/// shows nothing. (At nv = 7, N = 20 every exact QP is non-convex for the square-root Riccati
/// recursion, which needs each stage's cost-to-go P_k positive definite, and falls back: issue 35's
/// finding, left to a later issue.)
template <class R, int N, class T>
[[gnu::noinline]] void gauss_newton_matches_exact(bool exact_steps, double plan_tol) {
  using Task = TaskOf<R, N>;
  constexpr int nx = Task::nx, nu = Task::nu;
  SCOPED_TRACE(::testing::Message() << "nv=" << R::nv << " N=" << N << " scalar="
                                    << (std::is_same_v<T, float> ? "float" : "double"));
  static typename Task::template Workspace<ad::Analytical, T, false> wg;
  static typename Task::template Workspace<ad::Analytical, T, true> we;
  static const auto pg = Task::template problem<ad::Analytical>(wg);
  static const auto pe = Task::template problem<ad::Analytical>(we);
  using Pg = std::remove_const_t<decltype(pg)>;
  using Pe = std::remove_const_t<decltype(pe)>;
  static nmpc::Nmpc<Pg, T, HessianKind::gauss_newton> gn(pg);
  static nmpc::Nmpc<Pe, T, HessianKind::exact> ex(pe);
  using Vx = Eigen::Matrix<T, nx, 1>;
  using Vu = Eigen::Matrix<T, nu, 1>;
  Vx x0 = Vx::Zero();
  x0.template head<R::nv>() = Task::q_start().template cast<T>();
  ASSERT_EQ(gn.set_initial_guess(x0, Vu::Zero()), NmpcStatus::accepted);
  ASSERT_EQ(ex.set_initial_guess(x0, Vu::Zero()), NmpcStatus::accepted);
  gn.settings().max_iter = 100;
  ex.settings().max_iter = 100;
  NmpcStatus sg, se;
  {
    arbor::test::NoAllocScope guard;
    sg = gn.solve(x0);
    se = ex.solve(x0);
  }
  EXPECT_EQ(sg, NmpcStatus::converged)
      << "GN: " << gn.info().iterations << " iterations, qp " << gn.info().qp_status;
  EXPECT_EQ(se, NmpcStatus::converged)
      << "exact: " << ex.info().iterations << " iterations, qp " << ex.info().qp_status;
  if (exact_steps) {
    EXPECT_LT(ex.info().hessian_fallbacks, ex.info().iterations) << "no exact-Hessian step";
  }
  // the same optimum: the cost at the converged points (merit: cost + penalty of violations)
  const double mg = gn.info().merit, me = ex.info().merit;
  EXPECT_LE(std::abs(mg - me), (std::is_same_v<T, float> ? 1e-3 : 1e-9) * std::abs(mg))
      << "costs differ: " << mg << " vs " << me;
  const double tol = plan_tol;
  double dx = 0, du = 0, sx = 1, su = 1;
  for (int k = 0; k <= N; ++k) {
    dx = std::max(dx, double((gn.state(k) - ex.state(k)).cwiseAbs().maxCoeff()));
    sx = std::max(sx, double(gn.state(k).cwiseAbs().maxCoeff()));
  }
  for (int k = 0; k < N; ++k) {
    du = std::max(du, double((gn.input(k) - ex.input(k)).cwiseAbs().maxCoeff()));
    su = std::max(su, double(gn.input(k).cwiseAbs().maxCoeff()));
  }
  EXPECT_LE(dx, tol * sx) << "states differ";
  EXPECT_LE(du, tol * su) << "inputs differ";
  arbor::test::log() << "  [" << (std::is_same_v<T, float> ? "float " : "double")
                     << "] nv=" << R::nv << " GN " << gn.info().iterations << " it, exact "
                     << ex.info().iterations << " it (" << ex.info().hessian_fallbacks
                     << " Gauss-Newton fallbacks): max |dx| " << dx << ", |du| " << du << "\n";
}

/// The plant: x+ = RK4 of [qd, aba(q, qd, tau)] over h in 4 substeps (double).
template <class R>
Eigen::Matrix<double, 2 * R::nv, 1> plant_step(const Eigen::Matrix<double, 2 * R::nv, 1>& x,
                                               const Eigen::Matrix<double, R::nv, 1>& tau,
                                               double h) {
  constexpr int n = R::nv;
  using X = Eigen::Matrix<double, 2 * n, 1>;
  static arbor::Data<R, double> d;
  const auto f = [&](const X& y) {
    X r;
    r.template head<n>() = y.template tail<n>();
    r.template tail<n>() =
        arbor::aba<R>(d, y.template head<n>().eval(), y.template tail<n>().eval(), tau);
    return r;
  };
  X y = x;
  const double s = h / 4;
  for (int i = 0; i < 4; ++i) {
    const X k1 = f(y), k2 = f(y + 0.5 * s * k1), k3 = f(y + 0.5 * s * k2), k4 = f(y + s * k3);
    y += s / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return y;
}

/// RTI closed loop with a jump of the measured state at sample 20 (shoulder + jump rad; 0.5: out
/// of the tunnel, which is soft by default so the QP stays feasible; Soft = false: the hard
/// tunnel of hard_tunnel_jump_status()'s controller, with a jump that stays feasible): every
/// sample's QP solved, controls and states finite, back in the tunnel at the end. bound > 0: the
/// feedback's QP is bounded to that many iterations (NmpcSettings::feedback_qp_iterations):
/// step_taken or step_limited, never more QP iterations, the controls within their bounds, back
/// in the tunnel 80 samples after the jump (40 without the bound; or after loop_samples - 20).
template <class R, int N, class T, bool Soft = true,
          arbor::ocp::Sensitivity Sens = arbor::ocp::Sensitivity::exact>
[[gnu::noinline]] void rti_closed_loop(int bound = 0, double jump_rad = 0.5, int loop_samples = 0,
                                       double input_regularization = 0) {
  using Task = TaskOf<R, N>;
  constexpr int nx = Task::nx, nu = Task::nu, n = R::nv;
  constexpr bool frozen = Sens == arbor::ocp::Sensitivity::frozen;
  SCOPED_TRACE(::testing::Message() << "nv=" << n << " N=" << N
                                    << " scalar=" << (std::is_same_v<T, float> ? "float" : "double")
                                    << " feedback bound " << bound << (frozen ? " frozen" : "")
                                    << " input regularization " << input_regularization);
  static typename Task::template Workspace<ad::Analytical, T, false> ws;
  static const auto p = Task::template problem<ad::Analytical, Soft, Sens>(ws);
  using P = std::remove_const_t<decltype(p)>;
  static nmpc::Nmpc<P, T> c(p);
  using Vu = Eigen::Matrix<T, nu, 1>;
  Eigen::Matrix<double, nx, 1> x = Eigen::Matrix<double, nx, 1>::Zero();
  x.template head<n>() = Task::q_start();
  ASSERT_EQ(c.set_initial_guess(x.template cast<T>(), Vu::Zero()), NmpcStatus::accepted);
  c.settings().max_iter = 100;
  c.settings().feedback_qp_iterations = bound;
  c.settings().input_regularization = T(input_regularization);
  {
    arbor::test::NoAllocScope guard;
    (void)c.solve(x.template cast<T>());  // a converged start, as a controller is started
  }
  // (a bounded feedback spreads the correction over more samples: on the Cortex-M4F the float
  // 7-DoF loop with K = 3 was 1.6 mm outside the tunnel 40 samples after the jump)
  const int samples = loop_samples > 0 ? loop_samples : bound > 0 ? 100 : 60;
  constexpr int jump = 20;
  int failed = 0, limited = 0;
  double worst_qd = 0;
  for (int s = 0; s < samples; ++s) {
    if (s == jump)
      x[0] += jump_rad;  // the measured state jumps (a push): the plan no longer starts there
    NmpcStatus sp, sf;
    {
      arbor::test::NoAllocScope guard;
      c.shift();
      sp = c.prepare();
      sf = c.feedback(x.template cast<T>());
    }
    ASSERT_EQ(sp, NmpcStatus::prepared) << "sample " << s;
    const bool ok = sf == NmpcStatus::step_taken || (bound > 0 && sf == NmpcStatus::step_limited);
    EXPECT_TRUE(ok) << "sample " << s << ": " << sf << ", qp " << c.info().qp_status << " after "
                    << c.info().qp_iterations << " iterations";
    failed += ok ? 0 : 1;
    limited += sf == NmpcStatus::step_limited ? 1 : 0;
    if (bound > 0) {
      EXPECT_LE(c.info().qp_iterations, bound) << "sample " << s;
    }
    const Vu u = c.control();
    ASSERT_TRUE(u.allFinite()) << "sample " << s;
    EXPECT_TRUE((u.array() >= p.lbu.template cast<T>().array()).all() &&
                (u.array() <= p.ubu.template cast<T>().array()).all())
        << "sample " << s;
    x = plant_step<R>(x, u.template cast<double>(), Task::h);
    ASSERT_TRUE(x.allFinite()) << "sample " << s;
    worst_qd = std::max(worst_qd, x.template tail<n>().cwiseAbs().maxCoeff());
  }
  const double excess = Task::tunnel_excess(x.template head<n>().eval());
  EXPECT_LE(excess, 1e-3) << "not back in the tunnel at the end";
  arbor::test::log() << "  [" << (std::is_same_v<T, float> ? "float " : "double") << "] nv=" << n
                     << " RTI (feedback bound " << bound << (frozen ? ", frozen sensitivities" : "")
                     << "): " << failed << " failed, " << limited
                     << " step_limited samples, max |qd| " << worst_qd
                     << ", tunnel excess at the end " << excess << "\n";
}

/// The hard tunnel and a jump of the measured state 2 cm or more outside it (one joint moved):
/// the Gauss-Newton QP is convex by construction, so in double and in float it must be solved
/// (the controller steers back from stage 1 on) or proved infeasible, never `non_convex` or
/// `stalled` (issue 35: a float QP said non_convex after one iteration, from a factorization
/// that round-off broke, then stalled). Returns the QP status of the jump sample.
template <class R, int N, class T>
[[gnu::noinline]] arbor::qp::QpStatus hard_tunnel_jump_status() {
  using Task = TaskOf<R, N>;
  constexpr int nx = Task::nx, nu = Task::nu, n = R::nv;
  static typename Task::template Workspace<ad::Analytical, T, false> ws;
  static const auto p = Task::template problem<ad::Analytical, false>(ws);
  using P = std::remove_const_t<decltype(p)>;
  static nmpc::Nmpc<P, T> c(p);
  using Vu = Eigen::Matrix<T, nu, 1>;
  Eigen::Matrix<double, nx, 1> x = Eigen::Matrix<double, nx, 1>::Zero();
  x.template head<n>() = Task::q_start();
  EXPECT_EQ(c.set_initial_guess(x.template cast<T>(), Vu::Zero()), NmpcStatus::accepted);
  c.settings().max_iter = 100;
  NmpcStatus sp[6], sf[6];
  {
    arbor::test::NoAllocScope guard;
    (void)c.solve(x.template cast<T>());
    for (int s = 0; s < 5; ++s) {
      c.shift();
      sp[s] = c.prepare();
      sf[s] = c.feedback(x.template cast<T>());
      x = plant_step<R>(x, c.control().template cast<double>(), Task::h);
    }
  }
  for (int s = 0; s < 5; ++s) {
    EXPECT_EQ(sp[s], NmpcStatus::prepared) << "sample " << s;
    EXPECT_EQ(sf[s], NmpcStatus::step_taken) << "sample " << s;
  }
  // the jump: the first joint (then the next ones) moved until the end effector is 2 cm outside
  Eigen::Matrix<double, nx, 1> xj = x;
  for (int j = 0; j < n && Task::tunnel_excess(xj.template head<n>().eval()) < 0.02; ++j) {
    xj = x;
    for (double a = 0.5; a <= 3.0 && Task::tunnel_excess(xj.template head<n>().eval()) < 0.02;
         a += 0.5)
      xj[j] = x[j] + a;
  }
  const double excess = Task::tunnel_excess(xj.template head<n>().eval());
  EXPECT_GT(excess, 0.02) << "no jump of one joint leaves the tunnel";
  {
    arbor::test::NoAllocScope guard;
    c.shift();
    sp[5] = c.prepare();
    sf[5] = c.feedback(xj.template cast<T>());
  }
  EXPECT_EQ(sp[5], NmpcStatus::prepared);
  EXPECT_TRUE(sf[5] == NmpcStatus::step_taken || sf[5] == NmpcStatus::qp_failed) << sf[5];
  EXPECT_TRUE(c.control().allFinite());
  arbor::test::log() << "  [" << (std::is_same_v<T, float> ? "float " : "double") << "] nv=" << n
                     << " hard tunnel, state " << excess
                     << " m out of it: " << arbor::nmpc::to_string(sf[5]) << ", QP "
                     << arbor::qp::to_string(c.info().qp_status) << " after "
                     << c.info().qp_iterations << " iterations\n";
  return c.info().qp_status;
}

using R1 = arbor::test::RandomRobot<11, 1>;
using R7 = arbor::test::RandomRobot<17, 7>;
using R12 = arbor::test::RandomRobot<19, 12>;
using R3 = arbor::test::RandomRobot<13, 3>;

TEST(NmpcRandomMatrix, PrintsTheInstructionSet) {
  arbor::test::print_isa();
}

// Three units (compile memory: each controller type is ~0.6 GB of compiler memory and ~1 min of
// compiler time at -O1), ARBOR_MATRIX_PART: 1, double at the crash sizes (nx = 14, nu = 7, N = 20:
// GN vs exact Hessian, the hard tunnel out of reach); 2, the same in float and the RTI closed loop
// with a state jump in float (portable: also built for AArch64 (NEON) and the Cortex-M4F (no SIMD,
// a single-precision FPU), whose 4 MB of RAM hold these controllers); 3, GN vs exact-Hessian steps on
// 1 and 3 DoF and RTI closed loops with a state jump on 1 and 12 DoF in double.
#if ARBOR_MATRIX_PART == 1
#if !defined(ARBOR_MATRIX_NO_EXACT)  // (not in the -march=native variant: the suite's time)
TEST(NmpcRandomMatrix, GaussNewtonAndExactHessianAgree) {
  gauss_newton_matches_exact<R7, 20, double>(false, 1e-6);
}
#endif
TEST(NmpcRandomMatrix, HardTunnelAfterAJumpIsSolvedOrProvedInfeasible) {
  const auto st = hard_tunnel_jump_status<R7, 20, double>();
  EXPECT_TRUE(st == arbor::qp::QpStatus::solved || st == arbor::qp::QpStatus::infeasible) << st;
}
// The bounded feedback (issue 38) in this unit's builds (-O1 SSE2 and -O3 -march=native)
// on the same controller type (the hard tunnel), so no new instantiation: one QP iteration per
// sample (step_limited on nearly every sample), no jump.
TEST(NmpcRandomMatrix, BoundedFeedbackHardTunnelClosedLoop) {
  rti_closed_loop<R7, 20, double, false>(1, 0.0);
}
// With the hard tunnel, a jump of only 0.02-0.05 rad at sample 20 starts a period-2 oscillation of
// the joint velocities (|qd| alternating ~1.5 / ~3.5 rad/s) in the full (unbounded) RTI loop; it
// grows, the arm leaves the tunnel by up to 0.46 m 60 samples later and the controller falls back
// to the relaxed QP (issue 38's closing note, 2026-12-06; kept as the DISABLED reproduction). The
// proximal term on the inputs (NmpcSettings::input_regularization) damps it: the same loop stays
// in the tunnel (same controller type: no new instantiation).
TEST(NmpcRandomMatrix, HardTunnelRtiRecoversFromASmallJumpWithInputRegularization) {
  rti_closed_loop<R7, 20, double, false>(0, 0.02, 200, 1e-3);
  rti_closed_loop<R7, 20, double, false>(0, 0.05, 200, 1e-2);
}
TEST(NmpcRandomMatrix, DISABLED_HardTunnelRtiRecoversFromASmallJump) {
  rti_closed_loop<R7, 20, double, false>(0, 0.02, 200);
}
#elif ARBOR_MATRIX_PART == 2
// (not on the targets, ARBOR_MATRIX_NO_EXACT: the exact-Hessian controller's nested duals are
// half the unit's compile time there, and at these sizes it falls back to Gauss-Newton anyway)
#if !defined(ARBOR_MATRIX_NO_EXACT)
TEST(NmpcRandomMatrix, GaussNewtonAndExactHessianAgreeInFloat) {
  gauss_newton_matches_exact<R7, 20, float>(false, 2e-2);
}
#endif
#if !defined(ARBOR_MATRIX_NO_HARD_TUNNEL)
TEST(NmpcRandomMatrix, HardTunnelAfterAJumpIsSolvedOrProvedInfeasibleInFloat) {
  const auto st = hard_tunnel_jump_status<R7, 20, float>();
  EXPECT_TRUE(st == arbor::qp::QpStatus::solved || st == arbor::qp::QpStatus::infeasible) << st;
}
#endif
TEST(NmpcRandomMatrix, RtiClosedLoopRecoversFromAStateJumpInFloat) {
  rti_closed_loop<R7, 20, float>();
  rti_closed_loop<R7, 20, float>(3);  // the feedback bounded (issue 38)
}
#else
// Exact-Hessian steps on small robots (1 and 3 DoF, N = 6): GN and exact SQP reach the same optimum.
TEST(NmpcRandomMatrix, GaussNewtonAndExactNewtonStepsReachTheSameOptimum) {
  gauss_newton_matches_exact<R1, 6, double>(true, 1e-4);
  gauss_newton_matches_exact<R3, 6, double>(true, 1e-4);
}
TEST(NmpcRandomMatrix, RtiClosedLoopRecoversFromAStateJump) {
  rti_closed_loop<R1, 6, double>();
  rti_closed_loop<R12, 5, double>();
  rti_closed_loop<R1, 6, double>(2);  // the feedback bounded (issue 38)
  rti_closed_loop<R12, 5, double>(3);
  // RK4 with frozen sensitivities (ocp::Sensitivity::frozen: the dynamics' Jacobian inexact by
  // O(h^2), its residual exact): the same recovery on a 3-DoF robot
  rti_closed_loop<R3, 6, double, true, arbor::ocp::Sensitivity::frozen>();
}
#endif
}  // namespace
