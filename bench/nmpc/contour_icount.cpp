// Deterministic timing of the demo's controller: instructions per real-time-iteration phase
// (preparation, feedback) of every sample of examples/contour's closed loop (OCP-FD, or OCP-ID
// with CONTOUR_ID=1; analytical RBD derivatives, hard tunnel, double) to s > 0.99, counted by
// callgrind (bench/nmpc/contour_icount.sh runs it and summarises). The loop is the example's own
// ContourLoop; its Timer dumps callgrind's counters at each of the three time stamps of a sample,
// so every dump holds exactly one phase's instructions: what a wall clock measures without the
// machine's noise (preemption, caches, frequency). Without valgrind it runs and counts nothing.
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "closed_loop.hpp"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_DUMP_STATS
#endif

#ifndef CONTOUR_ID
#define CONTOUR_ID 0
#endif

namespace {

/// A ContourLoop Timer whose time stamps are callgrind dumps (elapsed: 0; the counts are in the
/// dump files, in call order: [rest of the last sample, plant, shift], preparation, feedback).
struct CallgrindTimer {
  using Stamp = int;
  static Stamp now() {
    CALLGRIND_DUMP_STATS;
    return 0;
  }
  static double elapsed(Stamp, Stamp) { return 0; }
};

using namespace contour;
constexpr Formulation kForm = CONTOUR_ID ? Formulation::id : Formulation::fd;
using Loop = ContourLoop<kForm, arbor::ad::Analytical, false, double, CallgrindTimer>;

}  // namespace

int main(int argc, char** argv) {
  Options o;
  // The demo's configuration for disturbances (examples/contour/main.cpp): the torque-rate inner
  // loop, the observer at the plant's rate, the state filter 0.3 (the back-off is task.hpp's
  // default). They run between the phases (the plant's steps, the measurement), outside the
  // counted ones, but change the states the controller sees.
  o.inner_loop = true;
  o.observer = true;
  o.state_filter = 0.3;
  // [K] [--mismatch] [--noise SIGMA] [--no-presolve] [--former]: the feedback's bound on QP
  // iterations (NmpcSettings::feedback_qp_iterations; 0: none), the plant scenarios of
  // examples/contour (0.5 kg payload the controller does not know; measurement noise on q, 10x on
  // qd), the feedback computing its first step itself (NmpcSettings::presolve_feedback off; on by
  // default) and the former configuration (no inner loop, observer or filter)
  if (argc > 1)
    o.feedback_qp_iter = std::atoi(argv[1]);
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--former")
      o.inner_loop = o.observer = false, o.state_filter = 0;
    else if (a == "--mismatch")
      o.mismatch = true;
    else if (a == "--noise" && i + 1 < argc)
      o.noise = std::atof(argv[++i]);
    else if (a == "--presolve")  // (the default)
      o.presolve = true;
    else if (a == "--no-presolve")
      o.presolve = false;
  }
  const auto loop = std::make_unique<Loop>(o);
  const auto st = loop->start();
  // The loop starts from the first solve's plan. With frozen RK4 sensitivities that solve may
  // end short of convergence (the demo prints it too): counted and said, not fatal; a status that
  // leaves no plan is.
  if (st != arbor::nmpc::NmpcStatus::converged)
    std::fprintf(stderr, "first solve: %s (the loop starts from its plan)\n",
                 arbor::nmpc::to_string(st));
  if (st == arbor::nmpc::NmpcStatus::non_finite_input ||
      st == arbor::nmpc::NmpcStatus::not_prepared)
    return 1;
  CALLGRIND_START_INSTRUMENTATION;
  Record r;
  int n = 0, failed = 0, limited = 0;
  double e_max = 0;
  while (!loop->done()) {
    loop->sample(r);
    ++n;
    failed += !arbor::nmpc::succeeded(r.status);
    limited += r.status == arbor::nmpc::NmpcStatus::step_limited;
    e_max = r.e_p > e_max ? r.e_p : e_max;
    std::printf("sample %d qp_iterations %d e_p %.6g s %.6g %s%s\n", n - 1, r.qp_iterations, r.e_p,
                r.x[14], arbor::nmpc::to_string(r.status), r.qp_presolved ? " presolved" : "");
  }
  std::printf(
      "samples %d failed %d step_limited %d max e_p %.3f mm (tunnel %.1f mm) %s, stages: "
      "%s\n",
      n, failed, limited, 1e3 * e_max, 1e3 * contour::rho, CONTOUR_ID ? "OCP-ID" : "OCP-FD",
      loop->generated_stage() ? "generated" : "expression layer");
  return failed != 0;
}
