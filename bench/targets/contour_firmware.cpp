// A firmware-sized image with only the contour NMPC of examples/contour (Kinova Gen3, OCP-FD or
// OCP-ID by CONTOUR_FW_ID, analytical RBD derivatives, hard tunnel) in the scalar
// CONTOUR_FW_SCALAR (stages from generated code with CONTOUR_GENERATED_STAGE=1; its constants are
// the definition's, this image's reference is a stand-in: sizes only): RBD workspace, problem and
// controller in static storage; main runs one real-time-iteration sample (prepare, then feedback
// on a state read from volatile memory), to measure flash, static RAM (arm-none-eabi-size) and
// the stack of that sample (painted stack).
// Nothing else (no plant, no test harness, no printf). Results: bench/nmpc/contour_targets.sh.
#include <cstdint>

#include "arbor/nmpc/controller.hpp"
#include "arbor_target.h"
#include "task.hpp"

using namespace contour;
using S = CONTOUR_FW_SCALAR;
constexpr Formulation kForm = CONTOUR_FW_ID ? Formulation::id : Formulation::fd;
using W = Workspace<arbor::ad::Analytical, S>;
using ExprProblem =
    decltype(make_problem<kForm, arbor::ad::Analytical, false>(std::declval<W&>(), Reference{}));
#if CONTOUR_GENERATED_STAGE  // the stages from generated code (ARBOR_CONTOUR_GENERATED_STAGE)
#include "contour_stages_ad.hpp"
using Problem = arbor::ocp::WithGeneratedStage<ExprProblem, StageDefinition<kForm, false, S>>;
#else
using Problem = ExprProblem;
#endif
using Controller = arbor::nmpc::Nmpc<Problem, S>;

volatile S g_state[nx];  // the measured state (volatile: nothing is folded away)
W g_ws;

int main() {
  Reference ref;  // the task's reference, from constants (make_reference needs the plant's Data)
  ref.c = 0.2;
  for (int i = 0; i < 9; ++i)
    ref.R0[std::size_t(i)] = (i % 4 == 0) ? 1.0 : 0.0;
  // (the controller keeps its own copy of the problem: built in place, not kept twice)
  static Controller ctrl(Problem(make_problem<kForm, arbor::ad::Analytical, false>(g_ws, ref)));
  Controller::Vx x;
  for (int i = 0; i < nx; ++i)
    x[i] = g_state[i];
  (void)ctrl.set_initial_guess(x, Controller::Vu::Zero());
  arbor_paint_stack();
  const std::uint32_t base = arbor_stack_high_water();
  arbor::nmpc::NmpcStatus st = ctrl.prepare();
  if (st == arbor::nmpc::NmpcStatus::prepared)
    st = ctrl.feedback(x);
  const std::uint32_t stack = arbor_stack_high_water() - base;
  char buf[16];
  int n = 15;
  buf[n] = 0;
  std::uint32_t v = stack;
  do {
    buf[--n] = char('0' + v % 10);
    v /= 10;
  } while (v);
  arbor_puts("FIRMWARE stack ");
  arbor_puts(buf + n);
  arbor_puts("\n");
  return ctrl.control().allFinite() ? 0 : 1;
}
