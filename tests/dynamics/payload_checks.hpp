// Test support: a run-time payload (dynamics/payload.hpp) on a generated robot against the same
// robot generated with the payload written into its URDF (an extra link on a fixed joint at the
// payload's frame, merged by the generator into that frame's body). Every inertia-dependent
// algorithm, at random states, under the allocation guard; the largest error of each is printed
// (relative to the largest entry of the reference, at least 1).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <arbor/derivatives/aba_second_order.hpp>
#include <arbor/derivatives/derivatives.hpp>
#include <arbor/derivatives/rnea_second_order.hpp>
#include <arbor/derivatives/rnea_second_order_tensors.hpp>
#include <arbor/dynamics/dynamics.hpp>
#include <arbor/dynamics/payload.hpp>
#include <cmath>
#include <cstdio>
#include <random>

#include "alloc_guard.hpp"
#include "payload_values.hpp"

namespace arbor::test::payload_checks {

/// URDF rpy -> rotation Rz(y) Ry(p) Rx(r).
inline Eigen::Matrix3d rpy_matrix(const double rpy[3]) {
  return (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// The payload of payload_values.hpp in its frame: mass, com, inertia about the com.
struct Spec {
  double mass;
  Eigen::Vector3d com;
  Eigen::Matrix3d Ic;
};
inline Spec urdf_payload() {
  namespace pv = payload_values;
  const Eigen::Matrix3d Rr = rpy_matrix(pv::rpy);
  const Eigen::Vector3d d(pv::diag[0], pv::diag[1], pv::diag[2]);
  return {pv::mass, Eigen::Vector3d(pv::com[0], pv::com[1], pv::com[2]),
          Rr * d.asDiagonal() * Rr.transpose()};
}

/// max |x - ref| / max(1, max |ref|).
template <class A, class B>
double rel_err(const Eigen::MatrixBase<A>& x, const Eigen::MatrixBase<B>& ref) {
  const auto xd = x.template cast<double>().eval();
  const auto rd = ref.template cast<double>().eval();
  return (xd - rd).cwiseAbs().maxCoeff() / std::max(1.0, rd.cwiseAbs().maxCoeff());
}

/// Largest error of each algorithm.
struct Errors {
  double rnea = 0, gravity = 0, nle = 0, crba = 0, aba = 0, minverse = 0, rnea_d = 0, aba_d = 0,
         rnea_so = 0, aba_so = 0, tensors = 0;
  double max() const {
    return std::max(
        {rnea, gravity, nle, crba, aba, minverse, rnea_d, aba_d, rnea_so, aba_so, tensors});
  }
  void print(const char* robot, const char* scalar) const {
    std::printf(
        "payload %s %s: rnea %.2e gravity %.2e nle %.2e crba %.2e aba %.2e minverse %.2e "
        "rnea_derivatives %.2e aba_derivatives %.2e rnea_second_order %.2e aba_second_order "
        "%.2e tensors %.2e\n",
        robot, scalar, rnea, gravity, nle, crba, aba, minverse, rnea_d, aba_d, rnea_so, aba_so,
        tensors);
  }
};

template <class R, class S>
struct Work {
  Data<R, S> d;
  DerivativeData<R, S> dd;
  SecondOrderData<R, S> so;
  SecondOrderTensors<R, S> t;
};

/// Plain with a run-time payload on frame `frame` against Merged (the payload in its URDF).
template <class Plain, class Merged, class S>
Errors compare_with_merged(int frame, int states = 6) {
  static_assert(Plain::nv == Merged::nv);
  constexpr int n = Plain::nv;
  using V = VecN<S, n>;
  static Work<Plain, S> p;   // payload set at run time
  static Work<Merged, S> m;  // payload in the model
  static Work<Plain, S> z;   // no payload, never set
  const Spec sp = urdf_payload();
  EXPECT_TRUE(set_payload(p.d, frame, S(sp.mass), sp.com.cast<S>().eval(), sp.Ic.cast<S>().eval()));
  EXPECT_TRUE(p.d.payload.active);
  EXPECT_EQ(p.d.payload.body, Plain::frames[frame].body);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rnd = [&] {
    V x;
    for (int k = 0; k < n; ++k)
      x[k] = S(u(rng));
    return x;
  };
  Errors e;
  for (int s = 0; s < states; ++s) {
    const V q = rnd(), v = rnd(), a = rnd(), tau = V(rnd() * S(10)), lam = rnd();
    {
      NoAllocScope guard;
      rnea<Plain>(p.d, q, v, a);
      rnea<Merged>(m.d, q, v, a);
    }
    e.rnea = std::max(e.rnea, rel_err(p.d.tau, m.d.tau));
    {
      NoAllocScope guard;
      gravity<Plain>(p.d, q);
      gravity<Merged>(m.d, q);
    }
    e.gravity = std::max(e.gravity, rel_err(p.d.tau, m.d.tau));
    {
      NoAllocScope guard;
      nle<Plain>(p.d, q, v);
      nle<Merged>(m.d, q, v);
    }
    e.nle = std::max(e.nle, rel_err(p.d.tau, m.d.tau));
    {
      NoAllocScope guard;
      crba<Plain>(p.d, q);
      crba<Merged>(m.d, q);
    }
    e.crba = std::max(e.crba, rel_err(p.d.M, m.d.M));
    {
      NoAllocScope guard;
      aba<Plain>(p.d, q, v, tau);
      aba<Merged>(m.d, q, v, tau);
    }
    e.aba = std::max(e.aba, rel_err(p.d.ddq, m.d.ddq));
    {
      NoAllocScope guard;
      minverse<Plain>(p.d, q);
      minverse<Merged>(m.d, q);
    }
    e.minverse = std::max(e.minverse, rel_err(p.d.Minv, m.d.Minv));
    {
      NoAllocScope guard;
      rnea_derivatives<Plain>(p.d, p.dd, q, v, a);
      rnea_derivatives<Merged>(m.d, m.dd, q, v, a);
    }
    e.rnea_d = std::max({e.rnea_d, rel_err(p.dd.dtau_dq, m.dd.dtau_dq),
                         rel_err(p.dd.dtau_dv, m.dd.dtau_dv), rel_err(p.d.M, m.d.M),
                         rel_err(p.d.tau, m.d.tau)});
    {
      NoAllocScope guard;
      aba_derivatives<Plain>(p.d, p.dd, q, v, tau);
      aba_derivatives<Merged>(m.d, m.dd, q, v, tau);
    }
    e.aba_d =
        std::max({e.aba_d, rel_err(p.dd.ddq_dq, m.dd.ddq_dq), rel_err(p.dd.ddq_dv, m.dd.ddq_dv),
                  rel_err(p.d.Minv, m.d.Minv), rel_err(p.d.ddq, m.d.ddq)});
    {
      NoAllocScope guard;
      rnea_second_order_derivatives<Plain>(p.d, p.so, q, v, a, lam);
      rnea_second_order_derivatives<Merged>(m.d, m.so, q, v, a, lam);
    }
    e.rnea_so = std::max(
        {e.rnea_so, rel_err(p.so.hessian, m.so.hessian), rel_err(p.so.gradient, m.so.gradient)});
    {
      NoAllocScope guard;
      aba_second_order_derivatives<Plain>(p.d, p.dd, p.so, q, v, tau, lam);
      aba_second_order_derivatives<Merged>(m.d, m.dd, m.so, q, v, tau, lam);
    }
    e.aba_so = std::max(
        {e.aba_so, rel_err(p.so.hessian, m.so.hessian), rel_err(p.so.gradient, m.so.gradient)});
    {
      NoAllocScope guard;
      rnea_second_order_tensors<Plain>(p.d, p.so, p.t, q, v, a);
      rnea_second_order_tensors<Merged>(m.d, m.so, m.t, q, v, a);
    }
    for (int i = 0; i < n; ++i)
      e.tensors = std::max({e.tensors, rel_err(p.t.d2tau_dqdq[i], m.t.d2tau_dqdq[i]),
                            rel_err(p.t.d2tau_dvdv[i], m.t.d2tau_dvdv[i]),
                            rel_err(p.t.d2tau_dqdv[i], m.t.d2tau_dqdv[i]),
                            rel_err(p.t.d2tau_dadq[i], m.t.d2tau_dadq[i])});
    // the payload changes the answer (the comparison is not vacuous), and clearing it gives
    // back the plain robot's results bit for bit
    rnea<Plain>(z.d, q, v, a);
    rnea<Plain>(p.d, q, v, a);
    EXPECT_GT(rel_err(p.d.tau, z.d.tau), 1e-3);
  }
  // clear_payload: the same results as a Data that never had one, bit for bit
  const V q = rnd(), v = rnd(), a = rnd();
  clear_payload(p.d);
  EXPECT_FALSE(p.d.payload.active);
  rnea<Plain>(p.d, q, v, a);
  rnea<Plain>(z.d, q, v, a);
  EXPECT_EQ(p.d.tau, z.d.tau);
  aba<Plain>(p.d, q, v, a);
  aba<Plain>(z.d, q, v, a);
  EXPECT_EQ(p.d.ddq, z.d.ddq);
  minverse<Plain>(p.d, q);
  minverse<Plain>(z.d, q);
  EXPECT_EQ(p.d.Minv, z.d.Minv);
  aba_derivatives<Plain>(p.d, p.dd, q, v, a);
  aba_derivatives<Plain>(z.d, z.dd, q, v, a);
  EXPECT_EQ(p.dd.ddq_dq, z.dd.ddq_dq);
  // bad arguments: refused, payload cleared
  EXPECT_FALSE(set_payload(p.d, Plain::nf, S(1), Vec3<S>::Zero(), Mat3<S>::Zero()));
  EXPECT_FALSE(set_payload(p.d, frame, S(-1), Vec3<S>::Zero(), Mat3<S>::Zero()));
  EXPECT_FALSE(p.d.payload.active);
  return e;
}

}  // namespace arbor::test::payload_checks
