// Generated stage code (ocp/generated_stage.hpp) against the expression layer's
// ocp::linearize_path at double on the contour OCP (examples/contour/stage_definition.hpp's
// FdStage: OCP-FD, hard tunnel, RK4 exact or frozen as built): time per path stage of each (reps
// calls, median of 7 rounds) and the largest relative difference of the blocks. Instruction
// counts: run it under `valgrind --tool=callgrind` and compare the inclusive counts of
// linearize_path's two instantiations (bench/ocp/CMakeLists.txt; figures in
// bench/nmpc/RESULTS.md).
#include <algorithm>
#include <chrono>
#include <contour_stage_ad.hpp>
#include <cstdio>

int main() {
  using namespace arbor;
  using Def = contour::FdStage;
  using T = double;
  static Def::Workspace<T> ws;
  const auto prob = Def::problem(ws);
  const auto gen = ocp::with_generated_stage<Def>(prob);
  using P = std::remove_cvref_t<decltype(prob)>;
  constexpr int ng = ocp::qp_rows(P::ng);
  VecN<T, P::nx> x, xn, lam;
  VecN<T, P::nu + P::ns> w;
  VecN<T, P::np> p;
  VecN<T, ng> lg;
  const auto q0 = contour::initial_q();
  for (int i = 0; i < P::nx; ++i)
    x[i] = i < 7 ? q0[i] + 0.013 * i : 0.04 + 0.011 * i;
  for (int i = 0; i < P::nu + P::ns; ++i)
    w[i] = 0.2 + 0.07 * i;
  for (int i = 0; i < P::np; ++i)
    p[i] = i == 0 ? 1.0 : 0.02 * i;
  for (int i = 0; i < P::nx; ++i)
    xn[i] = 0.03 * i;
  for (int i = 0; i < P::nx; ++i)
    lam[i] = 0.1 * i;
  lg.setConstant(0.7);  // a positive tunnel multiplier: its Gauss-Newton term runs in both
  typename ocp::QpOf<P, T>::Stage a, g;
  constexpr int reps = 2000;
  double t_lib[7], t_gen[7];
  for (int round = 0; round < 7; ++round) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < reps; ++k) {
      x[0] += 1e-9;
      ocp::linearize_path<ocp::HessianKind::gauss_newton>(prob, x, w, p, xn, lam, lg, a);
    }
    const auto t1 = std::chrono::steady_clock::now();
    for (int k = 0; k < reps; ++k) {
      x[0] += 1e-9;
      ocp::linearize_path<ocp::HessianKind::gauss_newton>(gen, x, w, p, xn, lam, lg, g);
    }
    const auto t2 = std::chrono::steady_clock::now();
    t_lib[round] = std::chrono::duration<double, std::micro>(t1 - t0).count() / reps;
    t_gen[round] = std::chrono::duration<double, std::micro>(t2 - t1).count() / reps;
  }
  ocp::linearize_path<ocp::HessianKind::gauss_newton>(prob, x, w, p, xn, lam, lg, a);
  ocp::linearize_path<ocp::HessianKind::gauss_newton>(gen, x, w, p, xn, lam, lg, g);
  double e = 0;
  auto cmp = [&](const auto& m1, const auto& m2) {
    e = std::max(e, (m1 - m2).cwiseAbs().maxCoeff() / (1 + m1.cwiseAbs().maxCoeff()));
  };
  cmp(a.A, g.A);
  cmp(a.B, g.B);
  cmp(a.b, g.b);
  cmp(a.Q, g.Q);
  cmp(a.S, g.S);
  cmp(a.R, g.R);
  cmp(a.q, g.q);
  cmp(a.r, g.r);
  cmp(a.C, g.C);
  cmp(a.D, g.D);
  cmp(a.ug, g.ug);
  std::sort(t_lib, t_lib + 7);
  std::sort(t_gen, t_gen + 7);
  std::printf(
      "generated path stage (%ld operations, RK4 %s) vs linearize_path: max relative "
      "difference %.2e\n",
      ocp::GeneratedStage<Def>::path_ops, CONTOUR_FROZEN_SENSITIVITY ? "frozen" : "exact", e);
  std::printf(
      "time per path stage, median of 7 rounds of %d: expression layer %.2f us, "
      "generated %.2f us (%.2f)\n",
      reps, t_lib[3], t_gen[3], t_gen[3] / t_lib[3]);
  return e < 1e-10 ? 0 : 1;
}
