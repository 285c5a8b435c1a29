// The Kinova-sized NMPC QP (N = 16, nx = 16, nu = 8; OCP-FD with one path row per stage, OCP-ID
// with 8) solved on a bare-metal target: instructions of a cold and of a warm-started solve
// (SysTick under -icount shift=0), iterations, status, solver size and stack. The problems come
// from bench/qp/kinova_qp.hpp, as in the host benchmark. Output lines:
//   QPBENCH <variant> <cold instructions> <cold iterations> <cold status>
//           <warm instructions> <warm iterations> <warm status> <solver bytes> <stack bytes>
//           <update instructions> <update iterations> <update status>
// (warm: setup(perturbed) + solve from the nominal solution; update: the real-time path, the
// bound problem refilled with the perturbed data, update(Convexity::assumed) + solve, as
// bench/qp/qp_count.cpp's warm_update_assumed).
#include "arbor/qp/ocp_qp_solver.hpp"
#include "arbor_target.h"
#include "bench_util.hpp"
#include "kinova_qp.hpp"

namespace {

using arbor::bench::KinovaQp;
using arbor::bench::put;

template <typename Qp>
void run(const char* name) {
  static Qp nominal, perturbed;
  static arbor::qp::OcpQpSolver<Qp> solver;
  arbor::bench::make_kinova_qp(nominal, 1);
  arbor::bench::make_kinova_qp(perturbed, 1, 1e-3, 0.01);
  using Scalar = typename decltype(nominal.terminal.q)::Scalar;
  arbor::qp::QpSettings<Scalar> settings;
  settings.max_iter = 1000;
  const std::uint64_t ipt = arbor::bench::insn_per_tick();

  const std::uint64_t t0 = arbor_ticks();
  const arbor::qp::QpStatus cold_setup = solver.setup(nominal, settings);
  solver.cold_start();
  const arbor::qp::QpStatus cold = solver.solve();
  const std::uint64_t t1 = arbor_ticks();
  const int cold_it = solver.info().iterations;

  arbor_paint_stack();
  const std::uint32_t base = arbor_stack_high_water();
  const std::uint64_t t2 = arbor_ticks();
  const arbor::qp::QpStatus warm_setup = solver.setup(perturbed, settings);
  const arbor::qp::QpStatus warm = solver.solve();
  const std::uint64_t t3 = arbor_ticks();
  const std::uint32_t stack = arbor_stack_high_water() - base;

  put("QPBENCH ");
  put(name);
  put(" ");
  put((t1 - t0) * ipt);
  put(" ");
  put(std::uint64_t(cold_it));
  put(" ");
  put(arbor::qp::to_string(cold));
  put(" ");
  put((t3 - t2) * ipt);
  put(" ");
  put(std::uint64_t(solver.info().iterations));
  put(" ");
  put(arbor::qp::to_string(warm));
  put(" ");
  put(std::uint64_t(sizeof(solver)));
  put(" ");
  put(std::uint64_t(stack));

  // the real-time path: the bound problem refilled with the perturbed data, then
  // update(Convexity::assumed) and the warm-started solve (from the nominal solution again)
  const arbor::qp::QpStatus rt_setup = solver.setup(nominal, settings);
  solver.cold_start();
  const arbor::qp::QpStatus rt_cold = solver.solve();
  nominal = perturbed;
  const std::uint64_t t4 = arbor_ticks();
  const arbor::qp::QpStatus rt_update = solver.update(arbor::qp::Convexity::assumed);
  const arbor::qp::QpStatus rt = solver.solve();
  const std::uint64_t t5 = arbor_ticks();
  put(" ");
  put((t5 - t4) * ipt);
  put(" ");
  put(std::uint64_t(solver.info().iterations));
  put(" ");
  put(arbor::qp::to_string(rt));
  put("\n");
  if (cold_setup != arbor::qp::QpStatus::accepted || warm_setup != arbor::qp::QpStatus::accepted ||
      warm != arbor::qp::QpStatus::solved || rt_setup != arbor::qp::QpStatus::accepted ||
      rt_cold != arbor::qp::QpStatus::solved || rt_update != arbor::qp::QpStatus::accepted ||
      rt != arbor::qp::QpStatus::solved)
    ++arbor::bench::failure_count();
}

}  // namespace

int main() {
  arbor::bench::calibrate();
#if ARBOR_BENCH_DOUBLE
  run<KinovaQp<double, 1>>("fd_double");
  run<KinovaQp<double, 8>>("id_double");
#endif
  run<KinovaQp<float, 1>>("fd_float");
  run<KinovaQp<float, 8>>("id_float");
  return arbor::bench::failures();
}
