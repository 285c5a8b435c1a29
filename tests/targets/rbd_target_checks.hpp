// Portable checks of the RBD core against the Pinocchio reference values, for any Scalar. Used by
// the host, AArch64 and the bare-metal targets (via the minitest harness): no files, no heap.
// Errors are norm-wise relative: max |ours - ref| / max(1, max |ref|) over a vector or matrix,
// which is what the ill-conditioned quantities (M^-1 and FD of long chains) allow.
#pragma once

#include <cmath>
#include <cstdio>
#include <string_view>

#include "arbor/dynamics/dynamics.hpp"
#include "arbor_test.hpp"

namespace arbor::test {

/// Pointers into one robot's constexpr reference arrays (tests/targets/reference_header.cmake).
struct RefView {
  int nv;                                    ///< DoF
  int samples;                               ///< number of samples
  const std::string_view* joints;            ///< the reference's joint order
  const double *q, *v, *a, *tau;             ///< inputs, [samples][nv]
  const double *rnea, *aba, *gravity, *nle;  ///< vector outputs, [samples][nv]
  const double *crba, *minv;                 ///< matrix outputs, [samples][nv * nv]
};

#define ARBOR_REF_VIEW(ns)                                                                     \
  ::arbor::test::RefView {                                                                     \
    ns::nv, ns::samples, ns::joints, &ns::q[0][0], &ns::v[0][0], &ns::a[0][0], &ns::tau[0][0], \
        &ns::rnea[0][0], &ns::aba[0][0], &ns::gravity[0][0], &ns::nle[0][0], &ns::crba[0][0],  \
        &ns::minv[0][0]                                                                        \
  }

/// Norm-wise relative tolerances per quantity and scalar.
template <class S>
struct Tolerance;
template <>
struct Tolerance<double> {
  static constexpr double id = 1e-9;    ///< rnea, gravity, nle
  static constexpr double mass = 1e-9;  ///< crba
  static constexpr double fd = 1e-8;    ///< aba, minverse (conditioning of M)
};
template <>
struct Tolerance<float> {
  static constexpr double id = 5e-6;
  static constexpr double mass = 5e-6;
  static constexpr double fd = 5e-5;
};

/// Runs rnea, gravity, nle, crba, aba and minverse on every reference sample and returns the
/// largest relative error of each, so that a test can both check and report them.
/// max(a, b) written as a comparison: GCC 12 for AArch64 crashes (internal compiler error in
/// vect_transform_reduction) when it vectorizes std::fmax reductions.
inline double larger(double a, double b) {
  return b > a ? b : a;
}

/// Our joint order matched to a reference's by joint name, and the norm-wise relative error
/// (max |ours - reference| / max(1, max |reference|)) of one of our vectors or matrices against
/// the reference's row-major values.
template <Robot R>
struct RefCompare {
  int perm[R::nv];  ///< perm[ours] = reference index (-1: not found)
  int ref_nv;       ///< the reference's DoF (its matrices' row length)
  RefCompare(const std::string_view* joints, int nv) : ref_nv(nv) {
    for (int i = 0; i < R::nv; ++i) {
      perm[i] = -1;
      for (int j = 0; j < nv; ++j)
        if (joints[j] == R::joint_names[i])
          perm[i] = j;
    }
  }
  template <class V>
  double vec(const V& x, const double* r) const {
    double err = 0, mag = 1;
    for (int i = 0; i < R::nv; ++i) {
      err = larger(err, std::fabs(double(x[i]) - r[perm[i]]));
      mag = larger(mag, std::fabs(r[perm[i]]));
    }
    return err / mag;
  }
  template <class M>
  double mat(const M& X, const double* r) const {
    double err = 0, mag = 1;
    for (int i = 0; i < R::nv; ++i)
      for (int j = 0; j < R::nv; ++j) {
        const double rij = r[perm[i] * ref_nv + perm[j]];
        err = larger(err, std::fabs(double(X(i, j)) - rij));
        mag = larger(mag, std::fabs(rij));
      }
    return err / mag;
  }
};

struct RbdErrors {
  double rnea = 0, gravity = 0, nle = 0, crba = 0, aba = 0, minv = 0;
};

template <Robot R, class S>
RbdErrors rbd_errors(const RefView& ref) {
  using D = Data<R, S>;
  static D data;  // static storage, as firmware would keep it
  RbdErrors e;
  const RefCompare<R> cmp(ref.joints, ref.nv);
  auto rel_vec = [&](const typename D::Vector& x, const double* r) { return cmp.vec(x, r); };
  auto rel_mat = [&](const typename D::Matrix& X, const double* r) { return cmp.mat(X, r); };
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
    e.rnea = larger(e.rnea, rel_vec(rnea<R>(data, q, v, a), ref.rnea + o));
    e.gravity = larger(e.gravity, rel_vec(gravity<R>(data, q), ref.gravity + o));
    e.nle = larger(e.nle, rel_vec(nle<R>(data, q, v), ref.nle + o));
    e.crba = larger(e.crba, rel_mat(crba<R>(data, q), ref.crba + om));
    e.aba = larger(e.aba, rel_vec(aba<R>(data, q, v, tau), ref.aba + o));
    e.minv = larger(e.minv, rel_mat(minverse<R>(data, q), ref.minv + om));
  }
  return e;
}

/// Every joint of the robot appears in the reference (same joint set, any order).
template <Robot R>
bool joints_match(const RefView& ref) {
  if (ref.nv != R::nv)
    return false;
  for (int i = 0; i < R::nv; ++i) {
    bool found = false;
    for (int j = 0; j < ref.nv; ++j)
      found = found || ref.joints[j] == R::joint_names[i];
    if (!found)
      return false;
  }
  return true;
}

/// Prints the errors (one line), on the console of whatever runs the test.
inline void log_errors(const char* what, const RbdErrors& e) {
#if defined(ARBOR_BARE_METAL)
  minitest::out() << "    " << what << ": rnea " << e.rnea << " gravity " << e.gravity << " nle "
                  << e.nle << " crba " << e.crba << " aba " << e.aba << " minv " << e.minv << "\n";
#else
  std::printf("    %s: rnea %.3g gravity %.3g nle %.3g crba %.3g aba %.3g minv %.3g\n", what,
              e.rnea, e.gravity, e.nle, e.crba, e.aba, e.minv);
#endif
}

template <Robot R, class S>
void check_rbd_against_reference(const RefView& ref) {
  ASSERT_TRUE(joints_match<R>(ref));
  const RbdErrors e = rbd_errors<R, S>(ref);
  log_errors(sizeof(S) == 8 ? "max relative error vs reference (double)"
                            : "max relative error vs reference (float)",
             e);
  using T = Tolerance<S>;
  EXPECT_LE(e.rnea, T::id) << "rnea";
  EXPECT_LE(e.gravity, T::id) << "gravity";
  EXPECT_LE(e.nle, T::id) << "nle";
  EXPECT_LE(e.crba, T::mass) << "crba";
  EXPECT_LE(e.aba, T::fd) << "aba";
  EXPECT_LE(e.minv, T::fd) << "minverse";
}

}  // namespace arbor::test
