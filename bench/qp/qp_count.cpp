// Repeatable measure for RESULTS.md: cold and warm solves per variant, each between callgrind
// toggles, plus the counters of each solve on stdout. The last measure is the real-time path:
// the bound problem refilled with the perturbed data, update(Convexity::assumed), solve; then the
// real-time feedback: prepare_start() and solve_from() with a moved x_0.
// Every variant runs with the OCP solver's backend (the exact-dynamics Riccati one), and one full
// factorization is measured on its own ("factor" labels: dynamics rows and x_0 in the working
// set). (The penalised and reference Cholesky backends' rows of RESULTS.md were measured with
// this program before issue 38 retired them.)
//   valgrind --tool=callgrind --instr-atstart=no ./qp_count   (one dump per measured call)
#include <array>
#include <cstdio>

#include "arbor/qp/ocp_interior_point.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "kinova_qp.hpp"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define ARBOR_MEASURE(label, stmt)   \
  do {                               \
    CALLGRIND_START_INSTRUMENTATION; \
    stmt;                            \
    CALLGRIND_STOP_INSTRUMENTATION;  \
    CALLGRIND_DUMP_STATS_AT(label);  \
  } while (0)
#else
#define ARBOR_MEASURE(label, stmt) stmt
#endif

namespace {
using arbor::bench::KinovaQp;
using arbor::bench::make_kinova_qp;
using arbor::qp::Convexity;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpStatus;

template <typename Qp, typename Backend>
struct Case {
  Qp nominal, perturbed, live;
  OcpQpSolver<Qp, Backend> solver;
};

template <typename Qp>
using Default = typename arbor::qp::detail::DefaultOcpBackend<Qp>::type;
template <typename Qp, typename Backend = Default<Qp>>
void run(const char* name) {
  static Case<Qp, Backend> c;  // static storage: ~0.3 MB
  make_kinova_qp(c.nominal, 1);
  make_kinova_qp(c.perturbed, 1, 1e-3, 0.01);
  using Scalar = typename decltype(c.nominal.terminal.q)::Scalar;
  arbor::qp::QpSettings<Scalar> settings;
  settings.max_iter = 1000;  // a cold start needs one iteration per active-set change
  QpStatus st = QpStatus::not_setup, su = QpStatus::not_setup;
  char label[64];
  std::snprintf(label, sizeof label, "%s/cold_nominal", name);
  ARBOR_MEASURE(label, (su = c.solver.setup(c.nominal, settings), c.solver.cold_start(),
                        st = c.solver.solve()));
  const auto& i = c.solver.info();
  std::printf(
      "%-10s cold nominal   %-15s it %3d changes %3d stages %4d active %3d pr %.1e du %.1e\n", name,
      arbor::qp::to_string(st), i.iterations, i.active_set_changes, i.stages_factorized,
      i.active_constraints, double(i.primal_residual), double(i.dual_residual));
  std::snprintf(label, sizeof label, "%s/warm_perturbed", name);
  ARBOR_MEASURE(label, (su = c.solver.setup(c.perturbed, settings), st = c.solver.solve()));
  std::printf(
      "%-10s warm perturbed %-15s it %3d changes %3d stages %4d active %3d pr %.1e du %.1e\n", name,
      arbor::qp::to_string(st), i.iterations, i.active_set_changes, i.stages_factorized,
      i.active_constraints, double(i.primal_residual), double(i.dual_residual));
  std::snprintf(label, sizeof label, "%s/cold_perturbed", name);
  ARBOR_MEASURE(label, (c.solver.cold_start(), st = c.solver.solve()));
  std::printf(
      "%-10s cold perturbed %-15s it %3d changes %3d stages %4d active %3d pr %.1e du %.1e\n", name,
      arbor::qp::to_string(st), i.iterations, i.active_set_changes, i.stages_factorized,
      i.active_constraints, double(i.primal_residual), double(i.dual_residual));
  // cold by the interior point and its crossover (qp/ocp_interior_point.hpp)
  static arbor::qp::OcpInteriorPoint<Qp> ipm;
  for (const Qp* q : {&c.nominal, &c.perturbed}) {
    const bool nominal = q == &c.nominal;
    std::snprintf(label, sizeof label, "%s/cold_ipm_%s", name, nominal ? "nominal" : "perturbed");
    ARBOR_MEASURE(
        label, (su = c.solver.setup(*q, settings), st = arbor::qp::cold_solve(c.solver, ipm, *q)));
    std::printf(
        "%-10s cold ipm %-9s %-15s ipm it %2d (%s, %d guessed active), then it %3d changes "
        "%3d stages %4d active %3d pr %.1e du %.1e\n",
        name, nominal ? "nominal" : "perturbed", arbor::qp::to_string(st), ipm.info().iterations,
        arbor::qp::to_string(ipm.status()), ipm.info().guessed_active, i.iterations,
        i.active_set_changes, i.stages_factorized, i.active_constraints, double(i.primal_residual),
        double(i.dual_residual));
  }
  // real-time iteration: one problem object, refilled; update without the convexity check
  c.live = c.nominal;
  if (c.solver.setup(c.live, settings) != QpStatus::accepted)
    std::printf("%-10s setup rejected\n", name);
  c.solver.cold_start();
  st = c.solver.solve();
  c.live = c.perturbed;
  std::snprintf(label, sizeof label, "%s/warm_update_assumed", name);
  ARBOR_MEASURE(label, (su = c.solver.update(Convexity::assumed), st = c.solver.solve()));
  std::printf(
      "%-10s warm update    %-15s it %3d changes %3d stages %4d active %3d pr %.1e du %.1e (%s)\n",
      name, arbor::qp::to_string(st), i.iterations, i.active_set_changes, i.stages_factorized,
      i.active_constraints, double(i.primal_residual), double(i.dual_residual),
      arbor::qp::to_string(su));
  // real-time feedback: the preparation (the first step for x_0 as the problem has it) and the
  // solve with x_0 moved to the perturbed problem's, warm-started from the last multipliers
  std::snprintf(label, sizeof label, "%s/presolve", name);
  typename OcpQpSolver<Qp, Backend>::PreparedStart prepared;
  ARBOR_MEASURE(label, (prepared = c.solver.prepare_start()));
  std::snprintf(label, sizeof label, "%s/presolved_feedback", name);
  const Eigen::Matrix<Scalar, Qp::nx, 1> x0 = c.perturbed.stage[0].lbx * Scalar(1.001);
  ARBOR_MEASURE(label, (st = c.solver.solve_from(prepared, x0)));
  std::printf(
      "%-10s presolved      %-15s it %3d changes %3d stages %4d (presolve %d, took it %d)\n", name,
      arbor::qp::to_string(st), i.iterations, i.active_set_changes, i.stages_factorized,
      prepared.stages_factorized(), int(i.presolved));
  std::printf("%-10s sizeof(solver) %zu bytes, sizeof(problem) %zu bytes\n", name,
              sizeof(OcpQpSolver<Qp, Backend>), sizeof(Qp));
}

/// One full factorization, the working set of a fresh solve (dynamics rows, x_0 fixed).
template <typename Qp, typename Backend>
void factor(const char* name) {
  using Scalar = typename decltype(Qp{}.terminal.q)::Scalar;
  using arbor::qp::detail::ConstraintState;
  static Qp qp;
  static Backend be;
  static std::array<ConstraintState, Qp::nv + Qp::na> ws{};
  make_kinova_qp(qp, 1);
  for (int i = 0; i < Qp::nv + Qp::na; ++i)
    ws[i] = i >= Qp::nv || i < Qp::nx ? ConstraintState::equality : ConstraintState::inactive;
  static Eigen::Matrix<Scalar, Qp::na, 1> wa;
  be.p = &qp;
  be.row_norms_sq(wa);
  const arbor::qp::QpSettings<Scalar> s;
  const Scalar w = Scalar(1) / s.reg_dual;
  for (int j = 0; j < Qp::na; ++j)
    wa(j) = w / wa(j);
  int done = 0;
  be.mark_all();
  ARBOR_MEASURE(name, (done = be.factorize(ws.data(), s.reg_primal, w, wa)));
  std::printf("%-22s %d stage blocks\n", name, done);
}
}  // namespace

int main() {
  factor<KinovaQp<double, 1>, Default<KinovaQp<double, 1>>>("fd_double/factor");
  factor<KinovaQp<double, 8>, Default<KinovaQp<double, 8>>>("id_double/factor");
  factor<KinovaQp<float, 1>, Default<KinovaQp<float, 1>>>("fd_float/factor");
  run<KinovaQp<double, 1>>("fd_double");
  run<KinovaQp<double, 8>>("id_double");
  run<KinovaQp<float, 1>>("fd_float");
  run<KinovaQp<float, 8>>("id_float");
  return 0;
}
