// Cost of differentiating a user's OCP function (an ad::fn body) with the expression layer's
// forward mode, dense (ad::fn_dense: the body at the evaluation's Dual<T, n>) against
// structure-aware (ad::fn: the body at a dual of only the directions its arguments depend on,
// include/arbor/ad/expr/structure.hpp). The function is the contour example's tracking residual
// (examples/contour/task.hpp, TrackResidual: sd - sd_ref(s), e_p, e_R, 1 - s, sd from the
// end-effector pose and [s, sd]) in a path stage's Jacobian environment: x (16), u (8), n = 24
// directions, of which the body's arguments depend on 9 (q and s, sd). The pose is a stand-in for
// the frame pose's call node: a call node of y = A sin(q) + b (A a dense 12 x 7 constant,
// Jacobian A diag(cos q)), so the body's inputs carry general derivatives along q's 7 directions
// that are functions of q, as the frame pose's are; its own operations are counted in a row of
// their own (the node alone), to be subtracted.
//
// Prints, for the Jacobian (9 x 24) and the Hessian of the residuals' sum (24 x 24, the exact-
// Hessian SQP's evaluation at nested duals): operations executed as the machine does them
// (Tick: every operation, zeros included), after folding and the live ones (Counted and its
// tape: what a symbolic tool would keep), then google-benchmark times at double.
//
//   build/bench/ad/arbor_ad_fn_counts [--benchmark_...]
#include <benchmark/benchmark.h>

#include <arbor/ad/expr.hpp>
#include <cstdio>
#include <task.hpp>

#include "op_counts.hpp"
#include "op_tick.hpp"
#include "track_function.hpp"
#include "track_function_ad.hpp"

namespace {

namespace ad = arbor::ad;
using arbor::VecN;

constexpr ad::Symbol<0, 16> X;
constexpr ad::Symbol<1, 8> U;
constexpr ad::Symbol<2, 1> P;

/// y = A sin(q) + b with a dense constant A (12 x 7): the frame pose's stand-in (a call node).
struct PoseStandIn {
  static constexpr int nin = 7, nout = 12;
  static double a(int i, int j) { return 0.1 + 0.05 * ((3 * i + 5 * j) % 7) - 0.02 * i; }
  template <class T>
  void value(const VecN<T, nin>& x, VecN<T, nout>& y) const {
    VecN<T, nin> s;
    for (int j = 0; j < nin; ++j)
      s[j] = arbor::sin(x[j]);
    for (int i = 0; i < nout; ++i) {
      y[i] = T(0.5 - 0.1 * i);
      for (int j = 0; j < nin; ++j)
        y[i] = y[i] + T(a(i, j)) * s[j];
    }
  }
  template <class Tag, class T>
  void value_and_jacobian(const VecN<T, nin>& x, VecN<T, nout>& y,
                          Eigen::Matrix<T, nout, nin>& J) const {
    value<T>(x, y);
    for (int j = 0; j < nin; ++j) {
      const T c = arbor::cos(x[j]);
      for (int i = 0; i < nout; ++i)
        J(i, j) = T(a(i, j)) * c;
    }
  }
};

/// The pose stand-in alone (9 of its rows, the size of the residual).
inline auto pose_alone() {
  return ad::segment<0, 9>(ad::call<ad::Analytical>(PoseStandIn{}, ad::segment<0, 7>(X)));
}

/// The parameters of the generated variant (the reference), static: the handle points at them.
std::array<double, 13> g_track_params{};

/// How the tracking residual is differentiated.
enum class Mode { dense, structure, generated };

/// The tracking residual: an fn node (dense: ad::fn_dense; structure: ad::fn) or a call node of
/// the user function with its generated Jacobian (generated).
template <Mode M>
auto track(const contour::Reference& ref) {
  const auto q = ad::segment<0, 7>(X);
  const auto pose = ad::call<ad::Analytical>(PoseStandIn{}, q);
  if constexpr (M == Mode::structure) {
    return ad::fn<9>(contour::TrackResidual{ref}, pose, ad::segment<14, 2>(X));
  } else if constexpr (M == Mode::dense) {
    return ad::fn_dense<9>(contour::TrackResidual{ref}, pose, ad::segment<14, 2>(X));
  } else {
    g_track_params = arbor::bench_ad::track_parameters(ref);
    return ad::call<ad::Generated>(
        ad::user_function<arbor::bench_ad::TrackFunction>(g_track_params.data()), pose,
        ad::segment<14, 2>(X));
  }
}

/// A stage point: q near q0, s = 0.3, sd = 0.2.
template <class T>
void stage_point(VecN<T, 16>& x, VecN<T, 8>& u, VecN<T, 1>& p, T (*make)(double)) {
  const auto q0 = contour::initial_q();
  for (int i = 0; i < 16; ++i)
    x[i] = make(i < 7 ? q0[i] + 0.05 * i : 0.1 * (i - 6));
  x[14] = make(0.3);
  x[15] = make(0.2);
  for (int i = 0; i < 8; ++i)
    u[i] = make(0.01 * (i + 1));
  p[0] = make(1.0);
}

struct Row {
  std::uint64_t machine = 0;  ///< Tick: every operation executed
  arbor::bench_ad::Count counted;
};

template <class E>
Row count_jacobian(const E& e) {
  Row r;
  {
    VecN<ad::Tick, 16> x;
    VecN<ad::Tick, 8> u;
    VecN<ad::Tick, 1> p;
    stage_point<ad::Tick>(x, u, p, [](double v) { return ad::Tick(v); });
    ad::reset_tick_count();
    const auto vj = ad::value_and_jacobian<0, 1>(e, x, u, p);
    r.machine = ad::tick_count();
    benchmark::DoNotOptimize(vj);
  }
  VecN<ad::Counted, 16> x;
  VecN<ad::Counted, 8> u;
  VecN<ad::Counted, 1> p;
  stage_point<ad::Counted>(x, u, p, [](double v) { return ad::Counted::input(v); });
  static ad::ValueJacobian<ad::Counted, 9, 24> vj;
  r.counted = arbor::bench_ad::measure([&] { vj = ad::value_and_jacobian<0, 1>(e, x, u, p); },
                                       vj.value, vj.jacobian);
  return r;
}

template <class E1>
Row count_hessian(const E1& e1) {
  const auto e = ad::sum(e1);
  Row r;
  {
    VecN<ad::Tick, 16> x;
    VecN<ad::Tick, 8> u;
    VecN<ad::Tick, 1> p;
    stage_point<ad::Tick>(x, u, p, [](double v) { return ad::Tick(v); });
    ad::reset_tick_count();
    const auto h = ad::value_gradient_hessian<0, 1>(e, x, u, p);
    r.machine = ad::tick_count();
    benchmark::DoNotOptimize(h);
  }
  VecN<ad::Counted, 16> x;
  VecN<ad::Counted, 8> u;
  VecN<ad::Counted, 1> p;
  stage_point<ad::Counted>(x, u, p, [](double v) { return ad::Counted::input(v); });
  static ad::ValueGradientHessian<ad::Counted, 24> h;
  r.counted = arbor::bench_ad::measure([&] { h = ad::value_gradient_hessian<0, 1>(e, x, u, p); },
                                       h.gradient, h.hessian);
  return r;
}

void print_row(const char* what, const char* mode, const Row& r, std::uint64_t dense_machine) {
  std::printf("| %s | %s | %llu (%.2fx) | %llu | %llu |\n", what, mode,
              static_cast<unsigned long long>(r.machine), double(r.machine) / double(dense_machine),
              static_cast<unsigned long long>(r.counted.executed),
              static_cast<unsigned long long>(r.counted.live));
}

template <Mode M>
void BM_track_jacobian(benchmark::State& state) {
  const auto ref = contour::make_reference(0.2);
  const auto e = track<M>(ref);
  VecN<double, 16> x;
  VecN<double, 8> u;
  VecN<double, 1> p;
  stage_point<double>(x, u, p, [](double v) { return v; });
  for (auto _ : state) {
    benchmark::DoNotOptimize(x.data());
    auto vj = ad::value_and_jacobian<0, 1>(e, x, u, p);
    benchmark::DoNotOptimize(vj);
  }
}
template <Mode M>
void BM_track_hessian(benchmark::State& state) {
  const auto ref = contour::make_reference(0.2);
  const auto e = ad::sum(track<M>(ref));
  VecN<double, 16> x;
  VecN<double, 8> u;
  VecN<double, 1> p;
  stage_point<double>(x, u, p, [](double v) { return v; });
  for (auto _ : state) {
    benchmark::DoNotOptimize(x.data());
    auto h = ad::value_gradient_hessian<0, 1>(e, x, u, p);
    benchmark::DoNotOptimize(h);
  }
}
BENCHMARK(BM_track_jacobian<Mode::dense>)->Name("track_jacobian/dense");
BENCHMARK(BM_track_jacobian<Mode::structure>)->Name("track_jacobian/structure");
BENCHMARK(BM_track_jacobian<Mode::generated>)->Name("track_jacobian/generated");
BENCHMARK(BM_track_hessian<Mode::dense>)->Name("track_hessian/dense");
BENCHMARK(BM_track_hessian<Mode::structure>)->Name("track_hessian/structure");
BENCHMARK(BM_track_hessian<Mode::generated>)->Name("track_hessian/generated");

}  // namespace

int main(int argc, char** argv) {
  const auto ref = contour::make_reference(0.2);
  // the compressed scalar of the body in this build (9 directions rounded up to SIMD registers)
  constexpr int n = 24;
  constexpr int kept = ad::detail::padded_directions<double, n, 9>();
  std::printf(
      "fn body of the contour's tracking residual, n = %d directions, %d kept "
      "(9 rounded up to whole SIMD registers of this build)\n\n",
      n, kept);
  std::printf(
      "| evaluation | fn body at | operations executed (Tick) | after folding (Counted) | "
      "live (Counted tape) |\n|---|---|---:|---:|---:|\n");
  const Row jd = count_jacobian(track<Mode::dense>(ref));
  const Row js = count_jacobian(track<Mode::structure>(ref));
  const Row jg = count_jacobian(track<Mode::generated>(ref));
  const Row jp = count_jacobian(pose_alone());
  print_row("Jacobian 9 x 24", "Dual<T, 24> (fn_dense)", jd, jd.machine);
  print_row("Jacobian 9 x 24", "compressed (fn)", js, jd.machine);
  print_row("Jacobian 9 x 24", "generated (call<Generated>, user_function)", jg, jd.machine);
  print_row("Jacobian 9 x 24", "(the pose stand-in alone)", jp, jd.machine);
  const Row hd = count_hessian(track<Mode::dense>(ref));
  const Row hs = count_hessian(track<Mode::structure>(ref));
  const Row hg = count_hessian(track<Mode::generated>(ref));
  const Row hp = count_hessian(pose_alone());
  print_row("Hessian 24 x 24 of the sum", "Dual<Dual<T, 24>, 24> (fn_dense)", hd, hd.machine);
  print_row("Hessian 24 x 24 of the sum", "compressed (fn)", hs, hd.machine);
  print_row("Hessian 24 x 24 of the sum", "generated Jacobian at Dual<T, 24>", hg, hd.machine);
  print_row("Hessian 24 x 24 of the sum", "(the pose stand-in alone)", hp, hd.machine);
  using GF = ad::GeneratedFunction<arbor::bench_ad::TrackFunction>;
  std::printf(
      "\ngenerated TrackFunction: primal %ld live operations, jacobian() %ld "
      "operations (value and 9 x 14 Jacobian)\n",
      GF::primal_ops, GF::jacobian_ops);
  std::printf("\n");
  std::fflush(stdout);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
