// The nested-dual and dual-through-analytical Hessians of lambda^T ID for the Kinova Gen3
// (hessian_checks.hpp), a unit of its own: hessian_test.cpp and hessian_kinova_fd_test.cpp were one
// unit of 2.2 GB of compiler memory. Compiled at -O0, like hessian_test.cpp.
#include <robots/kinova_gen3.hpp>

#include "hessian_checks.hpp"

namespace {

using namespace arbor;

TEST(AdHessian, KinovaGen3InverseDynamics) {
  arbor::test::hessian_checks::hessians_agree<ad::InverseDynamics<robots::KinovaGen3>>(5);
}

}  // namespace
