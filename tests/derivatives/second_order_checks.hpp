// Test bodies for the contracted second-order derivatives (rnea_second_order_derivatives,
// aba_second_order_derivatives): central finite differences of the analytical first-order
// derivatives contracted with lambda (an independent code path: the Hessian is the Jacobian of
// lambda' [dtau/dq, dtau/dv, M], resp. lambda' [dddq/dq, dddq/dv, M^-1]), the gradient against
// that contraction, symmetry of the finite-difference matrix, float against double, the
// nested-dual Hessian of the AD layer, and Pinocchio's contracted tensors for the generated
// robots. Every call of library code runs inside an allocation guard.
#pragma once

#include <gtest/gtest.h>

#include <arbor/derivatives/derivatives.hpp>
#include <arbor/dynamics/dynamics.hpp>
#include <memory>
#include <random>
#include <string>

#include "../dynamics/check_helpers.hpp"
#include "alloc_guard.hpp"
#include "random_draw.hpp"
#include "reference.hpp"

namespace arbor::test::second_order_checks {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

template <class R>
struct State {
  Vec<R::nv> q, v, a, tau, lambda;
  Eigen::Vector3d g;
};

template <class R>
State<R> random_state(std::mt19937& gen) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  State<R> s;
  for (int i = 0; i < R::nv; ++i) {
    s.q[i] = u(gen);
    s.v[i] = u(gen);
    s.a[i] = u(gen);
    s.tau[i] = 5 * u(gen);
    s.lambda[i] = u(gen);
  }
  s.g = arbor::test::draw3([&] { return u(gen); }) + Eigen::Vector3d(0, 0, -9.81);
  return s;
}

// Central differences of the analytical first-order derivatives: truncation h^2/6 |f'''| and
// rounding eps |f| / h are both ~1e-11 relative at h = 1e-5 for these O(1)-O(100) magnitudes, so
// 1e-6 relative to max(1, |value|) leaves orders of margin and still catches a wrong term
// (O(1) relative).
inline constexpr double kStep = 1e-5;
inline constexpr double kFdTol = 1e-6;

// Each library call sits in its own non-inlined function: the sweeps are unrolled and inlined
// into their callers, and one test function holding several of them would cost the compiler
// gigabytes of memory.

/// lambda' [dtau/dq, dtau/dv, M] at z = (q, v, a), from rnea_derivatives.
template <class R>
[[gnu::noinline]] Vec<3 * R::nv> id_gradient(Data<R, double>& d, DerivativeData<R, double>& dd,
                                             const Vec<3 * R::nv>& z, const Vec<R::nv>& lambda,
                                             const Eigen::Vector3d& g) {
  constexpr int n = R::nv;
  rnea_derivatives<R>(d, dd, z.template segment<n>(0), z.template segment<n>(n),
                      z.template segment<n>(2 * n), g);
  Vec<3 * n> r;
  r << dd.dtau_dq.transpose() * lambda, dd.dtau_dv.transpose() * lambda, d.M * lambda;
  return r;
}

/// lambda' [dddq/dq, dddq/dv, M^-1] at x = (q, v, tau), from aba_derivatives.
template <class R>
[[gnu::noinline]] Vec<3 * R::nv> fd_gradient(Data<R, double>& d, DerivativeData<R, double>& dd,
                                             const Vec<3 * R::nv>& x, const Vec<R::nv>& lambda,
                                             const Eigen::Vector3d& g) {
  constexpr int n = R::nv;
  aba_derivatives<R>(d, dd, x.template segment<n>(0), x.template segment<n>(n),
                     x.template segment<n>(2 * n), g);
  Vec<3 * n> r;
  r << dd.ddq_dq.transpose() * lambda, dd.ddq_dv.transpose() * lambda, d.Minv * lambda;
  return r;
}

/// The ID Hessian at (q, v, a) with multipliers lambda and gravity g, under the allocation guard.
template <class R, class S, class V>
[[gnu::noinline]] void id_hessian(Data<R, S>& d, SecondOrderData<R, S>& so, const V& q, const V& v,
                                  const V& a, const V& lambda, const Vec3<S>& g) {
  NoAllocScope guard;
  rnea_second_order_derivatives<R>(d, so, q, v, a, lambda, g);
}

/// The FD Hessian at (q, v, tau) with multipliers lambda and gravity g, under the allocation guard.
template <class R, class S, class V>
[[gnu::noinline]] void fd_hessian(Data<R, S>& d, DerivativeData<R, S>& dd,
                                  SecondOrderData<R, S>& so, const V& q, const V& v, const V& tau,
                                  const V& lambda, const Vec3<S>& g) {
  NoAllocScope guard;
  aba_second_order_derivatives<R>(d, dd, so, q, v, tau, lambda, g);
}

/// rnea and aba at double, under the allocation guard.
template <class R>
[[gnu::noinline]] Vec<R::nv> id_value(Data<R, double>& d, const State<R>& s) {
  NoAllocScope guard;
  return rnea<R>(d, s.q, s.v, s.a, s.g);
}
template <class R>
[[gnu::noinline]] Vec<R::nv> fd_value(Data<R, double>& d, const State<R>& s) {
  NoAllocScope guard;
  return aba<R>(d, s.q, s.v, s.tau, s.g);
}

/// Central differences of a gradient function: column k is d grad / d x_k.
template <int N, class F>
Mat<N> central_diff(const Vec<N>& x, F&& f) {
  NoAllocScope guard;
  Mat<N> D;
  for (int k = 0; k < N; ++k) {
    Vec<N> xp = x, xm = x;
    xp[k] += kStep;
    xm[k] -= kStep;
    D.col(k) = (f(xp) - f(xm)) / (2 * kStep);
  }
  return D;
}

/// Both Hessians against central differences of the first-order derivatives, their gradients
/// against the first-order derivatives, the values against rnea and aba, and the structural
/// zeros (a-a and a-v blocks of ID, tau-tau and tau-v blocks of FD).
template <class R>
void matches_finite_differences(unsigned seed, int trials = 2) {
  constexpr int n = R::nv;
  auto d = std::make_unique<Data<R, double>>();
  auto so = std::make_unique<SecondOrderData<R, double>>();
  auto dd = std::make_unique<DerivativeData<R, double>>();
  auto e = std::make_unique<Data<R, double>>();
  auto ed = std::make_unique<DerivativeData<R, double>>();
  std::mt19937 gen(seed);
  for (int trial = 0; trial < trials; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const State<R> s = random_state<R>(gen);
    // inverse dynamics
    Vec<3 * n> z;
    z << s.q, s.v, s.a;
    id_hessian<R>(*d, *so, s.q, s.v, s.a, s.lambda, s.g);
    const Vec<n> tau = id_value<R>(*e, s);
    Vec<3 * n> grad;
    {
      NoAllocScope guard;
      grad = id_gradient<R>(*e, *ed, z, s.lambda, s.g);
    }
    ARBOR_EXPECT_REL(d->tau, tau, 1e-12);
    ARBOR_EXPECT_REL(so->gradient, grad, 1e-11);
    const Mat<3 * n> Hid = so->hessian;
    const Mat<3 * n> Did = central_diff<3 * n>(
        z, [&](const Vec<3 * n>& x) { return id_gradient<R>(*e, *ed, x, s.lambda, s.g); });
    ARBOR_EXPECT_REL(Hid, Did, kFdTol);
    // the finite-difference matrix is symmetric to its accuracy (an independent check that the
    // first-order routine is a gradient), and the analytical one exactly
    ARBOR_EXPECT_REL(Did, Did.transpose().eval(), kFdTol);
    EXPECT_TRUE(Hid == Hid.transpose());
    EXPECT_TRUE((Hid.template bottomRightCorner<n, 2 * n>().array() == 0).all());
    // forward dynamics
    Vec<3 * n> x;
    x << s.q, s.v, s.tau;
    fd_hessian<R>(*d, *dd, *so, s.q, s.v, s.tau, s.lambda, s.g);
    const Vec<n> ddq = fd_value<R>(*e, s);
    {
      NoAllocScope guard;
      grad = fd_gradient<R>(*e, *ed, x, s.lambda, s.g);
    }
    ARBOR_EXPECT_REL(d->ddq, ddq, 1e-12);
    ARBOR_EXPECT_REL(so->gradient, grad, 1e-10);
    const Mat<3 * n> Dfd = central_diff<3 * n>(
        x, [&](const Vec<3 * n>& y) { return fd_gradient<R>(*e, *ed, y, s.lambda, s.g); });
    ARBOR_EXPECT_REL(so->hessian, Dfd, kFdTol);
    EXPECT_TRUE(so->hessian == so->hessian.transpose());
    EXPECT_TRUE((so->hessian.template bottomRightCorner<n, 2 * n>().array() == 0).all());
  }
}

/// The float instantiation against the double one. Float has eps = 6e-8; the Hessian sums
/// O(n d) products of O(1-100) magnitudes: 1e-4 relative for ID; FD also carries cond(M) (up to
/// ~1e3) twice (M^-1 and d ddq / d q): 3e-2 relative to max(1, |double value|).
template <class R>
void float_matches_double(unsigned seed, double tol_id = 1e-4, double tol_fd = 3e-2) {
  auto d = std::make_unique<Data<R, double>>();
  auto so = std::make_unique<SecondOrderData<R, double>>();
  auto dd = std::make_unique<DerivativeData<R, double>>();
  auto f = std::make_unique<Data<R, float>>();
  auto sf = std::make_unique<SecondOrderData<R, float>>();
  auto fdd = std::make_unique<DerivativeData<R, float>>();
  std::mt19937 gen(seed);
  const State<R> s = random_state<R>(gen);
  using Vf = Eigen::Matrix<float, R::nv, 1>;
  const Eigen::Vector3f gf = s.g.template cast<float>();
  const Vf qf = s.q.template cast<float>(), vf = s.v.template cast<float>(),
           af = s.a.template cast<float>(), tf = s.tau.template cast<float>(),
           lf = s.lambda.template cast<float>();
  id_hessian<R>(*d, *so, s.q, s.v, s.a, s.lambda, s.g);
  id_hessian<R>(*f, *sf, qf, vf, af, lf, gf);
  ARBOR_EXPECT_REL(sf->hessian.template cast<double>().eval(), so->hessian, tol_id);
  fd_hessian<R>(*d, *dd, *so, s.q, s.v, s.tau, s.lambda, s.g);
  fd_hessian<R>(*f, *fdd, *sf, qf, vf, tf, lf, gf);
  ARBOR_EXPECT_REL(sf->hessian.template cast<double>().eval(), so->hessian, tol_fd);
}

/// A generated robot against Pinocchio's contracted second-order tensors (hess_id, z = (q, v, a),
/// joint order permuted by name). Tolerance relative to max(1, |reference|).
template <class R>
void matches_reference(const std::string& file_name, double tol) {
  constexpr int n = R::nv;
  const ReferenceFile ref = load_reference(file_name + "_second_order");
  ASSERT_EQ(ref.nv, n);
  const std::vector<int> perm = joint_permutation<R>(ref);
  auto d = std::make_unique<Data<R, double>>();
  auto so = std::make_unique<SecondOrderData<R, double>>();
  ASSERT_FALSE(ref.samples.empty());
  int k = 0;
  for (const ReferenceSample& s : ref.samples) {
    SCOPED_TRACE("sample " + std::to_string(k++));
    const Vec<n> q = permute_vector(s.values.at("q"), perm);
    const Vec<n> v = permute_vector(s.values.at("v"), perm);
    const Vec<n> a = permute_vector(s.values.at("a"), perm);
    const Vec<n> lambda = permute_vector(s.values.at("lambda"), perm);
    const Eigen::MatrixXd& Hr = s.values.at("hess_id");
    ASSERT_EQ(Hr.rows(), 3 * n);
    // rows and columns of z = (q, v, a) in the robot's joint order
    Mat<3 * n> H;
    for (int r = 0; r < 3 * n; ++r)
      for (int c = 0; c < 3 * n; ++c)
        H(r, c) = Hr((r / n) * n + perm[r % n], (c / n) * n + perm[c % n]);
    id_hessian<R>(*d, *so, q, v, a, lambda, Eigen::Vector3d(0, 0, -9.81));
    ARBOR_EXPECT_REL(so->hessian, H, tol);
  }
}

}  // namespace arbor::test::second_order_checks
