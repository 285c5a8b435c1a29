// sizeof of the caller-owned workspaces for the Kinova Gen3 (the table of docs/api.md): printed
// for the record, and held to budgets so that a field added to a workspace is a visible decision.
// The budgets: the dynamics workspace of a 7-DoF arm fits a small MCU's RAM share (16 KB in
// double), the derivative arrays live outside it (Data alone must stay below the 17 KB it would
// take holding them), and the AutoDiff Jacobian workspace of the dynamics stays below the whole
// NMPC budget of DESIGN.md (256 KB in double).
#include <gtest/gtest.h>

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <arbor/derivatives/derivative_data.hpp>
#include <arbor/dynamics/data.hpp>
#include <cstdio>
#include <robots/kinova_gen3.hpp>

namespace {

using R = arbor::robots::KinovaGen3;
using FD = arbor::ad::ForwardDynamics<R>;
using D21 = arbor::ad::Dual<double, 21>;

TEST(WorkspaceSizes, KinovaGen3) {
  const std::size_t data_d = sizeof(arbor::Data<R, double>);
  const std::size_t data_f = sizeof(arbor::Data<R, float>);
  const std::size_t data_dual = sizeof(arbor::Data<R, D21>);
  const std::size_t deriv_d = sizeof(arbor::DerivativeData<R, double>);
  const std::size_t deriv_f = sizeof(arbor::DerivativeData<R, float>);
  const std::size_t deriv_dual = sizeof(arbor::DerivativeData<R, D21>);
  const std::size_t jac_a = sizeof(arbor::ad::JacobianWorkspace<FD, arbor::ad::Analytical>);
  const std::size_t jac_c = sizeof(arbor::ad::JacobianWorkspace<FD, arbor::ad::AutoDiff>);
  const std::size_t hes_a = sizeof(arbor::ad::HessianWorkspace<FD, arbor::ad::Analytical>);
  const std::size_t hes_c = sizeof(arbor::ad::HessianWorkspace<FD, arbor::ad::AutoDiff>);
  std::printf("Data<Kinova, double / float / Dual<double, 21>>           %7zu %7zu %7zu\n", data_d,
              data_f, data_dual);
  std::printf("DerivativeData<Kinova, double / float / Dual<double, 21>> %7zu %7zu %7zu\n", deriv_d,
              deriv_f, deriv_dual);
  std::printf("FD Jacobian workspace, Analytical / AutoDiff              %7zu %7zu\n", jac_a,
              jac_c);
  std::printf("FD Hessian workspace, Analytical / AutoDiff               %7zu %7zu\n", hes_a,
              hes_c);
  EXPECT_LT(data_d, 16u * 1024);
  EXPECT_LT(data_d, 17024u);  // Data<Kinova, double> with the derivative arrays inside
  EXPECT_LE(data_f * 2, data_d + 64);
  EXPECT_EQ(jac_a, data_d + deriv_d);  // exactly one Data and one DerivativeData
  EXPECT_EQ(jac_c, data_dual);         // exactly one Data at Dual<double, 21>
  EXPECT_LT(jac_c, 256u * 1024);
  EXPECT_GT(hes_a, jac_c);
  EXPECT_GT(hes_c, hes_a);
}

}  // namespace
