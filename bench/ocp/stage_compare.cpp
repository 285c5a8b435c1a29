// Issue 38 item 3, a measurement: the traced path stage (stage_trace.cpp's GeneratedStage::path)
// against the library's ocp::linearize_path at double on the contour OCP (OCP-FD, hard tunnel,
// RK4 exact or frozen as built): the largest relative difference of every QP block it writes, and
// the time per stage of each (reps calls, median of 7 rounds). Instruction counts: run it under
// `valgrind --tool=callgrind` and take linearize_path's inclusive count per call against the
// rest of main's (bench/ocp/CMakeLists.txt).
#include <algorithm>
#include <arbor/nmpc/workspace.hpp>
#include <arbor/ocp/linearize.hpp>
#include <chrono>
#include <cstdio>
#include <robots/kinova_gen3.hpp>
#include <task.hpp>

#include "generated_stage.hpp"

int main() {
  using namespace arbor;
  namespace ad = arbor::ad;
  using T = double;
  static contour::Workspace<ad::Analytical, T> ws;
  const auto prob = contour::make_problem<contour::Formulation::fd, ad::Analytical, false>(
      ws, contour::make_reference(0.2));
  using P = std::remove_cvref_t<decltype(prob)>;
  constexpr int ng = ocp::qp_rows(P::ng);
  VecN<T, P::nx> x, xn, lam;
  VecN<T, P::nu + P::ns> w;
  VecN<T, P::np> p;
  VecN<T, ng> lg;
  const auto q0 = contour::initial_q();
  for (int i = 0; i < P::nx; ++i)  // another point than the trace's
    x[i] = i < 7 ? q0[i] + 0.013 * i : 0.04 + 0.011 * i;
  for (int i = 0; i < P::nu + P::ns; ++i)
    w[i] = 0.2 + 0.07 * i;
  for (int i = 0; i < P::np; ++i)
    p[i] = i == 0 ? 1.0 : 0.02 * i;
  for (int i = 0; i < P::nx; ++i)
    xn[i] = 0.03 * i;
  for (int i = 0; i < P::nx; ++i)
    lam[i] = 0.1 * i;
  lg.setConstant(0.7);
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
      GeneratedStage::path(x.data(), w.data(), p.data(), xn.data(), lam.data(), lg.data(),
                           g.A.data(), g.B.data(), g.b.data(), g.Q.data(), g.S.data(), g.R.data(),
                           g.q.data(), g.r.data(), g.C.data(), g.D.data(), g.ug.data());
    }
    const auto t2 = std::chrono::steady_clock::now();
    t_lib[round] = std::chrono::duration<double, std::micro>(t1 - t0).count() / reps;
    t_gen[round] = std::chrono::duration<double, std::micro>(t2 - t1).count() / reps;
  }
  ocp::linearize_path<ocp::HessianKind::gauss_newton>(prob, x, w, p, xn, lam, lg, a);
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
  std::printf("generated stage (%ld operations) vs linearize_path: max relative difference %.2e\n",
              GeneratedStage::ops, e);
  std::printf(
      "time per path stage, median of 7 rounds of %d: linearize_path %.2f us, "
      "generated %.2f us (%.2f)\n",
      reps, t_lib[3], t_gen[3], t_gen[3] / t_lib[3]);
  return e < 1e-10 ? 0 : 1;
}
