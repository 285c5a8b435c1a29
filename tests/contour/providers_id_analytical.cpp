// One configuration of the providers test (providers.hpp): OCP-ID, Analytical RBD derivatives.
#include "providers.hpp"

contour_test::ProviderRun contour_test::run_id_analytical() {
  return run_provider<contour::Formulation::id, arbor::ad::Analytical>();
}
