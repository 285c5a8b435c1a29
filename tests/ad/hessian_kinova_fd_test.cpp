// The nested-dual and dual-through-analytical Hessians of lambda^T FD for the Kinova Gen3
// (hessian_checks.hpp), a unit of its own: hessian_test.cpp and hessian_kinova_id_test.cpp were one
// unit of 2.2 GB of compiler memory. Compiled at -O0, like hessian_test.cpp.
#include <robots/kinova_gen3.hpp>

#include "hessian_checks.hpp"

namespace {

using namespace arbor;

TEST(AdHessian, KinovaGen3ForwardDynamics) {
  arbor::test::hessian_checks::hessians_agree<ad::ForwardDynamics<robots::KinovaGen3>>(4);
}

}  // namespace
