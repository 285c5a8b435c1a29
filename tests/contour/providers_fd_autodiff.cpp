// One configuration of the providers test (providers.hpp): OCP-FD, AutoDiff RBD derivatives.
#include "providers.hpp"

contour_test::ProviderRun contour_test::run_fd_autodiff() {
  return run_provider<contour::Formulation::fd, arbor::ad::AutoDiff>();
}
