// NMPC benchmarks on the small OCPs of tests/nmpc (the pendulum and the cart-pole; figures in
// RESULTS.md), double and float:
//   sqp/<phase>   one full SQP solve (solve()'s loop, run phase by phase from a cold guess; the
//                 number of QP solves is the one solve() takes), timed per phase and reported
//                 per SQP iteration (manual time): linearize (evaluation and linearisation of
//                 every stage into the QP), solve_qp (QP update, i.e. its construction, and the
//                 QP solve), line_search (L1-merit backtracking and the step), and solve (the
//                 whole of solve(), including the KKT residuals and the convergence test);
//   rti/<phase>   a real-time-iteration closed loop (the portable test's scenario), timed per
//                 sample: prepare (shift() and prepare()) and feedback (feedback(x0)).
// Counters: SQP iterations (QP solves), QP iterations per QP, max_us (the slowest call seen),
// controller_bytes (sizeof the whole controller).
//
// `--run <problem> <phase> <double|float> <n>` runs n solves (sqp phases) or n samples (rti
// phases), with callgrind collecting only inside the phase (valgrind --collect-atstart=no), and
// prints `calls <count>`: bench/callgrind_counts.sh (BENCH=nmpc) divides by it. `--sizes`
// prints sizeof of the controllers.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "arbor/nmpc/controller.hpp"
#include "cartpole.hpp"
#include "problems.hpp"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define ARBOR_COLLECT(stmt)   \
  do {                        \
    CALLGRIND_TOGGLE_COLLECT; \
    stmt;                     \
    CALLGRIND_TOGGLE_COLLECT; \
  } while (0)
#else
#define ARBOR_COLLECT(stmt) stmt
#endif

namespace {

using arbor::nmpc::Nmpc;
using arbor::nmpc::NmpcStatus;
using Clock = std::chrono::steady_clock;
constexpr double pi = 3.14159265358979323846;

/// The pendulum of tests/nmpc/problems.hpp: N = 40 (2 s), Gauss-Newton (SCQP).
///   sqp: from 0.2 rad off upright at rest, cold guess (the state on every stage, zero input);
///   rti: the closed loop of tests/nmpc/portable_test.cpp (same start, plant RK4 with 10 steps).
struct Pendulum {
  static constexpr const char* name = "pendulum";
  static constexpr int horizon = 40;
  using Problem = decltype(nmpc_test::pendulum_problem<horizon>());
  using State = Eigen::Vector2d;
  static constexpr int samples = 80;  // one closed-loop episode (4 s)
  static Problem problem() { return nmpc_test::pendulum_problem<horizon>(); }
  static State start() { return {pi - 0.2, 0.0}; }
  static State plant(const State& x, double u) {
    return nmpc_test::rk4_plain(nmpc_test::pendulum_ode, x, u, nmpc_test::PendulumData::h, 10);
  }
};

/// The cart-pole of tests/nmpc/cartpole.hpp: N = 40 (2 s), Gauss-Newton, |f| <= 8, |p| <= 0.6;
/// sqp and rti from the pole 0.2 rad off upright, cart at rest at the centre.
struct CartPole {
  static constexpr const char* name = "cartpole";
  static constexpr int horizon = 40;
  using Problem = decltype(nmpc_test::cartpole_problem<horizon>());
  using State = Eigen::Vector4d;
  static constexpr int samples = 80;
  static Problem problem() { return nmpc_test::cartpole_problem<horizon>(); }
  static State start() { return {0.0, pi - 0.2, 0.0, 0.0}; }
  static State plant(const State& x, double u) {
    return nmpc_test::rk4_plain(nmpc_test::cartpole_ode, x, u, nmpc_test::CartPoleData::h, 10);
  }
};

template <class C, class S>
using Controller = Nmpc<typename C::Problem, S>;

/// The controller of case C at scalar S, in static storage.
template <class C, class S>
Controller<C, S>& controller() {
  static Controller<C, S> ctrl(C::problem());
  return ctrl;
}

enum class Phase { linearize, solve_qp, line_search, solve, prepare, feedback };
constexpr const char* phase_names[] = {"linearize", "solve_qp", "line_search",
                                       "solve",     "prepare",  "feedback"};

/// Seconds spent in each phase and the number of calls.
struct Times {
  double seconds[6] = {};
  double max_seconds[6] = {};
  long calls[6] = {};
  long qp_iterations = 0;
  int sqp_iterations = 0;  // of the last solve
  NmpcStatus status = NmpcStatus::not_prepared;
  bool failed = false;
  int collect = -1;  // the phase callgrind collects (--run); -1: time every phase
};

/// Runs f as phase p: timed (steady_clock), or collected by callgrind if p is t.collect.
template <class F>
void phase(Times& t, Phase p, F&& f) {
  const int i = int(p);
  if (t.collect == i) {
    ARBOR_COLLECT(f());
  } else if (t.collect >= 0) {
    f();
  } else {
    const auto t0 = Clock::now();
    f();
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    t.seconds[i] += s;
    t.max_seconds[i] = std::max(t.max_seconds[i], s);
  }
  ++t.calls[i];
}

/// Number of QP solves solve() takes from the cold guess (and its status).
template <class C, class S>
int sqp_iterations(NmpcStatus* status = nullptr) {
  auto& ctrl = controller<C, S>();
  const auto x0 = C::start().template cast<S>().eval();
  (void)ctrl.set_initial_guess(x0, Controller<C, S>::Vu::Zero());
  const NmpcStatus st = ctrl.solve(x0);
  if (status)
    *status = st;
  return ctrl.info().iterations;
}

/// One SQP solve from the cold guess, phase by phase: `iterations` QP solves, as solve() does
/// (without its KKT residuals and convergence test); or, with `whole`, solve() itself.
template <class C, class S>
void sqp(Times& t, int iterations, bool whole) {
  auto& ctrl = controller<C, S>();
  const auto x0 = C::start().template cast<S>().eval();
  (void)ctrl.set_initial_guess(x0, Controller<C, S>::Vu::Zero());
  if (whole) {
    NmpcStatus st;
    phase(t, Phase::solve, [&] { st = ctrl.solve(x0); });
    t.calls[int(Phase::solve)] += ctrl.info().iterations - 1;  // per SQP iteration
    t.qp_iterations += ctrl.info().qp_iterations;
    t.sqp_iterations = ctrl.info().iterations;
    t.status = st;
    return;
  }
  NmpcStatus st = NmpcStatus::step_taken;
  for (int it = 0; it < iterations && !t.failed; ++it) {
    phase(t, Phase::linearize, [&] { st = ctrl.linearize(); });
    ctrl.embed(x0);
    t.failed = t.failed || st != NmpcStatus::prepared;
    phase(t, Phase::solve_qp, [&] { st = ctrl.solve_qp(); });
    t.qp_iterations += ctrl.qp_solver().info().iterations;
    t.failed = t.failed || st != NmpcStatus::step_taken;
    phase(t, Phase::line_search, [&] { st = ctrl.line_search(x0); });
    t.failed = t.failed || st != NmpcStatus::step_taken;
  }
  t.sqp_iterations = iterations;
  t.status = st;
}

/// One real-time-iteration closed loop of `samples` samples from C::start().
template <class C, class S>
void rti(Times& t, int samples) {
  auto& ctrl = controller<C, S>();
  typename C::State x = C::start();
  (void)ctrl.set_initial_guess(x.template cast<S>(), Controller<C, S>::Vu::Zero());
  NmpcStatus st = ctrl.prepare();
  t.failed = t.failed || st != NmpcStatus::prepared;
  for (int k = 0; k < samples; ++k) {
    phase(t, Phase::feedback, [&] { st = ctrl.feedback(x.template cast<S>()); });
    t.failed = t.failed || st != NmpcStatus::step_taken;
    t.qp_iterations += ctrl.info().qp_iterations;
    const double u = double(ctrl.control()[0]);
    phase(t, Phase::prepare, [&] {
      ctrl.shift();
      st = ctrl.prepare();
    });
    t.failed = t.failed || st != NmpcStatus::prepared;
    x = C::plant(x, u);
  }
  t.status = st;
}

// ---- Google Benchmark ---------------------------------------------------------------------------
template <class C, class S>
void bm_sqp(benchmark::State& state, Phase p) {
  NmpcStatus solve_status;
  const int iterations = sqp_iterations<C, S>(&solve_status);
  Times t;
  for (auto _ : state) {
    const double before = t.seconds[int(p)];
    sqp<C, S>(t, iterations, p == Phase::solve);
    state.SetIterationTime((t.seconds[int(p)] - before) / iterations);
  }
  const double solves = double(state.iterations());
  state.counters["sqp_iterations"] = iterations;
  state.counters["qp_it_per_qp"] = double(t.qp_iterations) / (solves * iterations);
  state.counters["max_us"] = 1e6 * t.max_seconds[int(p)];
  state.counters["controller_bytes"] = double(sizeof(Controller<C, S>));
  state.SetLabel(std::string(to_string(p == Phase::solve ? t.status : solve_status)) +
                 (t.failed ? " (a phase failed)" : ""));
}

template <class C, class S>
void bm_rti(benchmark::State& state, Phase p) {
  Times t;
  for (auto _ : state) {
    const double before = t.seconds[int(p)];
    rti<C, S>(t, C::samples);
    state.SetIterationTime((t.seconds[int(p)] - before) / C::samples);
  }
  state.counters["qp_it_per_sample"] =
      double(t.qp_iterations) / (double(state.iterations()) * C::samples);
  state.counters["max_us"] = 1e6 * t.max_seconds[int(p)];
  state.counters["controller_bytes"] = double(sizeof(Controller<C, S>));
  state.SetLabel(t.failed ? "a phase failed" : "ok");
}

template <class C, class S>
void register_case(const char* scalar) {
  const std::string base = std::string(C::name) + "/" + scalar + "/";
  for (Phase p : {Phase::linearize, Phase::solve_qp, Phase::line_search, Phase::solve})
    benchmark::RegisterBenchmark((base + "sqp/" + phase_names[int(p)]).c_str(),
                                 [p](benchmark::State& s) { bm_sqp<C, S>(s, p); })
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
  for (Phase p : {Phase::prepare, Phase::feedback})
    benchmark::RegisterBenchmark((base + "rti/" + phase_names[int(p)]).c_str(),
                                 [p](benchmark::State& s) { bm_rti<C, S>(s, p); })
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
}

// ---- --run (callgrind) and --sizes --------------------------------------------------------------
template <class C, class S>
bool run(const std::string& name, long n) {
  Times t;
  int i = -1;
  for (int j = 0; j < 6; ++j)
    if (name == phase_names[j])
      i = j;
  if (i < 0)
    return false;
  const Phase p = Phase(i);
  t.collect = i;
  if (p == Phase::prepare || p == Phase::feedback) {
    rti<C, S>(t, int(n));
  } else {
    const int iterations = sqp_iterations<C, S>();
    for (long r = 0; r < n; ++r)
      sqp<C, S>(t, iterations, p == Phase::solve);
  }
  std::printf("calls %ld status %s%s\n", t.calls[i], to_string(t.status),
              t.failed ? " (a phase failed)" : "");
  return true;
}

template <class C>
bool run_case(const char* problem, const char* phase, const char* scalar, long n) {
  if (std::strcmp(problem, C::name) != 0)
    return false;
  if (std::strcmp(scalar, "double") == 0)
    return run<C, double>(phase, n);
  if (std::strcmp(scalar, "float") == 0)
    return run<C, float>(phase, n);
  return false;
}

template <class C>
void print_sizes() {
  using D = Controller<C, double>;
  using F = Controller<C, float>;
  std::printf(
      "%s (N = %d, nx = %d, nu = %d): controller %zu / %zu bytes (double / float), "
      "of which QP %zu / %zu, QP solver %zu / %zu\n",
      C::name, D::N, D::nx, D::nu, sizeof(D), sizeof(F), sizeof(typename D::Qp),
      sizeof(typename F::Qp), sizeof(typename D::QpSolver), sizeof(typename F::QpSolver));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 6 && std::strcmp(argv[1], "--run") == 0) {
    const long n = std::atol(argv[5]);
    const bool ok = run_case<Pendulum>(argv[2], argv[3], argv[4], n) ||
                    run_case<CartPole>(argv[2], argv[3], argv[4], n);
    if (!ok)
      std::fprintf(stderr, "unknown problem, phase or scalar\n");
    return ok ? 0 : 1;
  }
  if (argc == 2 && std::strcmp(argv[1], "--sizes") == 0) {
    print_sizes<Pendulum>();
    print_sizes<CartPole>();
    return 0;
  }
  register_case<Pendulum, double>("double");
  register_case<Pendulum, float>("float");
  register_case<CartPole, double>("double");
  register_case<CartPole, float>("float");
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
