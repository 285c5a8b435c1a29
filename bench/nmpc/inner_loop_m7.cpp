// Instructions per call on the Cortex-M7 (QEMU MPS2 AN500, -icount shift=0; SysTick counts
// calibrated by bench/targets/bench_util.hpp) of InnerLoop::control (Kinova sizes nx = 16,
// nu = 8, ND = 7 in double and float; nx = 12, nu = 6, ND = 6 in double) and of the QP's
// stage-0 and stage-1 feedback gains (qp::OcpQpSolver::feedback_gain) on the Kinova-sized QP of
// bench/qp/kinova_qp.hpp (N = 16, nx = 16, nu = 8, OCP-FD, x_0 fixed), double and float.
// Built and run by bench/nmpc/inner_loop_m7.sh. Output lines (bench_util.hpp's Measure):
//   BENCH <what> <scalar> <algorithm> <instructions/call> <stack bytes/call>
#include "arbor/nmpc/inner_loop.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "arbor_target.h"
#include "bench_util.hpp"
#include "kinova_qp.hpp"

namespace {

template <class Scalar, int NX, int NU, int ND>
void inner(const char* what, const char* scalar) {
  using Loop = arbor::nmpc::InnerLoop<Scalar, NX, NU, ND>;
  static Loop loop;
  static typename Loop::Gain k;
  for (int i = 0; i < NU; ++i)
    for (int j = 0; j < NX; ++j)
      k(i, j) = Scalar(0.01 * ((i * 7 + j * 3) % 11) - 0.05);
  typename Loop::Vx x0, x1;
  for (int j = 0; j < NX; ++j) {
    x0(j) = Scalar(0.1 * j);
    x1(j) = Scalar(0.1 * j + 0.01);
  }
  const typename Loop::Vu u0 = Loop::Vu::Constant(Scalar(0.5));
  const typename Loop::Vu lb = Loop::Vu::Constant(Scalar(-1)), ub = Loop::Vu::Constant(Scalar(1));
  const typename Loop::Vd d0 = Loop::Vd::Zero();
  if (loop.start(u0, x0, x1, Scalar(0.02), lb, ub, arbor::nmpc::NmpcStatus::accepted, k, &d0) !=
      arbor::nmpc::NmpcStatus::accepted)
    ++arbor::bench::failure_count();
  static typename Loop::Vx x;
  static typename Loop::Vd d;
  static typename Loop::Vu u;
  x = x0;
  d = d0;
  int c = 0;
  arbor::bench::Measure m(what, scalar);
  m.run("inner_loop_control", [&] {
    x(c % NX) += Scalar(1e-4);
    if constexpr (ND > 0)
      d(c % ND) += Scalar(1e-3);
    u = loop.control(Scalar(0.001) * Scalar(c % 20 + 1), x, d);
    ++c;
    __asm volatile("" : : "r"(u.data()) : "memory");
  });
}

template <typename Qp>
void gain(const char* scalar) {
  static Qp qp;
  static arbor::qp::OcpQpSolver<Qp> solver;
  arbor::bench::make_kinova_qp(qp, 1);
  using Scalar = typename decltype(qp.terminal.q)::Scalar;
  arbor::qp::QpSettings<Scalar> settings;
  settings.max_iter = 1000;
  if (solver.setup(qp, settings) != arbor::qp::QpStatus::accepted)
    ++arbor::bench::failure_count();
  solver.cold_start();
  if (solver.solve() != arbor::qp::QpStatus::solved)
    ++arbor::bench::failure_count();
  static Eigen::Matrix<Scalar, Qp::nu, Qp::nx> k;
  bool ok = true;
  arbor::bench::Measure m("kinova_qp", scalar);
  m.run("feedback_gain_stage0", [&] {
    ok = ok && solver.feedback_gain(0, k);
    __asm volatile("" : : "r"(k.data()) : "memory");
  });
  m.run("feedback_gain_stage1", [&] {
    ok = ok && solver.feedback_gain(1, k);
    __asm volatile("" : : "r"(k.data()) : "memory");
  });
  if (!ok)
    ++arbor::bench::failure_count();
}

}  // namespace

int main() {
  arbor::bench::calibrate();
  inner<double, 16, 8, 7>("kinova_16_8_7", "double");
  inner<float, 16, 8, 7>("kinova_16_8_7", "float");
  inner<double, 12, 6, 6>("size_12_6_6", "double");
  gain<arbor::bench::KinovaQp<double, 1>>("double");
  gain<arbor::bench::KinovaQp<float, 1>>("float");
  return arbor::bench::failures();
}
