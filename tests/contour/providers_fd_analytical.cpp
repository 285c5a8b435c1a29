// One configuration of the providers test (providers.hpp): OCP-FD, Analytical RBD derivatives.
#include "providers.hpp"

contour_test::ProviderRun contour_test::run_fd_analytical() {
  return run_provider<contour::Formulation::fd, arbor::ad::Analytical>();
}
