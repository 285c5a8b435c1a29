// The OCP solver the QP tests run: the default backend, or, in the test executables built with
// ARBOR_QP_TEST_RICCATI (the *_riccati_test targets of tests/qp/CMakeLists.txt), the
// exact-dynamics Riccati backend (ocp_riccati_backend.hpp). Same tests, same tolerances.
#pragma once

#include "arbor/qp/ocp_qp_solver.hpp"

namespace arbor::qp::test {

#if defined(ARBOR_QP_TEST_RICCATI)
template <typename Qp>
using OcpQpSolver = ::arbor::qp::OcpQpSolver<Qp, typename detail::RiccatiOcpBackend<Qp>::type>;
#else
template <typename Qp>
using OcpQpSolver = ::arbor::qp::OcpQpSolver<Qp>;
#endif

}  // namespace arbor::qp::test
