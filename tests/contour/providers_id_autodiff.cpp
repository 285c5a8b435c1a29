// One configuration of the providers test (providers.hpp): OCP-ID, AutoDiff RBD derivatives.
#include "providers.hpp"

contour_test::ProviderRun contour_test::run_id_autodiff() {
  return run_provider<contour::Formulation::id, arbor::ad::AutoDiff>();
}
