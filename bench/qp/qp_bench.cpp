// Host benchmarks of the OCP QP solver at the size of the paper's Kinova Gen3 NMPC (N = 16,
// nx = 16, nu = 8): OCP-FD (1 path row per stage) and OCP-ID (8 rows per stage), double and float.
//   cold:   setup + cold start + solve
//   cold_ipm: setup + the interior point, its crossover and the active set's solve
//           (qp/ocp_interior_point.hpp: qp::cold_solve)
//   warm:   solve of a perturbed problem (x0 shifted, costs perturbed by 1 %) from the solution of
//           the nominal one (the copy of the iterate, a few us, is inside the timing)
//   update: the real-time path: update(Convexity::assumed) of the bound (perturbed) problem,
//           then the warm-started solve (compare with setup + warm)
//   factor: one full block-tridiagonal factorization (all 17 stages)
// The odd_* rows: a QP whose sizes are no multiple of any vector width, (N, nx, nu, ng, ngn) =
// (20, 14, 7, 1, 1), a 6-DoF arm's contour task (issue 35: it crashed at -march=native), random
// data of tests/qp/qp_random_static.hpp (perturbed: x0 shifted by 1e-3).
// Counters: iterations, active-set changes, stage blocks factorized per solve, solver bytes.
// Every case runs with the OCP solver's backend (the exact-dynamics Riccati one,
// ocp_riccati_backend.hpp); the "pen_" rows of RESULTS.md (the penalised block elimination) were
// measured before issue 38 retired it.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>

#include "arbor/qp/ocp_interior_point.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "kinova_qp.hpp"
#include "qp_random_static.hpp"

namespace {
using arbor::bench::KinovaQp;
using arbor::bench::make_kinova_qp;
using arbor::qp::Convexity;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpStatus;
using arbor::qp::detail::ConstraintState;

template <typename Qp>
using Default = typename arbor::qp::detail::DefaultOcpBackend<Qp>::type;

template <typename Qp, typename Backend>
struct Fixture {
  Qp nominal;
  Qp perturbed;
  OcpQpSolver<Qp, Backend> solver;
  Eigen::Matrix<typename decltype(nominal.terminal.q)::Scalar, Qp::nv, 1> x0;
  Eigen::Matrix<typename decltype(nominal.terminal.q)::Scalar, Qp::nv, 1> lx0;
  Eigen::Matrix<typename decltype(nominal.terminal.q)::Scalar, Qp::na, 1> la0;
  arbor::qp::QpSettings<typename decltype(nominal.terminal.q)::Scalar> settings;
  Fixture() {
    settings.max_iter = 1000;  // a cold start needs one iteration per active-set change
    if constexpr (Qp::nx == 16 && Qp::nu == 8) {
      make_kinova_qp(nominal, 1);
      make_kinova_qp(perturbed, 1, 1e-3, 0.01);
    } else {
      using S = typename decltype(nominal.terminal.q)::Scalar;
      static arbor::qp::OcpQp<double, Qp::horizon, Qp::nx, Qp::nu, Qp::ng, Qp::ngn> d;
      qp_matrix::random_problem(d, 1);
      qp_matrix::cast_problem<S>(d, nominal);
      d.stage[0].lbx.array() += 1e-3;
      d.stage[0].ubx.array() += 1e-3;
      qp_matrix::cast_problem<S>(d, perturbed);
    }
    if (solver.setup(nominal, settings) != QpStatus::accepted)
      return;
    solver.cold_start();
    benchmark::DoNotOptimize(solver.solve());
    x0 = solver.x();
    lx0 = solver.lam_x();
    la0 = solver.lam_a();
  }
};

template <typename Qp, typename Backend>
Fixture<Qp, Backend>& fixture() {
  static Fixture<Qp, Backend> f;  // ~0.3 MB: static storage
  return f;
}

template <typename Qp, typename Backend>
void report(benchmark::State& state, const OcpQpSolver<Qp, Backend>& s, QpStatus st) {
  state.counters["iterations"] = s.info().iterations;
  state.counters["changes"] = s.info().active_set_changes;
  state.counters["stages_factorized"] = s.info().stages_factorized;
  state.counters["solved"] = st == QpStatus::solved ? 1 : 0;
  state.counters["solver_bytes"] = sizeof(OcpQpSolver<Qp, Backend>);
  state.counters["problem_bytes"] = sizeof(Qp);
}

template <typename Qp, typename Backend = Default<Qp>>
void bm_cold(benchmark::State& state) {
  auto& f = fixture<Qp, Backend>();
  QpStatus st = QpStatus::not_setup;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.solver.setup(f.perturbed, f.settings));
    f.solver.cold_start();
    st = f.solver.solve();
    benchmark::DoNotOptimize(f.solver.x().data());
  }
  report(state, f.solver, st);
}

/// Cold solve by the interior point and its crossover (qp/ocp_interior_point.hpp): setup,
/// interior-point iterations, warm start of the active set from the crossover point, solve.
template <typename Qp, typename Backend = Default<Qp>>
void bm_cold_ipm(benchmark::State& state) {
  auto& f = fixture<Qp, Backend>();
  static arbor::qp::OcpInteriorPoint<Qp> ipm;
  QpStatus st = QpStatus::not_setup;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.solver.setup(f.perturbed, f.settings));
    st = arbor::qp::cold_solve(f.solver, ipm, f.perturbed);
    benchmark::DoNotOptimize(f.solver.x().data());
  }
  report(state, f.solver, st);
  state.counters["ipm_iterations"] = ipm.info().iterations;
  state.counters["ipm_bytes"] = sizeof(ipm);
}

template <typename Qp, typename Backend = Default<Qp>>
void bm_warm(benchmark::State& state) {
  auto& f = fixture<Qp, Backend>();
  QpStatus st = f.solver.setup(f.perturbed, f.settings);
  for (auto _ : state) {
    f.solver.set_warm_start(f.x0, f.lx0, f.la0);
    st = f.solver.solve();
    benchmark::DoNotOptimize(f.solver.x().data());
  }
  report(state, f.solver, st);
}

template <typename Qp, typename Backend = Default<Qp>>
void bm_update(benchmark::State& state) {
  auto& f = fixture<Qp, Backend>();
  QpStatus st = f.solver.setup(f.perturbed, f.settings);
  for (auto _ : state) {
    f.solver.set_warm_start(f.x0, f.lx0, f.la0);
    benchmark::DoNotOptimize(f.solver.update(Convexity::assumed));
    st = f.solver.solve();
    benchmark::DoNotOptimize(f.solver.x().data());
  }
  report(state, f.solver, st);
}

template <typename Qp, typename Backend = Default<Qp>>
void bm_factor(benchmark::State& state) {
  using Scalar = typename decltype(Qp{}.terminal.q)::Scalar;
  static Backend be;
  static std::array<ConstraintState, Qp::nv + Qp::na> ws{};
  auto& f = fixture<Qp, Backend>();
  be.p = &f.nominal;
  for (int i = 0; i < Qp::nv + Qp::na; ++i)
    ws[i] = i >= Qp::nv ? ConstraintState::equality : ConstraintState::inactive;  // dynamics
  for (int i = 0; i < Qp::nx; ++i)
    ws[i] = ConstraintState::equality;  // x_0 fixed
  static Eigen::Matrix<Scalar, Qp::na, 1> wa;
  be.row_norms_sq(wa);
  const Scalar w = Scalar(1) / f.solver.settings().reg_dual;
  for (int j = 0; j < Qp::na; ++j)
    wa(j) = w / wa(j);
  int done = 0;
  for (auto _ : state) {
    be.mark_all();
    done = be.factorize(ws.data(), f.solver.settings().reg_primal, w, wa);
    benchmark::DoNotOptimize(be.l_term.data());
  }
  state.counters["stages"] = done;
}

template <typename Qp, typename Backend = Default<Qp>>
void bm_setup(benchmark::State& state) {
  auto& f = fixture<Qp, Backend>();
  for (auto _ : state)
    benchmark::DoNotOptimize(f.solver.setup(f.perturbed, f.settings));
}

using FdD = KinovaQp<double, 1>;
using IdD = KinovaQp<double, 8>;
using FdF = KinovaQp<float, 1>;
using IdF = KinovaQp<float, 8>;
using OddD = arbor::qp::OcpQp<double, 20, 14, 7, 1, 1>;
using OddF = arbor::qp::OcpQp<float, 20, 14, 7, 1, 1>;

BENCHMARK(bm_cold<FdD>)->Name("fd_double/cold")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold_ipm<FdD>)->Name("fd_double/cold_ipm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_warm<FdD>)->Name("fd_double/warm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_update<FdD>)->Name("fd_double/update_assumed_warm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_factor<FdD>)->Name("fd_double/factor_full")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_setup<FdD>)->Name("fd_double/setup")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold<IdD>)->Name("id_double/cold")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold_ipm<IdD>)->Name("id_double/cold_ipm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_warm<IdD>)->Name("id_double/warm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_update<IdD>)->Name("id_double/update_assumed_warm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_factor<IdD>)->Name("id_double/factor_full")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold<OddD>)->Name("odd_double/cold")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold_ipm<OddD>)->Name("odd_double/cold_ipm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_warm<OddD>)->Name("odd_double/warm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_factor<OddD>)->Name("odd_double/factor_full")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold<OddF>)->Name("odd_float/cold")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_warm<OddF>)->Name("odd_float/warm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold<FdF>)->Name("fd_float/cold")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold_ipm<FdF>)->Name("fd_float/cold_ipm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_warm<FdF>)->Name("fd_float/warm")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_factor<FdF>)->Name("fd_float/factor_full")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_cold<IdF>)->Name("id_float/cold")->Unit(benchmark::kMicrosecond);
BENCHMARK(bm_warm<IdF>)->Name("id_float/warm")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
