// Instructions of the real-time iteration's preparation phase (Nmpc::prepare()) on the paper's
// contour NMPC (examples/contour: OCP-FD, analytical RBD derivatives, hard tunnel, double), for
// callgrind. The example's own closed loop (ContourLoop::sample()) runs with a timer that turns
// callgrind's collection on around prepare() only (so feedback, shift and the plant are not
// counted); after each sample the QP that prepare() built is written to a binary file (--dump)
// or compared with such a file (--compare: max |a - b| / (1 + |b|) over every QP entry, and the
// controls), so that a change of the linearisation can be checked to change nothing beyond
// round-off. Before the closed loop, one prepare() at a fixed plan (no solver before it, so that
// only the linearisation's round-off can differ; the closed loop's QP data also carry the
// solvers' tolerances, amplified along the loop) is written/compared first; it is not counted
// by callgrind (the callgrind macros toggle in the loop's timer only).
//
//   valgrind --tool=callgrind --collect-atstart=no prepare_cg SAMPLES [--dump F | --compare F]
//
// Build (no -march=native, as the Cortex-M7 build):
//   g++ -std=c++20 -O3 -DNDEBUG -Iinclude -Iexamples/contour -I<build>/examples/robots/
//       arbor_robot_kinova_gen3_gen -isystem /usr/include/eigen3 bench/nmpc/prepare_cg.cpp
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "closed_loop.hpp"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define PREP_CG_TOGGLE CALLGRIND_TOGGLE_COLLECT
#else
#define PREP_CG_TOGGLE
#endif

namespace {

/// ContourLoop::sample() calls now() three times: before prepare(), after it, after feedback().
/// Collection is toggled at the first two.
struct PrepareTimer {
  using Stamp = int;
  static inline int calls = 0;
  static Stamp now() {
    const int c = calls++ % 3;
    if (c != 2)
      PREP_CG_TOGGLE;
    return c;
  }
  static double elapsed(Stamp, Stamp) { return 0; }
};

using Loop = contour::ContourLoop<contour::Formulation::fd, arbor::ad::Analytical, false, double,
                                  PrepareTimer>;

/// Appends every entry of the QP's stage data (not the variable bounds) to v.
template <class Qp>
void flatten(const Qp& qp, std::vector<double>& v) {
  auto add = [&v](const auto& m) {
    for (int i = 0; i < int(m.size()); ++i)
      v.push_back(m.data()[i]);
  };
  for (const auto& st : qp.stage) {
    add(st.Q), add(st.S), add(st.R), add(st.q), add(st.r), add(st.A), add(st.B), add(st.b);
    add(st.C), add(st.D), add(st.lg), add(st.ug);
  }
  add(qp.terminal.Q), add(qp.terminal.q), add(qp.terminal.C), add(qp.terminal.lg);
  add(qp.terminal.ug);
}

}  // namespace

int main(int argc, char** argv) {
  const int samples = argc > 1 ? std::atoi(argv[1]) : 20;
  const char* dump = argc > 3 && std::strcmp(argv[2], "--dump") == 0 ? argv[3] : nullptr;
  const char* cmp = argc > 3 && std::strcmp(argv[2], "--compare") == 0 ? argv[3] : nullptr;
  contour::Options o;
  const auto loop = std::make_unique<Loop>(o);
  std::vector<double> data;
  {  // first: one linearisation at a fixed plan (no solver in between: only round-off differs)
    auto& c = loop->controller();
    for (int k = 0; k <= contour::horizon; ++k) {
      Loop::Controller::Vp p = Loop::Controller::Vp::Zero();  // d = 0
      p[0] = k == 0 ? 0 : 1;
      c.set_parameter(k, p);
      Loop::Controller::Vx x = Loop::Controller::Vx::Zero();
      x.head<contour::nq>() = contour::initial_q();
      for (int i = 0; i < contour::nx; ++i)
        x[i] += 0.05 * std::sin(1.3 * i + 0.7 * k);
      x[14] = 0.01 * k;
      x[15] = 0.1 + 0.01 * k;
      (void)c.set_state_guess(k, x);
      if (k < contour::horizon) {
        Loop::Controller::Vu u;
        for (int i = 0; i < contour::nu; ++i)
          u[i] = 2 * std::cos(0.9 * i + 0.4 * k);
        (void)c.set_input_guess(k, u);
      }
    }
    if (c.prepare() != arbor::nmpc::NmpcStatus::prepared) {
      std::printf("fixed-point prepare failed\n");
      return 1;
    }
    flatten(c.qp(), data);
    for (int i = 0; i < contour::nu; ++i)
      data.push_back(0);
    PrepareTimer::calls = 0;
  }
  if (loop->start() != arbor::nmpc::NmpcStatus::converged) {
    std::printf("start failed\n");
    return 1;
  }
  contour::Record rec;
  for (int n = 0; n < samples; ++n) {
    loop->sample(rec);
    flatten(loop->controller().qp(), data);
    for (int i = 0; i < contour::nu; ++i)
      data.push_back(rec.u[i]);
  }
  std::printf("samples %d, last status %s, s %.6f, |e_p| %.3e\n", samples,
              arbor::nmpc::to_string(rec.status), rec.x[14], rec.e_p);
  if (dump) {
    FILE* f = std::fopen(dump, "wb");
    std::fwrite(data.data(), sizeof(double), data.size(), f);
    std::fclose(f);
  }
  if (cmp) {
    std::vector<double> ref(data.size());
    FILE* f = std::fopen(cmp, "rb");
    const std::size_t got = std::fread(ref.data(), sizeof(double), ref.size(), f);
    std::fclose(f);
    if (got != ref.size()) {
      std::printf("compare: size mismatch\n");
      return 1;
    }
    double worst = 0;
    std::size_t at = 0;
    const std::size_t per = ref.size() / std::size_t(samples + 1);
    for (std::size_t i = 0; i < ref.size(); ++i) {
      if (i == per)
        std::printf("  fixed plan: %.3e\n", worst);
      else if (i % per == 0 && i > 0)
        std::printf("  up to sample %zu: %.3e\n", i / per - 2, worst);
      const double a = data[i], b = ref[i];
      double e = 0;
      if (std::isinf(a) || std::isinf(b))
        e = a == b ? 0 : INFINITY;
      else
        e = std::fabs(a - b) / (1 + std::fabs(b));
      if (!(e <= worst)) {
        worst = e;
        at = i;
      }
    }
    std::printf("compare: max |a - b| / (1 + |b|) = %.3e at entry %zu of %zu\n", worst, at,
                ref.size());
  }
  return 0;
}
