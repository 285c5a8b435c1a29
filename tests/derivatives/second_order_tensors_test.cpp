// The four second-order tensors of inverse dynamics (rnea_second_order_tensors): on two random
// compile-time robots (RandomRobot<52, 6>: a revolute branch point below the root, revolute and
// prismatic joints on both branches; RandomRobot<6, 7>: two chains from the root, unaligned
// revolute and prismatic joints; RandomRobot<19, 6>: a numbering that is not depth-first, the
// routine's per-pair path) and the Kinova Gen3 (when the generated robots are
// built), in double, and the first random robot in float (the Kinova's float instantiation would
// add ~20 s of compiler time to this unit):
//   - each tensor against central differences of rnea_derivatives (dtau/dq, dtau/dv) and of crba
//     (M = dtau/da) in q and v: an independent code path;
//   - the contraction identity sum_i lambda_i T_i = the blocks of the contracted Hessian of
//     rnea_second_order_derivatives for a random lambda;
//   - exact symmetry of the q-q and v-v slices, d2tau/dv2 independent of a, d2tau/da dq
//     independent of v and a, and the float instantiation against the double one.
// Every call of library code runs inside the allocation guard. One translation unit: each
// library call sits in its own non-inlined function (second_order_checks.hpp says why).
#include <arbor/derivatives/rnea_second_order_tensors.hpp>

#include "../dynamics/random_robot.hpp"
#include "second_order_checks.hpp"

#include <cstdio>

#ifdef ARBOR_TENSORS_TEST_KINOVA
#include <robots/kinova_gen3.hpp>
#endif

namespace {
using namespace arbor::test::second_order_checks;
using arbor::test::NoAllocScope;

template <class R, class S>
using Tensors = arbor::SecondOrderTensors<R, S>;

/// The tensors at (q, v, a) with gravity g, under the allocation guard.
template <class R, class S, class V>
[[gnu::noinline]] void tensors(arbor::Data<R, S>& d, arbor::SecondOrderData<R, S>& so,
                               Tensors<R, S>& t, const V& q, const V& v, const V& a,
                               const arbor::Vec3<S>& g) {
  NoAllocScope guard;
  arbor::rnea_second_order_tensors<R>(d, so, t, q, v, a, g);
}

/// [dtau/dq, dtau/dv] (n x 2n) at u = (q, v) and a, from rnea_derivatives.
template <class R>
[[gnu::noinline]] Eigen::Matrix<double, R::nv, 2 * R::nv> id_jacobian(
    arbor::Data<R, double>& d, arbor::DerivativeData<R, double>& dd, const Vec<2 * R::nv>& u,
    const Vec<R::nv>& a, const Eigen::Vector3d& g) {
  constexpr int n = R::nv;
  NoAllocScope guard;
  arbor::rnea_derivatives<R>(d, dd, u.template head<n>(), u.template tail<n>(), a, g);
  Eigen::Matrix<double, n, 2 * n> J;
  J << dd.dtau_dq, dd.dtau_dv;
  return J;
}

/// M(q) from crba.
template <class R>
[[gnu::noinline]] Mat<R::nv> mass_matrix(arbor::Data<R, double>& d, const Vec<R::nv>& q) {
  NoAllocScope guard;
  return arbor::crba<R>(d, q);
}

/// Largest |a - b| over the slices, relative to max(1, largest |b|).
template <int n>
double tensor_rel_err(const std::array<Mat<n>, n>& a, const std::array<Mat<n>, n>& b) {
  double err = 0, scale = 1;
  for (int i = 0; i < n; ++i) {
    err = std::max(err, (a[i] - b[i]).cwiseAbs().maxCoeff());
    scale = std::max(scale, b[i].cwiseAbs().maxCoeff());
  }
  return err / scale;
}

/// Every tensor against central differences of the first-order derivatives, the contraction
/// identity, symmetry and the independences.
template <class R>
void check_tensors(unsigned seed, int trials = 2) {
  constexpr int n = R::nv;
  using T = std::array<Mat<n>, n>;
  auto d = std::make_unique<arbor::Data<R, double>>();
  auto so = std::make_unique<arbor::SecondOrderData<R, double>>();
  auto t = std::make_unique<Tensors<R, double>>();
  auto t2 = std::make_unique<Tensors<R, double>>();
  auto e = std::make_unique<arbor::Data<R, double>>();
  auto ed = std::make_unique<arbor::DerivativeData<R, double>>();
  auto fd = std::make_unique<std::array<T, 4>>();  // qq, vv, qv, aq by finite differences
  std::mt19937 gen(seed);
  for (int trial = 0; trial < trials; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const State<R> s = random_state<R>(gen);
    tensors<R>(*d, *so, *t, s.q, s.v, s.a, s.g);
    EXPECT_LE(arbor::test::rel_err(d->tau, id_value<R>(*e, s)), 1e-12);

    // central differences: column k of d/du_k [dtau/dq, dtau/dv], d/dq_k M
    Vec<2 * n> u;
    u << s.q, s.v;
    for (int k = 0; k < 2 * n; ++k) {
      Vec<2 *n> up = u, um = u;
      up[k] += kStep;
      um[k] -= kStep;
      const Eigen::Matrix<double, n, 2 * n> D =
          (id_jacobian<R>(*e, *ed, up, s.a, s.g) - id_jacobian<R>(*e, *ed, um, s.a, s.g)) /
          (2 * kStep);
      Mat<n> dM;
      if (k < n)
        dM = (mass_matrix<R>(*e, up.template head<n>()) -
              mass_matrix<R>(*e, um.template head<n>())) /
             (2 * kStep);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          if (k < n) {
            (*fd)[0][i](j, k) = D(i, j);   // d/dq_k dtau_i/dq_j
            (*fd)[3][i](j, k) = dM(i, j);  // d/dq_k M(i, j) = d2tau_i / da_j dq_k
          } else {
            (*fd)[2][i](j, k - n) = D(i, j);      // d/dv_k dtau_i/dq_j
            (*fd)[1][i](j, k - n) = D(i, n + j);  // d/dv_k dtau_i/dv_j
          }
        }
    }
    const double e_qq = tensor_rel_err<n>(t->d2tau_dqdq, (*fd)[0]);
    const double e_vv = tensor_rel_err<n>(t->d2tau_dvdv, (*fd)[1]);
    const double e_qv = tensor_rel_err<n>(t->d2tau_dqdv, (*fd)[2]);
    const double e_aq = tensor_rel_err<n>(t->d2tau_dadq, (*fd)[3]);
    EXPECT_LE(e_qq, kFdTol) << "d2tau_dqdq";
    EXPECT_LE(e_vv, kFdTol) << "d2tau_dvdv";
    EXPECT_LE(e_qv, kFdTol) << "d2tau_dqdv";
    EXPECT_LE(e_aq, kFdTol) << "d2tau_dadq";

    // the contraction identity against rnea_second_order_derivatives
    id_hessian<R>(*d, *so, s.q, s.v, s.a, s.lambda, s.g);
    const Mat<3 * n> H = so->hessian;
    Mat<n> qq = Mat<n>::Zero(), vv = Mat<n>::Zero(), qv = Mat<n>::Zero(), aq = Mat<n>::Zero();
    for (int i = 0; i < n; ++i) {
      qq += s.lambda[i] * t->d2tau_dqdq[i];
      vv += s.lambda[i] * t->d2tau_dvdv[i];
      qv += s.lambda[i] * t->d2tau_dqdv[i];
      aq += s.lambda[i] * t->d2tau_dadq[i];
    }
    constexpr double tol_c = 1e-10;
    const Mat<n> Hqq = H.topLeftCorner(n, n), Hvv = H.block(n, n, n, n), Hqv = H.block(0, n, n, n),
                 Hvq = H.block(n, 0, n, n), Haq = H.block(2 * n, 0, n, n),
                 Hqa = H.block(0, 2 * n, n, n);
    ARBOR_EXPECT_REL(qq, Hqq, tol_c);
    ARBOR_EXPECT_REL(vv, Hvv, tol_c);
    ARBOR_EXPECT_REL(qv, Hqv, tol_c);
    ARBOR_EXPECT_REL(qv.transpose().eval(), Hvq, tol_c);
    ARBOR_EXPECT_REL(aq, Haq, tol_c);
    ARBOR_EXPECT_REL(aq.transpose().eval(), Hqa, tol_c);
    std::printf(
        "  n = %d: relative error vs finite differences qq %.1e vv %.1e qv %.1e aq %.1e; "
        "contraction qq %.1e vv %.1e qv %.1e aq %.1e\n",
        n, e_qq, e_vv, e_qv, e_aq, arbor::test::rel_err(qq, Hqq), arbor::test::rel_err(vv, Hvv),
        arbor::test::rel_err(qv, Hqv), arbor::test::rel_err(aq, Haq));

    // symmetry (exact: each pair is computed once and stored twice)
    for (int i = 0; i < n; ++i) {
      EXPECT_TRUE(t->d2tau_dqdq[i] == t->d2tau_dqdq[i].transpose()) << "slice " << i;
      EXPECT_TRUE(t->d2tau_dvdv[i] == t->d2tau_dvdv[i].transpose()) << "slice " << i;
    }
    // d2tau/dv2 does not depend on a, d2tau/da dq on neither v nor a
    const Vec<n> v2 = -s.v * 0.5, a2 = s.a * 2 + Vec<n>::Ones();
    tensors<R>(*d, *so, *t2, s.q, s.v, a2, s.g);
    EXPECT_LE(tensor_rel_err<n>(t2->d2tau_dvdv, t->d2tau_dvdv), 1e-13);
    tensors<R>(*d, *so, *t2, s.q, v2, a2, s.g);
    EXPECT_LE(tensor_rel_err<n>(t2->d2tau_dadq, t->d2tau_dadq), 1e-13);
  }
}

/// The float instantiation against the double one (ID: 1e-4 relative, as for the contracted
/// Hessian).
template <class R>
void tensors_float_matches_double(unsigned seed, double tol = 1e-4) {
  constexpr int n = R::nv;
  auto d = std::make_unique<arbor::Data<R, double>>();
  auto so = std::make_unique<arbor::SecondOrderData<R, double>>();
  auto t = std::make_unique<Tensors<R, double>>();
  auto f = std::make_unique<arbor::Data<R, float>>();
  auto sf = std::make_unique<arbor::SecondOrderData<R, float>>();
  auto tf = std::make_unique<Tensors<R, float>>();
  std::mt19937 gen(seed);
  const State<R> s = random_state<R>(gen);
  using Vf = Eigen::Matrix<float, n, 1>;
  const Vf qf = s.q.template cast<float>(), vf = s.v.template cast<float>(),
           af = s.a.template cast<float>();
  tensors<R>(*d, *so, *t, s.q, s.v, s.a, s.g);
  tensors<R>(*f, *sf, *tf, qf, vf, af, arbor::Vec3<float>(s.g.template cast<float>()));
  const auto cast = [](const std::array<Eigen::Matrix<float, n, n>, n>& x) {
    std::array<Mat<n>, n> y;
    for (int i = 0; i < n; ++i)
      y[i] = x[i].template cast<double>();
    return y;
  };
  const double e[4] = {tensor_rel_err<n>(cast(tf->d2tau_dqdq), t->d2tau_dqdq),
                       tensor_rel_err<n>(cast(tf->d2tau_dvdv), t->d2tau_dvdv),
                       tensor_rel_err<n>(cast(tf->d2tau_dqdv), t->d2tau_dqdv),
                       tensor_rel_err<n>(cast(tf->d2tau_dadq), t->d2tau_dadq)};
  for (int k = 0; k < 4; ++k)
    EXPECT_LE(e[k], tol) << "tensor " << k << " (qq, vv, qv, aq)";
  std::printf("  n = %d: float vs double qq %.1e vv %.1e qv %.1e aq %.1e\n", n, e[0], e[1], e[2],
              e[3]);
}

// 0 -> 1 -> {2 -> 3, 4 -> 5}: revolute y, unaligned revolute (the branch point), prismatic x,
// revolute z | unaligned revolute, prismatic z; every body has mass. Outputs on one branch make
// the branch point's sweep cross the other branch, whose entries must come out zero.
using R_52_6 = arbor::test::RandomRobot<52, 6>;
using R_6_7 = arbor::test::RandomRobot<6, 7>;

TEST(SecondOrderTensors_52_6, MatchFiniteDifferencesAndContraction) {
  check_tensors<R_52_6>(5261u);
}
TEST(SecondOrderTensors_52_6, FloatMatchesDouble) {
  tensors_float_matches_double<R_52_6>(5262u);
}
TEST(SecondOrderTensors_6_7, MatchFiniteDifferencesAndContraction) {
  check_tensors<R_6_7>(6711u);
}

// Parents -1 0 1 0 1 4: the subtrees of joints 0 and 1 are not contiguous ranges, so this robot
// takes the per-pair path for numberings that are not depth-first (no generated robot has one).
using R_19_6 = arbor::test::RandomRobot<19, 6>;
static_assert(!arbor::detail::tens_depth_first<R_19_6>());
TEST(SecondOrderTensors_19_6, NotDepthFirstMatchFiniteDifferencesAndContraction) {
  check_tensors<R_19_6>(1961u);
}

#ifdef ARBOR_TENSORS_TEST_KINOVA
using Kinova = arbor::robots::KinovaGen3;
TEST(SecondOrderTensors_KinovaGen3, MatchFiniteDifferencesAndContraction) {
  check_tensors<Kinova>(7011u);
}
#endif

}  // namespace
