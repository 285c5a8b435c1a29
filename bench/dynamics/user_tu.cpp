// A user's translation unit for instruction counts (bench/dynamics/user_tu_counts.sh): one
// program that calls one algorithm (ARBOR_UT_ALGO_ID: 1 rnea, 2 crba, 3 aba, 4 minverse,
// 5 rnea_derivatives, 6 aba_derivatives) of one robot (ARBOR_UT_ROBOT_HEADER, ARBOR_UT_STRUCT) N
// times on a cycle of 16 random inputs, as a user would (no benchmark framework, the library's own
// inlining), the method of ../shared/reference/pinocchio_counts.md: instructions per call =
// (I(1200) - I(200)) / 1000 under callgrind. With a second argument ("time"), the CPU time of the
// call loop per call is printed to stderr in nanoseconds (bench/dynamics/user_tu_times.sh).
#include ARBOR_UT_ROBOT_HEADER

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include "arbor/derivatives/derivatives.hpp"
#include "arbor/dynamics/dynamics.hpp"

using R = arbor::robots::ARBOR_UT_STRUCT;
using D = arbor::Data<R, double>;

static D d;
static arbor::DerivativeData<R, double> dd;
static D::Vector q[16], v[16], a[16], tau[16];

int main(int argc, char** argv) {
  const int calls = argc > 1 ? std::atoi(argv[1]) : 1;
  unsigned s = 12345;
  auto next = [&] {
    s = s * 1664525u + 1013904223u;
    return double(s >> 8) / double(1u << 24) * 2.0 - 1.0;
  };
  for (int k = 0; k < 16; ++k)
    for (int i = 0; i < R::nv; ++i) {
      q[k][i] = next();
      v[k][i] = next();
      a[k][i] = next();
      tau[k][i] = 10.0 * next();
    }
  double sink = 0;
  timespec t0{}, t1{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t0);
  for (int c = 0; c < calls; ++c) {
    const int k = c & 15;
#if ARBOR_UT_ALGO_ID == 1
    sink += arbor::rnea<R>(d, q[k], v[k], a[k])[0];
#elif ARBOR_UT_ALGO_ID == 2
    sink += arbor::crba<R>(d, q[k])(0, 0);
#elif ARBOR_UT_ALGO_ID == 3
    sink += arbor::aba<R>(d, q[k], v[k], tau[k])[0];
#elif ARBOR_UT_ALGO_ID == 4
    sink += arbor::minverse<R>(d, q[k])(0, 0);
#elif ARBOR_UT_ALGO_ID == 5
    arbor::rnea_derivatives<R>(d, dd, q[k], v[k], a[k]);
    sink += dd.dtau_dq(0, 0);
#elif ARBOR_UT_ALGO_ID == 6
    arbor::aba_derivatives<R>(d, dd, q[k], v[k], tau[k]);
    sink += dd.ddq_dq(0, 0);
#else
#error "ARBOR_UT_ALGO_ID: 1..6"
#endif
  }
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t1);
  if (argc > 2 && std::strcmp(argv[2], "time") == 0)
    std::fprintf(stderr, "%.3f\n",
                 (double(t1.tv_sec - t0.tv_sec) * 1e9 + double(t1.tv_nsec - t0.tv_nsec)) / calls);
  std::printf("%g\n", sink);
  return 0;
}
