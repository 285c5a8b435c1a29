// The contour-following NMPC (examples/contour: Kinova Gen3, OCP-FD, or OCP-ID with
// CONTOUR_TEST_ID=1; analytical RBD derivatives, hard tunnel, real-time iteration) in closed loop
// for 50 samples, on every target that builds it: the host in double and float
// (CONTOUR_TEST_FLOAT=1), the Cortex-M7 in double, the Cortex-M4F in float (the plant, in double,
// is emulated in software there). The loop (controller, plant, workspace)
// lives in static storage; every sample (plant step, shift, prepare, feedback) runs inside a
// NoAllocScope (on bare metal the link-time heap trap does the same). Checked at every sample:
// status, finite controls and states, the tunnel |e_p| <= rho (to 1 um),
// torque, velocity and position limits, s not decreasing, one SQP step per sample; progress at the
// end.
//
// Host runs also write the plant trajectory they produced (contour_trajectory_<fd|id>_<scalar>.inc
// in the working folder, build/tests/contour); a cross build configured with ARBOR_HOST_BUILD_DIR
// compiles that file in (ARBOR_TEST_HOST_VALUES) and checks that the target's trajectory matches
// the host's (tolerance per precision below). On the Cortex-M targets the preparation and feedback
// phases are counted in instructions (SysTick ticks under QEMU's -icount shift=0, calibrated on a
// loop of known length); the test prints their median and maximum over the run.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "arbor_test.hpp"
#include "closed_loop.hpp"
#include "status_names.hpp"

#if defined(ARBOR_BARE_METAL)
#include "arbor_target.h"
#include "bench_util.hpp"  // bench/targets: instructions per SysTick tick, calibrated
#else
#include <cstdio>
#endif

#ifndef CONTOUR_TEST_FLOAT
#define CONTOUR_TEST_FLOAT 0
#endif
#ifndef CONTOUR_TEST_ID
#define CONTOUR_TEST_ID 0
#endif
#ifndef ARBOR_TEST_HOST_VALUES
#define ARBOR_TEST_HOST_VALUES 0
#endif

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {

using namespace contour;
using arbor::nmpc::NmpcStatus;
using Scalar = std::conditional_t<CONTOUR_TEST_FLOAT != 0, float, double>;
constexpr const char* kScalarName = CONTOUR_TEST_FLOAT ? "float" : "double";
constexpr Formulation kForm = CONTOUR_TEST_ID ? Formulation::id : Formulation::fd;
constexpr const char* kFormName = CONTOUR_TEST_ID ? "id" : "fd";
constexpr int kSamples = 50;

#if ARBOR_TEST_HOST_VALUES
// host_x[k][i]: the host's plant state after sample k+1 (same scalar), from the host's run.
#include "contour_trajectory.inc"
static_assert(sizeof(host_x) / sizeof(host_x[0]) == kSamples, "host trajectory of another length");
#endif

#if defined(ARBOR_BARE_METAL)
/// Counts instructions (SysTick ticks x the calibration).
struct InstructionTimer {
  using Stamp = std::uint64_t;
  static Stamp now() { return arbor_ticks(); }
  static double elapsed(Stamp from, Stamp to) {
    return double((to - from) * arbor::bench::insn_per_tick());
  }
};
using Timer = InstructionTimer;
constexpr const char* kUnit = "instructions";
#else
using Timer = SteadyTimer;
constexpr const char* kUnit = "us";
#endif

using Loop = ContourLoop<kForm, arbor::ad::Analytical, false, Scalar, Timer>;
#ifndef CONTOUR_FEEDBACK_ITER
#define CONTOUR_FEEDBACK_ITER 0
#endif
#ifndef CONTOUR_PRESOLVE
#define CONTOUR_PRESOLVE 0
#endif
Options make_options() {
  Options o;
  o.max_samples = kSamples;
  o.feedback_qp_iter = CONTOUR_FEEDBACK_ITER;  // (the build's ARBOR_CONTOUR_FEEDBACK_ITER)
  o.presolve = CONTOUR_PRESOLVE != 0;          // (the build's ARBOR_CONTOUR_PRESOLVE)
  return o;
}
Loop g_loop(make_options());  // ~320 KB in double: static storage, not the stack
std::array<Record, kSamples> g_records;

/// Median and maximum of v[0..n).
template <std::size_t M>
void median_max(std::array<double, M> v, double& median, double& max) {
  std::sort(v.begin(), v.end());
  median = v[M / 2];
  max = v[M - 1];
}

/// Median, 95th percentile (the ceil(0.95 n)-th smallest; with 50 samples the p99 is the
/// maximum) and maximum of the per-sample costs v, printed as one CONTOUR line.
template <std::size_t M>
void report(const char* what, std::array<double, M> v) {
  std::sort(v.begin(), v.end());
  const double median = v[M / 2], p95 = v[(95 * M + 99) / 100 - 1], max = v[M - 1];
#if defined(ARBOR_BARE_METAL)
  arbor::minitest::out() << "CONTOUR " << kFormName << " " << kScalarName << " " << what
                         << " median " << static_cast<long long>(median) << " p95 "
                         << static_cast<long long>(p95) << " max " << static_cast<long long>(max)
                         << " " << kUnit << "\n";
  arbor::minitest::out().flush();
#else
  std::printf("CONTOUR %s %s %s median %.0f p95 %.0f max %.0f %s\n", kFormName, kScalarName, what,
              median, p95, max, kUnit);
#endif
}

#if !defined(ARBOR_BARE_METAL) && !defined(__aarch64__) && !defined(__arm__)
/// Writes the trajectory for the cross builds (see the top of the file).
void write_trajectory() {
  char name[64];
  std::snprintf(name, sizeof name, "contour_trajectory_%s_%s.inc", kFormName, kScalarName);
  std::FILE* f = std::fopen(name, "w");
  ASSERT_NE(f, nullptr) << "cannot write " << name;
  std::fprintf(f,
               "// written by contour_target_%s_test on the host (tests/contour/target_test.cpp)\n",
               kScalarName);
  std::fprintf(f, "constexpr double host_x[%d][%d] = {\n", kSamples, nx);
  for (const Record& r : g_records) {
    std::fprintf(f, "    {");
    for (int i = 0; i < nx; ++i)
      std::fprintf(f, "%s%.17g", i ? ", " : "", r.x[i]);
    std::fprintf(f, "},\n");
  }
  std::fprintf(f, "};\n");
  std::fclose(f);
}
#endif

// Tolerances per precision. Tunnel: the controller plans inside rho - 1 mm (task.hpp's
// default_backoff); the plant stays inside rho in both precisions (float with mpc.hpp's
// float_qp_tol_primal).
constexpr double kTunnelTol = 1e-6;
// Torque limits: OCP-FD applies u_0's torque, bounded exactly; OCP-ID bounds ID(q, qd, qdd) at the
// plan's nodes, while the plant's 1 kHz computed-torque loop evaluates it along the true motion.
constexpr double kTauTol = CONTOUR_TEST_ID ? 1e-2 : 1e-9;
// Trajectory against the host's, relative to 1 + |x_i|: the same algorithm compiled for another
// instruction set (FMA contraction, libm) differs in the last bits, which the closed loop
// amplifies. Double: 1e-6 for every state. Float: the controller's linearisation and QP in 24 bits
// give slightly different torques in two builds, each held over the 0.02 s sample: the joint
// velocities show it most, the positions integrate it. Measured on the host over these 50 samples,
// float built with and without FMA contraction (-mfma -ffp-contract=fast; the Cortex-M4F
// contracts too): with the former float QP primal tolerance 1e-6 (OCP-FD) q, s within 5.5e-5,
// qd, sd within 9.5e-3; with today's 3e-5 (float_qp_tol_primal) OCP-FD 2.9e-7 and 1.8e-5, OCP-ID
// 4.9e-6 and 1.1e-4; the Cortex-M4F against the host (bench/nmpc/RESULTS-targets.md, e512db4):
// OCP-FD 3.0e-6 and 5.0e-4, OCP-ID 9.0e-8 and 2.9e-6. The tolerances are about 4x the largest:
// 2e-5 for the positions (q, s), 2e-3 for the velocities (qd, sd) (were 2e-4 and 4e-2, set on the
// former figures).
[[maybe_unused]] constexpr double kTrajectoryTolPos = CONTOUR_TEST_FLOAT ? 2e-5 : 1e-6;
[[maybe_unused]] constexpr double kTrajectoryTolVel = CONTOUR_TEST_FLOAT ? 2e-3 : 1e-6;

TEST(ContourTarget, ClosedLoop50Samples) {
#if defined(ARBOR_BARE_METAL)
  arbor::bench::calibrate();
  ASSERT_GT(arbor::bench::insn_per_tick(), 0u);
#endif
  {
    arbor::test::NoAllocScope guard;
    const NmpcStatus st = g_loop.start();
    ASSERT_EQ(st, NmpcStatus::converged);
  }
  double s_prev = 0, tau_ratio = 0;
  [[maybe_unused]] double dev_pos = 0, dev_vel = 0;  // largest deviation from the host's run
  for (int k = 0; k < kSamples; ++k) {
    Record& r = g_records[std::size_t(k)];
    {
      arbor::test::NoAllocScope guard;
      g_loop.sample(r);
    }
    ASSERT_TRUE(arbor::nmpc::succeeded(r.status)) << "sample " << k << ": " << r.status;
    ASSERT_TRUE(r.u.allFinite()) << "sample " << k;
    ASSERT_TRUE(r.x.allFinite()) << "sample " << k;
    EXPECT_LE(r.e_p, rho + kTunnelTol) << "sample " << k;
    for (int i = 0; i < nq; ++i) {
      EXPECT_LE(r.tau_peak[i], tau_max[std::size_t(i)] * (1 + kTauTol)) << "sample " << k;
      tau_ratio = std::max(tau_ratio, r.tau_peak[i] / tau_max[std::size_t(i)]);
      EXPECT_LE(std::fabs(r.x[nq + i]), qd_max * (1 + 1e-3)) << "sample " << k;
      if (std::isfinite(q_max[std::size_t(i)])) {
        EXPECT_LE(std::fabs(r.x[i]), q_max[std::size_t(i)]) << "sample " << k;
      }
    }
    EXPECT_GE(r.x[14], s_prev) << "sample " << k;
    s_prev = r.x[14];
    EXPECT_EQ(r.sqp_iterations, 1) << "sample " << k;
#if ARBOR_TEST_HOST_VALUES
    for (int i = 0; i < nx; ++i) {
      const double h = host_x[k][i];
      const bool velocity = (i >= nq && i < 2 * nq) || i == nx - 1;  // qd, sd
      const double tol = velocity ? kTrajectoryTolVel : kTrajectoryTolPos;
      const double d = std::fabs(r.x[i] - h) / (1 + std::fabs(h));
      (velocity ? dev_vel : dev_pos) = std::max(velocity ? dev_vel : dev_pos, d);
      EXPECT_LE(std::fabs(r.x[i] - h), tol * (1 + std::fabs(h)))
          << "sample " << k << " state " << i << ": target " << r.x[i] << ", host " << h;
    }
#endif
  }
  // progress along the path: s follows sd_ref from rest (sd_ref(0) = 0.0515 c)
  EXPECT_GT(s_prev, 0.01);

  // QP iterations per sample (one warm-started QP each). Measured on the host in double over
  // these 50 samples (bench/nmpc/rti_qp_diag.cpp): OCP-FD 132 in all, OCP-ID 92, since the
  // multipliers stay in place across shift() and a warm start steps on its working set before
  // adding constraints; 597 and 119 before (shifted multipliers: the tunnel's active stages one
  // stage off every sample). The bound, 4 per sample on average, fails the former OCP-FD loop
  // and leaves 1.5x margin for another instruction set. Float (closed_loop.hpp's float QP
  // tolerance and back-off): host OCP-FD 112, OCP-ID 89; Cortex-M4F 113 and 89; with the former
  // float tolerance 1e-6 OCP-FD took 696 (the bound fails it).
  int qp_total = 0;
  std::array<double, kSamples> qp_its{};
  for (int k = 0; k < kSamples; ++k) {
    qp_its[std::size_t(k)] = g_records[std::size_t(k)].qp_iterations;
    qp_total += g_records[std::size_t(k)].qp_iterations;
  }
  EXPECT_LE(qp_total, 4 * kSamples);
  double qp_med = 0, qp_max = 0;
  median_max(qp_its, qp_med, qp_max);
#if defined(ARBOR_BARE_METAL)
  arbor::minitest::out() << "CONTOUR " << kFormName << " " << kScalarName
                         << " QP iterations per sample median " << static_cast<long long>(qp_med)
                         << " max " << static_cast<long long>(qp_max) << " total "
                         << static_cast<long long>(qp_total) << "\n";
  arbor::minitest::out().flush();
#else
  std::printf("CONTOUR %s %s QP iterations per sample median %.0f max %.0f total %d\n", kFormName,
              kScalarName, qp_med, qp_max, qp_total);
#endif

  std::array<double, kSamples> prep{}, fb{}, both{};
  for (int k = 0; k < kSamples; ++k) {
    prep[std::size_t(k)] = g_records[std::size_t(k)].prepare_us;
    fb[std::size_t(k)] = g_records[std::size_t(k)].feedback_us;
    both[std::size_t(k)] = prep[std::size_t(k)] + fb[std::size_t(k)];
  }
  report("preparation", prep);
  report("feedback", fb);
  report("sample", both);
#if defined(ARBOR_BARE_METAL)
  arbor::minitest::out() << "CONTOUR " << kFormName << " " << kScalarName << " max-tau/limit "
                         << tau_ratio << " s " << s_prev << "\n";
#if ARBOR_TEST_HOST_VALUES
  arbor::minitest::out() << "CONTOUR " << kFormName << " " << kScalarName
                         << " deviation from the host (relative): q, s " << dev_pos << "; qd, sd "
                         << dev_vel << "\n";
#endif
  arbor::minitest::out().flush();
#else
  std::printf("CONTOUR %s %s max-tau/limit %.6g s %.6g\n", kFormName, kScalarName, tau_ratio,
              s_prev);
#endif
#if !defined(ARBOR_BARE_METAL) && !defined(__aarch64__) && !defined(__arm__)
  write_trajectory();
#endif
}

}  // namespace
