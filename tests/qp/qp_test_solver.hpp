// The OCP solvers the QP tests run. OcpQpSolver: the default (Riccati) backend or, in the test
// executable built with ARBOR_QP_TEST_PENALISED (qp_penalised_test in tests/qp/CMakeLists.txt),
// the penalised block elimination that was the default before it (ocp_backend.hpp). The checks
// of random problems (qp_ocp_check.hpp, qp_float_test.cpp) run both backends on every problem,
// against one dense reference: PenalisedOcpQpSolver is the second one. Same tests, same
// tolerances.
#pragma once

#include "arbor/qp/ocp_qp_solver.hpp"

namespace arbor::qp::test {

/// The former default backend (ocp_backend.hpp), opt-in.
template <typename Qp>
using PenalisedOcpQpSolver =
    ::arbor::qp::OcpQpSolver<Qp, typename detail::PenalisedOcpBackend<Qp>::type>;

#if defined(ARBOR_QP_TEST_PENALISED)
template <typename Qp>
using OcpQpSolver = PenalisedOcpQpSolver<Qp>;
#else
template <typename Qp>
using OcpQpSolver = ::arbor::qp::OcpQpSolver<Qp>;
#endif

}  // namespace arbor::qp::test
