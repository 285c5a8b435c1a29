// The providers test (providers_test.cpp): one short closed loop per configuration, each compiled
// in its own translation unit (providers_id_<provider>.cpp: a Kinova controller takes
// ~2 GB of compiler memory) and returned as plain arrays.
#pragma once

#include <array>

#include "alloc_guard.hpp"
#include "closed_loop.hpp"

namespace contour_test {

constexpr int kProviderSamples = 10;

/// What a run returns: the start status, and per sample the status, the control and the plant
/// state.
struct ProviderRun {
  arbor::nmpc::NmpcStatus start = arbor::nmpc::NmpcStatus::not_prepared;
  int start_iterations = 0;
  std::array<arbor::nmpc::NmpcStatus, kProviderSamples> status{};
  std::array<contour::VecN<double, contour::nu>, kProviderSamples> u;
  std::array<contour::VecN<double, contour::nx>, kProviderSamples> x;
};

ProviderRun run_id_analytical();
ProviderRun run_id_autodiff();

/// The closed loop of configuration (F, Tag), hard tunnel, double, real-time iteration, in static
/// storage; every controller call runs inside a NoAllocScope (an allocation fails the test).
template <contour::Formulation F, class Tag>
ProviderRun run_provider() {
  static contour::ContourLoop<F, Tag, false, double> loop([] {
    contour::Options o;
    o.max_samples = kProviderSamples;
    return o;
  }());
  ProviderRun run;
  {
    arbor::test::NoAllocScope guard;
    run.start = loop.start();
  }
  run.start_iterations = loop.start_iterations();
  for (int k = 0; k < kProviderSamples; ++k) {
    contour::Record r;
    {
      arbor::test::NoAllocScope guard;
      loop.sample(r);
    }
    run.status[std::size_t(k)] = r.status;
    run.u[std::size_t(k)] = r.u;
    run.x[std::size_t(k)] = r.x;
  }
  return run;
}

}  // namespace contour_test
