// A short closed loop of the contour-following NMPC (examples/contour) against its plant: OCP-FD,
// analytical RBD derivatives, hard tunnel, real-time iteration, in double and float. Every sample
// (plant step, shift, prepare, feedback) runs inside a NoAllocScope; the plant must stay in the
// tunnel (up to the controller's back-off margin), within the torque and velocity limits, with
// finite controls and s increasing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "alloc_guard.hpp"
#include "closed_loop.hpp"

namespace {

using namespace contour;
using arbor::nmpc::NmpcStatus;

constexpr int kSamples = 40;

template <class Loop>
void run_closed_loop(Loop& loop, double tunnel_tol) {
  std::printf("sizeof controller %zu bytes, RBD workspace %zu bytes\n",
              sizeof(typename Loop::Controller), sizeof(typename Loop::W));
  {
    arbor::test::NoAllocScope guard;
    const NmpcStatus st = loop.start();
    ASSERT_EQ(st, NmpcStatus::converged) << arbor::nmpc::to_string(st);
  }
  double s_prev = 0;
  for (int k = 0; k < kSamples; ++k) {
    Record r;
    {
      arbor::test::NoAllocScope guard;
      loop.sample(r);
    }
    ASSERT_TRUE(arbor::nmpc::succeeded(r.status))
        << "sample " << k << ": " << arbor::nmpc::to_string(r.status);
    ASSERT_TRUE(r.u.allFinite()) << "sample " << k;
    ASSERT_TRUE(r.x.allFinite()) << "sample " << k;
    EXPECT_LE(r.e_p, rho + tunnel_tol) << "sample " << k;
    for (int i = 0; i < nq; ++i) {
      EXPECT_LE(r.tau_peak[i], tau_max[std::size_t(i)] * (1 + 1e-9)) << "sample " << k;
      EXPECT_LE(std::fabs(r.x[nq + i]), qd_max * (1 + 1e-3)) << "sample " << k;
      if (std::isfinite(q_max[std::size_t(i)])) {
        EXPECT_LE(std::fabs(r.x[i]), q_max[std::size_t(i)]) << "sample " << k;
      }
    }
    EXPECT_GE(r.x[14], s_prev) << "sample " << k;
    s_prev = r.x[14];
    EXPECT_EQ(r.sqp_iterations, 1) << "sample " << k;
  }
  // progress along the path: s follows sd_ref from rest (sd_ref(0) = 0.0515 c)
  EXPECT_GT(s_prev, 0.01);
}

// One scalar per executable (CONTOUR_TEST_FLOAT), to keep each translation unit's compile memory
// below 2 GB.
#if CONTOUR_TEST_FLOAT
TEST(ContourClosedLoop, OcpFdAnalyticalFloat) {
  Options o;
  o.max_samples = kSamples;
  static ContourLoop<Formulation::fd, arbor::ad::Analytical, false, float> loop(o);
  run_closed_loop(loop, 1e-4);
}
#else
TEST(ContourClosedLoop, OcpFdAnalyticalDouble) {
  Options o;
  o.max_samples = kSamples;
  static ContourLoop<Formulation::fd, arbor::ad::Analytical, false, double> loop(o);
  run_closed_loop(loop, 1e-6);
}
#endif

}  // namespace
