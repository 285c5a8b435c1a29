// Test bodies for the first-order derivatives: central finite differences of the project's own
// rnea / aba / frame kinematics on random robots (with and without external forces), identities
// (d tau / d a = crba, d ddq / d tau = minverse, d ddq / d q = -M^-1 d tau / d q at the FD
// solution), float against double, and the Pinocchio reference values for the generated robots.
// Every call of library code runs inside an allocation guard.
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

namespace arbor::test::derivative_checks {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

template <class R>
struct State {
  Vec<R::nv> q, v, a, tau;
  Eigen::Vector3d g;
  ForceArray<R, double> fext;
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
  }
  s.g = arbor::test::draw3([&] { return u(gen); }) + Eigen::Vector3d(0, 0, -9.81);
  for (auto& f : s.fext) {
    f.f = arbor::test::draw3([&] { return u(gen); }) * 2;
    f.n = arbor::test::draw3([&] { return u(gen); }) * 2;
  }
  return s;
}

// Finite-difference step and tolerance. Central differences have truncation error h^2/6 |f'''|
// and rounding error ~ eps |f| / h. With h = 1e-5 both are ~1e-11 relative for the O(1)-O(100)
// magnitudes of these random robots (|f'''| grows with velocities and link sizes, both O(1)),
// so 1e-6 relative to max(1, |reference|) leaves five orders of margin while still catching any
// wrong term (a missing or mis-signed term is O(1) relative).
inline constexpr double kStep = 1e-5;
inline constexpr double kFdTol = 1e-6;

/// Central differences of a vector function f(x) (n -> m) with respect to x.
/// The library calls inside f run under the allocation guard too.
template <int M, int N, class F>
Eigen::Matrix<double, M, N> central_diff(const Vec<N>& x, F&& f) {
  NoAllocScope guard;
  Eigen::Matrix<double, M, N> D;
  for (int k = 0; k < N; ++k) {
    Vec<N> xp = x, xm = x;
    xp[k] += kStep;
    xm[k] -= kStep;
    D.col(k) = (f(xp) - f(xm)) / (2 * kStep);
  }
  return D;
}

/// rnea_derivatives and aba_derivatives against central differences of rnea and aba, with and
/// without external forces; identities with crba and minverse.
template <class R>
void matches_finite_differences(unsigned seed) {
  constexpr int n = R::nv;
  auto d = std::make_unique<Data<R, double>>();
  auto dd = std::make_unique<DerivativeData<R, double>>();
  auto e = std::make_unique<Data<R, double>>();  // for the finite differences
  auto ed = std::make_unique<DerivativeData<R, double>>();
  std::mt19937 gen(seed);
  for (int trial = 0; trial < 3; ++trial) {
    const State<R> s = random_state<R>(gen);
    for (bool with_fext : {false, true}) {
      SCOPED_TRACE(with_fext ? "with fext" : "without fext");
      // every algorithm with the external forces, or without them
      auto id = [&](Data<R, double>& w, const Vec<n>& q, const Vec<n>& v, const Vec<n>& a) {
        return with_fext ? rnea<R>(w, q, v, a, s.g, s.fext) : rnea<R>(w, q, v, a, s.g);
      };
      auto fd = [&](Data<R, double>& w, const Vec<n>& q, const Vec<n>& v, const Vec<n>& t) {
        return with_fext ? aba<R>(w, q, v, t, s.g, s.fext) : aba<R>(w, q, v, t, s.g);
      };
      auto id_derivatives = [&](Data<R, double>& w, DerivativeData<R, double>& wd,
                                const Vec<n>& a) {
        if (with_fext)
          rnea_derivatives<R>(w, wd, s.q, s.v, a, s.g, s.fext);
        else
          rnea_derivatives<R>(w, wd, s.q, s.v, a, s.g);
      };
      auto fd_derivatives = [&](Data<R, double>& w, DerivativeData<R, double>& wd) {
        if (with_fext)
          aba_derivatives<R>(w, wd, s.q, s.v, s.tau, s.g, s.fext);
        else
          aba_derivatives<R>(w, wd, s.q, s.v, s.tau, s.g);
      };
      // inverse dynamics
      {
        NoAllocScope guard;
        id_derivatives(*d, *dd, s.a);
      }
      Vec<n> tau, ddq;
      Mat<n> M, Minv;
      {
        NoAllocScope guard;
        tau = id(*e, s.q, s.v, s.a);
        M = crba<R>(*e, s.q);
        ddq = fd(*e, s.q, s.v, s.tau);
        Minv = minverse<R>(*e, s.q);
      }
      ARBOR_EXPECT_REL(d->tau, tau, 1e-12);
      auto id_q = [&](const Vec<n>& q) -> Vec<n> { return id(*e, q, s.v, s.a); };
      auto id_v = [&](const Vec<n>& v) -> Vec<n> { return id(*e, s.q, v, s.a); };
      ARBOR_EXPECT_REL(dd->dtau_dq, (central_diff<n, n>(s.q, id_q)), kFdTol);
      ARBOR_EXPECT_REL(dd->dtau_dv, (central_diff<n, n>(s.v, id_v)), kFdTol);
      // d tau / d a = M exactly (tau is linear in a), and equals crba
      ARBOR_EXPECT_REL(d->M, M, 1e-12);
      // forward dynamics
      {
        NoAllocScope guard;
        fd_derivatives(*d, *dd);
      }
      ARBOR_EXPECT_REL(d->ddq, ddq, 1e-12);
      auto fd_q = [&](const Vec<n>& q) -> Vec<n> { return fd(*e, q, s.v, s.tau); };
      auto fd_v = [&](const Vec<n>& v) -> Vec<n> { return fd(*e, s.q, v, s.tau); };
      auto fd_t = [&](const Vec<n>& t) -> Vec<n> { return fd(*e, s.q, s.v, t); };
      ARBOR_EXPECT_REL(dd->ddq_dq, (central_diff<n, n>(s.q, fd_q)), kFdTol);
      ARBOR_EXPECT_REL(dd->ddq_dv, (central_diff<n, n>(s.v, fd_v)), kFdTol);
      ARBOR_EXPECT_REL(d->Minv, (central_diff<n, n>(s.tau, fd_t)), kFdTol);
      // d ddq / d tau = minverse; d ddq / d q = -M^-1 d tau / d q at (q, v, aba(q, v, tau)),
      // with every factor from a separate call
      ARBOR_EXPECT_REL(d->Minv, Minv, 1e-12);
      {
        NoAllocScope guard;
        id_derivatives(*e, *ed, ddq);
      }
      ARBOR_EXPECT_REL(dd->ddq_dq, (-Minv * ed->dtau_dq).eval(), 1e-10);
      ARBOR_EXPECT_REL(dd->ddq_dv, (-Minv * ed->dtau_dv).eval(), 1e-10);
      ARBOR_EXPECT_REL((e->M * Minv).eval(), (Mat<n>::Identity()), 1e-9);
    }
  }
}

/// Frame position and Jacobian-times-vector derivatives against central differences of the
/// frame placement and of the LocalWorldAligned frame Jacobian, for every operational frame.
template <class R>
void frame_derivatives_match_finite_differences(unsigned seed) {
  constexpr int n = R::nv;
  auto d = std::make_unique<Data<R, double>>();
  auto e = std::make_unique<Data<R, double>>();
  std::mt19937 gen(seed);
  const State<R> s = random_state<R>(gen);
  const Vec<n> x = s.v;
  for (int f = 0; f < R::nf; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    Eigen::Matrix<double, 3, n> Dp;
    Eigen::Matrix<double, 6, n> Djx;
    {
      NoAllocScope guard;
      compute_frame_position_derivative<R>(*d, s.q, f, Dp);
      compute_frame_jacobian_times_vector_derivative<R>(*d, s.q, f, x, Djx);
    }
    auto pos = [&](const Vec<n>& q) -> Eigen::Vector3d {
      forward_kinematics<R>(*e, q);
      return frame_placement<R>(*e, f).p;
    };
    auto jx = [&](const Vec<n>& q) -> Vec<6> {
      Eigen::Matrix<double, 6, n> J = Eigen::Matrix<double, 6, n>::Zero();  // -O1 warns otherwise
      compute_frame_jacobian<R>(*e, q, f, ReferenceFrame::local_world_aligned, J);
      return J * x;
    };
    ARBOR_EXPECT_REL(Dp, (central_diff<3, n>(s.q, pos)), kFdTol);
    ARBOR_EXPECT_REL(Djx, (central_diff<6, n>(s.q, jx)), kFdTol);
  }
}

/// The float instantiation against the double one. Tolerances: float has eps = 6e-8; the sweeps
/// sum O(n d) products of O(1-100) magnitudes, so 1e-4 relative for the inverse-dynamics
/// derivatives; the forward-dynamics ones also carry cond(M) (up to ~1e3 for these robots) from
/// M^-1, so 1e-2 relative to max(1, |double value|).
template <class R>
void float_matches_double(unsigned seed, double tol_id = 1e-4, double tol_fd = 1e-2) {
  constexpr int n = R::nv;
  auto d = std::make_unique<Data<R, double>>();
  auto dd = std::make_unique<DerivativeData<R, double>>();
  auto f = std::make_unique<Data<R, float>>();
  auto fd = std::make_unique<DerivativeData<R, float>>();
  std::mt19937 gen(seed);
  const State<R> s = random_state<R>(gen);
  const Eigen::Matrix<float, n, 1> qf = s.q.template cast<float>(), vf = s.v.template cast<float>(),
                                   af = s.a.template cast<float>(),
                                   tf = s.tau.template cast<float>();
  const Eigen::Vector3f gf = s.g.template cast<float>();
  {
    NoAllocScope guard;
    rnea_derivatives<R>(*d, *dd, s.q, s.v, s.a, s.g);
    rnea_derivatives<R>(*f, *fd, qf, vf, af, gf);
  }
  ARBOR_EXPECT_REL(fd->dtau_dq, dd->dtau_dq, tol_id);
  ARBOR_EXPECT_REL(fd->dtau_dv, dd->dtau_dv, tol_id);
  ARBOR_EXPECT_REL(f->M, d->M, tol_id);
  {
    NoAllocScope guard;
    aba_derivatives<R>(*d, *dd, s.q, s.v, s.tau, s.g);
    aba_derivatives<R>(*f, *fd, qf, vf, tf, gf);
  }
  ARBOR_EXPECT_REL(fd->ddq_dq, dd->ddq_dq, tol_fd);
  ARBOR_EXPECT_REL(fd->ddq_dv, dd->ddq_dv, tol_fd);
  ARBOR_EXPECT_REL(f->Minv, d->Minv, tol_fd);
}

/// A generated robot against the reference values: drnea_dq, drnea_dv (and crba) at (q, v, a),
/// daba_dq, daba_dv (and minv) at (q, v, tau). Tolerances relative to max(1, |reference|).
template <class R>
void matches_reference(const std::string& file_name, double tol_id, double tol_fd) {
  constexpr int n = R::nv;
  const ReferenceFile ref = load_reference(file_name);
  ASSERT_EQ(ref.nv, n);
  const std::vector<int> perm = joint_permutation<R>(ref);
  auto d = std::make_unique<Data<R, double>>();
  auto dd = std::make_unique<DerivativeData<R, double>>();
  ASSERT_FALSE(ref.samples.empty());
  int k = 0;
  for (const ReferenceSample& s : ref.samples) {
    SCOPED_TRACE("sample " + std::to_string(k++));
    const Vec<n> q = permute_vector(s.values.at("q"), perm);
    const Vec<n> v = permute_vector(s.values.at("v"), perm);
    const Vec<n> a = permute_vector(s.values.at("a"), perm);
    const Vec<n> tau = permute_vector(s.values.at("tau"), perm);
    {
      NoAllocScope guard;
      rnea_derivatives<R>(*d, *dd, q, v, a);
    }
    ARBOR_EXPECT_REL(dd->dtau_dq, permute_matrix(s.values.at("drnea_dq"), perm), tol_id);
    ARBOR_EXPECT_REL(dd->dtau_dv, permute_matrix(s.values.at("drnea_dv"), perm), tol_id);
    ARBOR_EXPECT_REL(d->M, permute_matrix(s.values.at("crba"), perm), tol_id);
    ARBOR_EXPECT_REL(d->tau, permute_vector(s.values.at("rnea"), perm), tol_id);
    {
      NoAllocScope guard;
      aba_derivatives<R>(*d, *dd, q, v, tau);
    }
    ARBOR_EXPECT_REL(dd->ddq_dq, permute_matrix(s.values.at("daba_dq"), perm), tol_fd);
    ARBOR_EXPECT_REL(dd->ddq_dv, permute_matrix(s.values.at("daba_dv"), perm), tol_fd);
    ARBOR_EXPECT_REL(d->Minv, permute_matrix(s.values.at("minv"), perm), tol_fd);
    ARBOR_EXPECT_REL(d->ddq, permute_vector(s.values.at("aba"), perm), tol_fd);
  }
}

}  // namespace arbor::test::derivative_checks
