// Portable checks of the first-order derivatives (rnea_derivatives, aba_derivatives) against the
// Pinocchio reference values, for the targets (host, Cortex-M7) via arbor_test.hpp: the same
// quantities and tolerances as tests/derivatives/reference_test.cpp.in on the host (drnea_dq,
// drnea_dv, M, tau; daba_dq, daba_dv, M^-1, ddq), read from constexpr arrays instead of files.
// Errors are norm-wise relative, as in rbd_target_checks.hpp. Cost per sample: one call of each.
#pragma once

#include <string_view>

#include "arbor/derivatives/derivatives.hpp"
#include "rbd_target_checks.hpp"

namespace arbor::test {

/// Pointers into one robot's constexpr derivative reference arrays (reference_header.cmake with
/// the derivative keys).
struct DerivRefView {
  int nv;                             ///< DoF
  int samples;                        ///< number of samples
  const std::string_view* joints;     ///< the reference's joint order
  const double *q, *v, *a, *tau;      ///< inputs, [samples][nv]
  const double *rnea, *aba;           ///< tau = ID(q, v, a), ddq = FD(q, v, tau)
  const double *crba, *minv;          ///< M, M^-1, [samples][nv * nv]
  const double *drnea_dq, *drnea_dv;  ///< [samples][nv * nv]
  const double *daba_dq, *daba_dv;    ///< [samples][nv * nv]
};

#define ARBOR_DERIV_REF_VIEW(ns)                                                                \
  ::arbor::test::DerivRefView {                                                                 \
    ns::nv, ns::samples, ns::joints, &ns::q[0][0], &ns::v[0][0], &ns::a[0][0], &ns::tau[0][0],  \
        &ns::rnea[0][0], &ns::aba[0][0], &ns::crba[0][0], &ns::minv[0][0], &ns::drnea_dq[0][0], \
        &ns::drnea_dv[0][0], &ns::daba_dq[0][0], &ns::daba_dv[0][0]                             \
  }

struct DerivErrors {
  double dtau_dq = 0, dtau_dv = 0, M = 0, tau = 0;   ///< rnea_derivatives
  double ddq_dq = 0, ddq_dv = 0, Minv = 0, ddq = 0;  ///< aba_derivatives
};

/// Runs rnea_derivatives and aba_derivatives on every reference sample and returns the largest
/// relative error of each output.
template <Robot R, class S>
DerivErrors derivative_errors(const DerivRefView& ref) {
  using D = Data<R, S>;
  static D data;  // static storage, as firmware would keep it
  static DerivativeData<R, S> deriv;
  const RefCompare<R> cmp(ref.joints, ref.nv);
  auto rel_vec = [&](const typename D::Vector& x, const double* r) { return cmp.vec(x, r); };
  auto rel_mat = [&](const typename D::Matrix& X, const double* r) { return cmp.mat(X, r); };
  DerivErrors e;
  typename D::Vector q, v, a, tau;
  for (int k = 0; k < ref.samples; ++k) {
    const int o = k * ref.nv;
    for (int i = 0; i < R::nv; ++i) {
      q[i] = S(ref.q[o + cmp.perm[i]]);
      v[i] = S(ref.v[o + cmp.perm[i]]);
      a[i] = S(ref.a[o + cmp.perm[i]]);
      tau[i] = S(ref.tau[o + cmp.perm[i]]);
    }
    const int om = k * ref.nv * ref.nv;
    NoAllocScope guard;
    rnea_derivatives<R>(data, deriv, q, v, a);
    e.dtau_dq = larger(e.dtau_dq, rel_mat(deriv.dtau_dq, ref.drnea_dq + om));
    e.dtau_dv = larger(e.dtau_dv, rel_mat(deriv.dtau_dv, ref.drnea_dv + om));
    e.M = larger(e.M, rel_mat(data.M, ref.crba + om));
    e.tau = larger(e.tau, rel_vec(data.tau, ref.rnea + o));
    aba_derivatives<R>(data, deriv, q, v, tau);
    e.ddq_dq = larger(e.ddq_dq, rel_mat(deriv.ddq_dq, ref.daba_dq + om));
    e.ddq_dv = larger(e.ddq_dv, rel_mat(deriv.ddq_dv, ref.daba_dv + om));
    e.Minv = larger(e.Minv, rel_mat(data.Minv, ref.minv + om));
    e.ddq = larger(e.ddq, rel_vec(data.ddq, ref.aba + o));
  }
  return e;
}

/// Prints the errors (one line), on the console of whatever runs the test.
inline void log_errors(const char* what, const DerivErrors& e) {
#if defined(ARBOR_BARE_METAL)
  minitest::out() << "    " << what << ": dtau_dq " << e.dtau_dq << " dtau_dv " << e.dtau_dv
                  << " M " << e.M << " tau " << e.tau << " ddq_dq " << e.ddq_dq << " ddq_dv "
                  << e.ddq_dv << " Minv " << e.Minv << " ddq " << e.ddq << "\n";
#else
  std::printf(
      "    %s: dtau_dq %.3g dtau_dv %.3g M %.3g tau %.3g ddq_dq %.3g ddq_dv %.3g Minv %.3g ddq "
      "%.3g\n",
      what, e.dtau_dq, e.dtau_dv, e.M, e.tau, e.ddq_dq, e.ddq_dv, e.Minv, e.ddq);
#endif
}

/// The checks of tests/derivatives' reference test: inverse-dynamics outputs within tol_id,
/// forward-dynamics outputs within tol_fd (norm-wise relative).
template <Robot R, class S>
void check_derivatives_against_reference(const DerivRefView& ref, double tol_id, double tol_fd) {
  bool joints_found = ref.nv == R::nv;  // the same joint set, in any order
  for (int i = 0; joints_found && i < R::nv; ++i) {
    bool found = false;
    for (int j = 0; j < ref.nv; ++j)
      found = found || ref.joints[j] == R::joint_names[i];
    joints_found = found;
  }
  ASSERT_TRUE(joints_found);
  const DerivErrors e = derivative_errors<R, S>(ref);
  log_errors(sizeof(S) == 8 ? "max relative error vs reference (double)"
                            : "max relative error vs reference (float)",
             e);
  EXPECT_LE(e.dtau_dq, tol_id) << "drnea_dq";
  EXPECT_LE(e.dtau_dv, tol_id) << "drnea_dv";
  EXPECT_LE(e.M, tol_id) << "M";
  EXPECT_LE(e.tau, tol_id) << "tau";
  EXPECT_LE(e.ddq_dq, tol_fd) << "daba_dq";
  EXPECT_LE(e.ddq_dv, tol_fd) << "daba_dv";
  EXPECT_LE(e.Minv, tol_fd) << "Minv";
  EXPECT_LE(e.ddq, tol_fd) << "ddq";
}

}  // namespace arbor::test
