#include <gtest/gtest.h>
#include "alloc_guard.hpp"
#include "arbor/nmpc/controller.hpp"
#include "problems.hpp"
#include "status_names.hpp"
namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}
namespace arbor::qp {
using ::arbor::test::status_names::operator<<;
}

TEST(NmpcSmoke, PendulumSwingUp) {
  auto problem = nmpc_test::pendulum_problem<40>();
  using Ctrl = arbor::nmpc::Nmpc<decltype(problem), double>;
  static Ctrl* ctrl = new Ctrl(problem);
  Eigen::Vector2d x0(0, 0);
  (void)ctrl->set_initial_guess(x0, Eigen::Matrix<double, 1, 1>::Zero());
  arbor::nmpc::NmpcStatus st;
  {
    arbor::test::NoAllocScope guard;
    st = ctrl->solve(x0);
  }
  const auto& in = ctrl->info();
  printf("status %s it %d qp_it %d stat %g pr %g comp %g alpha %g\n", to_string(st), in.iterations,
         in.qp_iterations, in.stationarity, in.primal_residual, in.complementarity, in.step_size);
  for (int k = 0; k <= 40; k += 5)
    printf("x%d = %g %g\n", k, ctrl->state(k)[0], ctrl->state(k)[1]);
  EXPECT_EQ(st, arbor::nmpc::NmpcStatus::converged);
}
