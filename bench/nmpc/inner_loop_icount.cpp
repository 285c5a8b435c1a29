// Instructions of the feedback gain and of the torque-rate inner loop (issue 59 items 1, 2), by
// callgrind (bench/nmpc/inner_loop_icount.sh runs it and summarises):
//   demo:  the demo's closed loop (examples/contour's ContourLoop, OCP-FD, analytical, hard
//          tunnel, double, its default configuration: feedback bounded to 2 QP iterations, argv[1]
//          otherwise) with, after each sample, the controller's
//          stage-0 gain (Nmpc::feedback_gain) and 20 inner-loop calls (InnerLoop<double, 16, 8, 7>
//          at t = 1..20 ms on the measured state, a disturbance estimate moving): per sample six
//          dumps [gap, preparation, feedback, tail, gain, 20 calls];
//   calls: 1000 calls of InnerLoop::control per variant (Kinova sizes nx = 16, nu = 8, ND = 7 in
//          double and float; the 2-DoF arm's nx = 4, nu = 2, ND = 2; nx = 12, nu = 6, ND = 6),
//          one dump per variant.
// Without valgrind it runs and counts nothing.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "arbor/nmpc/inner_loop.hpp"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#define CALLGRIND_DUMP_STATS
#endif

#ifdef INNER_LOOP_DEMO
#include "closed_loop.hpp"
#endif

namespace {

template <class Scalar, int NX, int NU, int ND>
void calls(const char* name) {
  using Loop = arbor::nmpc::InnerLoop<Scalar, NX, NU, ND>;
  static Loop loop;
  typename Loop::Gain k;
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
  (void)loop.start(u0, x0, x1, Scalar(0.02), lb, ub, arbor::nmpc::NmpcStatus::accepted, k, &d0);
  volatile Scalar sink = 0;
  typename Loop::Vx x = x0;
  typename Loop::Vd d = d0;
  CALLGRIND_DUMP_STATS;
  for (int c = 0; c < 1000; ++c) {
    x(c % NX) += Scalar(1e-4);
    if constexpr (ND > 0)
      d(c % ND) += Scalar(1e-3);
    const typename Loop::Vu u = loop.control(Scalar(0.001) * Scalar(c % 20 + 1), x, d);
    sink = sink + u(c % NU);
  }
  CALLGRIND_DUMP_STATS;
  std::printf("%s: sink %g\n", name, double(sink));
}

#ifdef INNER_LOOP_DEMO
/// A ContourLoop Timer whose time stamps are callgrind dumps (contour_icount.cpp's).
struct CallgrindTimer {
  using Stamp = int;
  static Stamp now() {
    CALLGRIND_DUMP_STATS;
    return 0;
  }
  static double elapsed(Stamp, Stamp) { return 0; }
};
using Loop = contour::ContourLoop<contour::Formulation::fd, arbor::ad::Analytical, false, double,
                                  CallgrindTimer>;

int demo(int feedback_iter) {
  contour::Options o;
  o.feedback_qp_iter = feedback_iter;  // the demo's default: 2 (contour_icount.sh's FEEDBACK_ITER)
  const auto loop = std::make_unique<Loop>(o);
  if (loop->start() != arbor::nmpc::NmpcStatus::converged)
    return 1;
  auto& ctrl = loop->controller();
  constexpr int nx = Loop::Controller::nx, nu = Loop::Controller::nu;
  using Inner = arbor::nmpc::InnerLoop<double, nx, nu, 7>;
  static Inner inner;
  const typename Inner::Vu lb = Inner::Vu::Constant(-1e3), ub = Inner::Vu::Constant(1e3);
  Eigen::Matrix<double, nu, nx> k;
  volatile double sink = 0;
  int n = 0, with_gain = 0;
  CALLGRIND_START_INSTRUMENTATION;
  contour::Record r;
  while (!loop->done()) {
    loop->sample(r);
    ++n;
    CALLGRIND_DUMP_STATS;  // the tail of sample()
    const arbor::nmpc::NmpcStatus gs = ctrl.feedback_gain(0, k);
    CALLGRIND_DUMP_STATS;  // the gain
    with_gain += gs == arbor::nmpc::NmpcStatus::accepted;
    typename Inner::Vd d = r.d_hat.head<7>();
    (void)inner.start(ctrl.control(), ctrl.state(0), ctrl.state(1), contour::h, lb, ub, gs, k, &d);
    typename Inner::Vx x = r.x;
    for (int j = 1; j <= 20; ++j) {
      x(j % nx) += 1e-4;
      d(j % 7) += 1e-3;
      const typename Inner::Vu u = inner.control(1e-3 * j, x, d);
      sink = sink + u(j % nu);
    }
    CALLGRIND_DUMP_STATS;  // 20 inner-loop calls
  }
  std::printf("samples %d with gain %d sink %g\n", n, with_gain, double(sink));
  return with_gain == n ? 0 : 2;
}
#endif

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "calls") == 0) {
    CALLGRIND_START_INSTRUMENTATION;
    calls<double, 16, 8, 7>("double 16 8 7");
    calls<float, 16, 8, 7>("float 16 8 7");
    calls<double, 4, 2, 2>("double 4 2 2");
    calls<double, 12, 6, 6>("double 12 6 6");
    return 0;
  }
#ifdef INNER_LOOP_DEMO
  return demo(argc > 1 ? std::atoi(argv[1]) : 2);
#else
  std::fprintf(stderr, "demo mode needs the Kinova robot (examples/contour)\n");
  return 1;
#endif
}
