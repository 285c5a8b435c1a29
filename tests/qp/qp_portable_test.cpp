// QP solvers on every target (host, AArch64, Cortex-M7, Cortex-M4F), in double and float (the
// Cortex-M7 in double, the Cortex-M4F in float), on problems whose solutions are derived by hand
// below; no reference solver, no files, no heap.
#include <cmath>
#include <limits>

#include "arbor/qp/dense_qp_solver.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "arbor_test.hpp"
#include "status_names.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {

using arbor::qp::DenseQpProblem;
using arbor::qp::DenseQpSolver;
using arbor::qp::OcpQp;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpStatus;

template <class S>
constexpr S inf() {
  return std::numeric_limits<S>::infinity();
}
template <class S>
constexpr double tol() {
  return sizeof(S) == 8 ? 1e-8 : 2e-4;
}

// CasADi issue 3141: min x s.t. 0 <= 2x + 1 <= 2, zero Hessian. The row's lower bound is the
// minimizer: 2x + 1 = 0, x = -0.5.
template <class S>
void casadi_3141() {
  using P = DenseQpProblem<S, 1, 1>;
  static P p;
  static DenseQpSolver<S, 1, 1> solver;
  p.H.setZero();
  p.g << S(1);
  p.A << S(2);
  p.lbx << -inf<S>();
  p.ubx << inf<S>();
  p.lba << S(-1);  // 0 <= 2x + 1 <= 2  <=>  -1 <= 2x <= 1
  p.uba << S(1);
  arbor::test::NoAllocScope guard;
  ASSERT_EQ(solver.setup(p), QpStatus::accepted);
  EXPECT_EQ(solver.solve(), QpStatus::solved);
  EXPECT_NEAR(solver.x()(0), -0.5, tol<S>());
}

// min 1/2 |x - c|^2 within a box: the solution is c clamped to the box.
template <class S>
void box_projection() {
  using P = DenseQpProblem<S, 3, 1>;
  static P p;
  static DenseQpSolver<S, 3, 1> solver;
  const S c[3] = {S(2), S(-3), S(0.25)};
  p.H.setIdentity();
  for (int i = 0; i < 3; ++i)
    p.g(i) = -c[i];
  p.A.setZero();
  p.lba << -inf<S>();
  p.uba << inf<S>();
  p.lbx.setConstant(S(-1));
  p.ubx.setConstant(S(1));
  arbor::test::NoAllocScope guard;
  ASSERT_EQ(solver.setup(p), QpStatus::accepted);
  EXPECT_EQ(solver.solve(), QpStatus::solved);
  EXPECT_NEAR(solver.x()(0), 1.0, tol<S>());
  EXPECT_NEAR(solver.x()(1), -1.0, tol<S>());
  EXPECT_NEAR(solver.x()(2), 0.25, tol<S>());
  // Multiplier signs give the active set: upper bound active (> 0), lower active (< 0).
  EXPECT_GT(solver.lam_x()(0), S(0));
  EXPECT_LT(solver.lam_x()(1), S(0));
  EXPECT_NEAR(solver.lam_x()(2), 0.0, tol<S>());
}

// min 1/2 |x|^2 s.t. x1 + x2 + x3 = 3: by symmetry x = (1, 1, 1).
template <class S>
void equality() {
  using P = DenseQpProblem<S, 3, 1>;
  static P p;
  static DenseQpSolver<S, 3, 1> solver;
  p.H.setIdentity();
  p.g.setZero();
  p.A.setOnes();
  p.lba << S(3);
  p.uba << S(3);
  p.lbx.setConstant(-inf<S>());
  p.ubx.setConstant(inf<S>());
  arbor::test::NoAllocScope guard;
  ASSERT_EQ(solver.setup(p), QpStatus::accepted);
  EXPECT_EQ(solver.solve(), QpStatus::solved);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(solver.x()(i), 1.0, tol<S>());
}

// LP: min -x1 - x2 s.t. x1 + 2 x2 <= 4, 3 x1 + x2 <= 6, x >= 0. Optimal vertex where both rows
// are active: x = (1.6, 1.2).
template <class S>
void linear_program() {
  using P = DenseQpProblem<S, 2, 2>;
  static P p;
  static DenseQpSolver<S, 2, 2> solver;
  p.H.setZero();
  p.g << S(-1), S(-1);
  p.A << S(1), S(2), S(3), S(1);
  p.lba.setConstant(-inf<S>());
  p.uba << S(4), S(6);
  p.lbx.setZero();
  p.ubx.setConstant(inf<S>());
  arbor::test::NoAllocScope guard;
  ASSERT_EQ(solver.setup(p), QpStatus::accepted);
  EXPECT_EQ(solver.solve(), QpStatus::solved);
  EXPECT_NEAR(solver.x()(0), 1.6, tol<S>());
  EXPECT_NEAR(solver.x()(1), 1.2, tol<S>());
}

// x1 + x2 >= 3 with x <= 1: infeasible, and must never be reported as solved.
template <class S>
void infeasible() {
  using P = DenseQpProblem<S, 2, 1>;
  static P p;
  static DenseQpSolver<S, 2, 1> solver;
  p.H.setIdentity();
  p.g.setZero();
  p.A.setOnes();
  p.lba << S(3);
  p.uba << inf<S>();
  p.lbx.setConstant(-inf<S>());
  p.ubx.setConstant(S(1));
  arbor::test::NoAllocScope guard;
  ASSERT_EQ(solver.setup(p), QpStatus::accepted);
  EXPECT_EQ(solver.solve(), QpStatus::infeasible);
}

template <class S>
void non_finite() {
  using P = DenseQpProblem<S, 2, 1>;
  static P p;
  static DenseQpSolver<S, 2, 1> solver;
  p.H.setIdentity();
  p.g << std::numeric_limits<S>::quiet_NaN(), S(0);
  p.A.setOnes();
  p.lba << S(0);
  p.uba << S(1);
  p.lbx.setConstant(S(-1));
  p.ubx.setConstant(S(1));
  arbor::test::NoAllocScope guard;
  EXPECT_EQ(solver.setup(p), QpStatus::non_finite);
}

// Stage-structured: x_{k+1} = x_k + u_k, x_0 = 1 (fixed by its bounds), N = 3,
// min sum_k u_k^2 + x_N^2 (R = 2, Q_N = 2 with the 1/2 factor). The gradient conditions give
// u_k = -x_N for every k and x_N = 1 + 3 u, so u = -1/4 and x_N = 1/4. With |u| <= 0.2 the
// bound is active at every stage: u = -0.2 and x_N = 0.4.
template <class S>
void fill_one_dimensional(OcpQp<S, 3, 1, 1, 0, 0>& qp, bool bounded) {
  for (auto& s : qp.stage) {
    s.Q.setZero();
    s.S.setZero();
    s.R << S(2);
    s.q.setZero();
    s.r.setZero();
    s.A << S(1);
    s.B << S(1);
    s.b.setZero();
    s.lbx << -inf<S>();
    s.ubx << inf<S>();
    s.lbu << (bounded ? S(-0.2) : -inf<S>());
    s.ubu << (bounded ? S(0.2) : inf<S>());
  }
  qp.stage[0].lbx << S(1);
  qp.stage[0].ubx << S(1);
  qp.terminal.Q << S(2);
  qp.terminal.q.setZero();
  qp.terminal.lbx << -inf<S>();
  qp.terminal.ubx << inf<S>();
}

template <class S>
void ocp_one_dimensional(bool bounded) {
  using Qp = OcpQp<S, 3, 1, 1, 0, 0>;
  static Qp qp;
  static OcpQpSolver<Qp> solver;
  fill_one_dimensional(qp, bounded);
  arbor::test::NoAllocScope guard;
  solver.cold_start();
  ASSERT_EQ(solver.setup(qp), QpStatus::accepted);
  EXPECT_EQ(solver.solve(), QpStatus::solved);
  const double u = bounded ? -0.2 : -0.25;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(solver.input(k)(0), u, tol<S>());
    EXPECT_NEAR(solver.state(k)(0), 1.0 + k * u, tol<S>());
  }
  EXPECT_NEAR(solver.state(3)(0), 1.0 + 3 * u, tol<S>());
}

// The real-time path on the same OCP: tighter input bounds |u| <= 0.1 through update() without
// the convexity check give u = -0.1, x = (1, 0.9, 0.8, 0.7); shift() moves that solution one
// stage (the last stage repeats); with x_0 = 0.9 (the plant followed the prediction) the
// unconstrained optimum u = -x_N, x_N = 0.9 + 3 u = 0.225 is again cut to u = -0.1:
// x = (0.9, 0.8, 0.7, 0.6).
template <class S>
void ocp_update_and_shift() {
  using Qp = OcpQp<S, 3, 1, 1, 0, 0>;
  static Qp qp;
  static OcpQpSolver<Qp> solver;
  fill_one_dimensional(qp, false);
  // the states add up the dynamics residuals of the stages before them: solve 10x tighter
  arbor::qp::QpSettings<S> settings;
  settings.tol_primal = settings.tol_dual = settings.tol_comp = S(tol<S>() / 10);
  arbor::test::NoAllocScope guard;
  ASSERT_EQ(solver.setup(qp, settings), QpStatus::accepted);
  solver.cold_start();
  ASSERT_EQ(solver.solve(), QpStatus::solved);
  EXPECT_NEAR(solver.input(0)(0), -0.25, tol<S>());
  for (auto& s : qp.stage) {
    s.lbu << S(-0.1);
    s.ubu << S(0.1);
  }
  ASSERT_EQ(solver.update(arbor::qp::Convexity::assumed), QpStatus::accepted);
  ASSERT_EQ(solver.solve(), QpStatus::solved);
  for (int k = 0; k <= 3; ++k)
    EXPECT_NEAR(solver.state(k)(0), 1.0 - 0.1 * k, tol<S>());
  solver.shift();
  EXPECT_NEAR(solver.state(0)(0), 0.9, tol<S>());
  EXPECT_NEAR(solver.state(2)(0), 0.7, tol<S>());
  EXPECT_NEAR(solver.state(3)(0), 0.7, tol<S>());  // the last stage repeats
  EXPECT_NEAR(solver.input(2)(0), -0.1, tol<S>());
  qp.stage[0].lbx << S(0.9);
  qp.stage[0].ubx << S(0.9);
  ASSERT_EQ(solver.update(arbor::qp::Convexity::assumed), QpStatus::accepted);
  ASSERT_EQ(solver.solve(), QpStatus::solved);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(solver.input(k)(0), -0.1, tol<S>());
  for (int k = 0; k <= 3; ++k)
    EXPECT_NEAR(solver.state(k)(0), 0.9 - 0.1 * k, tol<S>());
}

// The scalars of this build (ARBOR_TEST_DOUBLE, ARBOR_TEST_FLOAT: tests/CMakeLists.txt), each
// Cortex-M its FPU's precision.
#if ARBOR_TEST_DOUBLE
TEST(QpPortable, Casadi3141Double) {
  casadi_3141<double>();
}
TEST(QpPortable, BoxProjectionDouble) {
  box_projection<double>();
}
TEST(QpPortable, EqualityDouble) {
  equality<double>();
}
TEST(QpPortable, LinearProgramDouble) {
  linear_program<double>();
}
TEST(QpPortable, InfeasibleDouble) {
  infeasible<double>();
}
TEST(QpPortable, NonFiniteDouble) {
  non_finite<double>();
}
TEST(QpPortable, OcpUnconstrainedDouble) {
  ocp_one_dimensional<double>(false);
}
TEST(QpPortable, OcpInputBoundActiveDouble) {
  ocp_one_dimensional<double>(true);
}
TEST(QpPortable, OcpUpdateAndShiftDouble) {
  ocp_update_and_shift<double>();
}
#endif

#if ARBOR_TEST_FLOAT
TEST(QpPortable, Casadi3141Float) {
  casadi_3141<float>();
}
TEST(QpPortable, BoxProjectionFloat) {
  box_projection<float>();
}
TEST(QpPortable, EqualityFloat) {
  equality<float>();
}
TEST(QpPortable, LinearProgramFloat) {
  linear_program<float>();
}
TEST(QpPortable, InfeasibleFloat) {
  infeasible<float>();
}
TEST(QpPortable, NonFiniteFloat) {
  non_finite<float>();
}
TEST(QpPortable, OcpUnconstrainedFloat) {
  ocp_one_dimensional<float>(false);
}
TEST(QpPortable, OcpInputBoundActiveFloat) {
  ocp_one_dimensional<float>(true);
}
TEST(QpPortable, OcpUpdateAndShiftFloat) {
  ocp_update_and_shift<float>();
}
#endif

}  // namespace
