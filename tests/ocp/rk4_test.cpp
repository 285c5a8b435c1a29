// ocp::rk4: the node's value and its exact and frozen sensitivities (ocp/rk4.hpp).
// - A linear ODE x' = A x + B u: RK4's map is linear with the closed form Phi = sum_k (hA)^k / k!
//   (k <= 4), Gamma = h sum_k (hA)^k / (k+1)! B; exact and frozen both equal it (the Jacobian of
//   a linear f is the same at every stage).
// - x' = [v, aba(q, v, u + p)] on random robots of 1, 3 and 7 joints (p a parameter, not
//   differentiated): the value equals a plain RK4 of aba written here; the exact Jacobian equals
//   central differences of that plain RK4; the frozen Jacobian equals the closed form above for
//   A0, B0 = aba's Jacobian at the start by central differences (RK4 of the linearisation), and
//   its distance to the exact one shrinks as h^2 (halving h divides it by ~4).
// - M = 2 steps, and a value-only evaluation (the frozen node's value path is the exact one).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "arbor/ad/expr.hpp"
#include "arbor/ad/rbd_functions.hpp"
#include "arbor/dynamics/aba.hpp"
#include "arbor/ocp/rk4.hpp"
#include "arbor_test.hpp"
#include "random_robot.hpp"

namespace {

namespace ad = arbor::ad;
namespace ocp = arbor::ocp;
using ocp::Sensitivity;

template <int R, int C>
using Mat = Eigen::Matrix<double, R, C>;
template <int R>
using Vec = Eigen::Matrix<double, R, 1>;

/// RK4's Jacobians for x' = A x + B u over h in M steps: (Phi, Gamma), by the closed form.
template <int n, int m>
std::pair<Mat<n, n>, Mat<n, m>> linear_rk4(const Mat<n, n>& A, const Mat<n, m>& B, double h,
                                           int M) {
  const double hs = h / M;
  const Mat<n, n> I = Mat<n, n>::Identity(), hA = hs * A;
  const Mat<n, n> P = I + hA + hA * hA / 2 + hA * hA * hA / 6 + hA * hA * hA * hA / 24;
  const Mat<n, m> G = hs * (I + hA / 2 + hA * hA / 6 + hA * hA * hA / 24) * B;
  Mat<n, n> Pm = I;
  Mat<n, m> Gm = Mat<n, m>::Zero();
  for (int s = 0; s < M; ++s) {  // x_{s+1} = P x_s + G u
    Gm = P * Gm + G;
    Pm = P * Pm;
  }
  return {Pm, Gm};
}

/// The linear ODE's matrices (compile-time, for ad::mul).
struct KA {
  static constexpr int rows = 3, cols = 3;
  static constexpr double e[9] = {-0.4, 1.1, 0.2, -0.7, -0.3, 0.9, 0.5, -1.2, -0.8};
  static constexpr double at(int r, int c) { return e[r * cols + c]; }
};
struct KB {
  static constexpr int rows = 3, cols = 2;
  static constexpr double e[6] = {0.3, -1.0, 0.8, 0.4, -0.6, 1.3};
  static constexpr double at(int r, int c) { return e[r * cols + c]; }
};
template <class K>
Mat<K::rows, K::cols> to_matrix() {
  Mat<K::rows, K::cols> r;
  for (int i = 0; i < K::rows; ++i)
    for (int j = 0; j < K::cols; ++j)
      r(i, j) = K::at(i, j);
  return r;
}

TEST(OcpRk4, ExactAndFrozenEqualTheClosedFormOnALinearOde) {
  constexpr int n = 3, m = 2;
  const Mat<n, n> A = to_matrix<KA>();
  const Mat<n, m> B = to_matrix<KB>();
  constexpr ad::Symbol<0, n> x;
  constexpr ad::Symbol<1, m> u;
  const auto f = ad::mul<KA>(x) + ad::mul<KB>(u);
  const Vec<n> x0(0.3, -0.2, 0.7);
  const Vec<m> u0(-0.5, 0.9);
  for (const double h : {0.02, 0.3}) {
    const auto [P, G] = linear_rk4<n, m>(A, B, h, 1);
    const auto e = ad::value_and_jacobian(ocp::rk4<1>(f, h), x0, u0);
    const auto z = ad::value_and_jacobian(ocp::rk4<1, Sensitivity::frozen>(f, h), x0, u0);
    const Vec<n> y = P * x0 + G * u0;
    EXPECT_LE((e.value - y).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LE((z.value - y).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LE((e.jacobian.template leftCols<n>() - P).cwiseAbs().maxCoeff(), 1e-14) << h;
    EXPECT_LE((z.jacobian.template leftCols<n>() - P).cwiseAbs().maxCoeff(), 1e-14) << h;
    EXPECT_LE((e.jacobian.template rightCols<m>() - G).cwiseAbs().maxCoeff(), 1e-14) << h;
    EXPECT_LE((z.jacobian.template rightCols<m>() - G).cwiseAbs().maxCoeff(), 1e-14) << h;
  }
}

/// The robot ODE's pieces for robot R: a plain RK4 of aba, aba's Jacobian by central differences.
template <class R>
struct RobotOde {
  static constexpr int nv = R::nv, nx = 2 * nv;
  using Vx = Vec<nx>;
  using Vv = Vec<nv>;
  static Vx f(const Vx& x, const Vv& tau) {
    static arbor::Data<R, double> d;  // test-only scratch
    Vx r;
    r.template head<nv>() = x.template tail<nv>();
    r.template tail<nv>() = arbor::aba<R>(d, x.template head<nv>(), x.template tail<nv>(), tau);
    return r;
  }
  static Vx rk4(Vx x, const Vv& tau, double h, int M) {
    const double hs = h / M;
    for (int s = 0; s < M; ++s) {
      const Vx k1 = f(x, tau), k2 = f(x + hs / 2 * k1, tau), k3 = f(x + hs / 2 * k2, tau),
               k4 = f(x + hs * k3, tau);
      x += hs / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return x;
  }
  /// Central differences of g(x, u) (nx rows) with respect to (x, u).
  template <class G>
  static Mat<nx, nx + nv> central(const G& g, const Vx& x, const Vv& u, double eps) {
    Mat<nx, nx + nv> J;
    for (int k = 0; k < nx + nv; ++k) {
      Vx xp = x, xm = x;
      Vv up = u, um = u;
      if (k < nx) {
        xp[k] += eps;
        xm[k] -= eps;
      } else {
        up[k - nx] += eps;
        um[k - nx] -= eps;
      }
      J.col(k) = (g(xp, up) - g(xm, um)) / (2 * eps);
    }
    return J;
  }
};

template <class R, int M>
void robot_case() {
  using O = RobotOde<R>;
  constexpr int nv = R::nv, nx = 2 * nv;
  SCOPED_TRACE(::testing::Message() << "nv=" << nv << " M=" << M);
  using Fd = ad::ForwardDynamics<R>;
  static ad::MergedWorkspace<ad::ValueWorkspace<Fd, double>,
                             ad::JacobianWorkspace<Fd, ad::Analytical, double>>
      ws;
  constexpr ad::Symbol<0, nx> x;
  constexpr ad::Symbol<1, nv> u;
  constexpr ad::Symbol<2, nv> p;  // a parameter: an offset of the torque, not differentiated
  const auto q = ad::segment<0, nv>(x);
  const auto v = ad::segment<nv, nv>(x);
  const auto ode = ad::cat(v, ad::call<ad::Analytical>(ad::bind<Fd>(ws), q, v, u + p));
  typename O::Vx x0;
  typename O::Vv u0, p0;
  for (int i = 0; i < nv; ++i) {
    x0[i] = 0.4 * std::sin(1.3 * i + 0.2);
    x0[nv + i] = 0.8 * std::cos(0.7 * i + 0.5);
    u0[i] = 0.9 * std::sin(2.1 * i + 1.0);
    p0[i] = 0.1 * std::cos(1.9 * i);
  }
  double gap_prev = 0;
  for (const double h : {0.04, 0.02, 0.01}) {
    SCOPED_TRACE(::testing::Message() << "h=" << h);
    const auto e = ad::value_and_jacobian<0, 1>(ocp::rk4<M>(ode, h), x0, u0, p0);
    const auto z =
        ad::value_and_jacobian<0, 1>(ocp::rk4<M, Sensitivity::frozen>(ode, h), x0, u0, p0);
    // the map: a plain RK4 of aba
    const typename O::Vx y = O::rk4(x0, u0 + p0, h, M);
    const double sy = 1 + y.cwiseAbs().maxCoeff();
    EXPECT_LE((e.value - y).cwiseAbs().maxCoeff(), 1e-12 * sy);
    EXPECT_LE((z.value - y).cwiseAbs().maxCoeff(), 1e-12 * sy);
    // a value-only evaluation of either node is the same map
    const Vec<nx> yv = ad::evaluate(ocp::rk4<M, Sensitivity::frozen>(ode, h), x0, u0, p0);
    EXPECT_LE((yv - y).cwiseAbs().maxCoeff(), 1e-12 * sy);
    // exact: central differences of the plain RK4
    const auto step = [&](const typename O::Vx& xx, const typename O::Vv& uu) {
      return O::rk4(xx, uu + p0, h, M);
    };
    const Mat<nx, nx + nv> J = O::central(step, x0, u0, 1e-6);
    const double sj = 1 + J.cwiseAbs().maxCoeff();
    EXPECT_LE((e.jacobian - J).cwiseAbs().maxCoeff(), 1e-7 * sj);
    // frozen: RK4 of the linearisation at the start (A0, B0 by central differences of f)
    const Mat<nx, nx + nv> J0 = O::central(
        [&](const typename O::Vx& xx, const typename O::Vv& uu) { return O::f(xx, uu + p0); }, x0,
        u0, 1e-6);
    const auto [P, G] =
        linear_rk4<nx, nv>(J0.template leftCols<nx>(), J0.template rightCols<nv>(), h, M);
    Mat<nx, nx + nv> Jz;
    Jz << P, G;
    EXPECT_LE((z.jacobian - Jz).cwiseAbs().maxCoeff(), 1e-7 * sj);
    // the frozen Jacobian is not the exact one, and their distance is O(h^2)
    const double gap = (z.jacobian - e.jacobian).cwiseAbs().maxCoeff();
    EXPECT_GT(gap, 1e-10) << "frozen equals exact: the test shows nothing";
    if (gap_prev > 0) {
      EXPECT_GT(gap_prev / gap, 3.0) << gap_prev << " -> " << gap;
      EXPECT_LT(gap_prev / gap, 5.5) << gap_prev << " -> " << gap;
    }
    gap_prev = gap;
  }
}

TEST(OcpRk4, FrozenIsRk4OfTheLinearisationOnRandomRobots) {
  robot_case<arbor::test::RandomRobot<11, 1>, 1>();
  robot_case<arbor::test::RandomRobot<13, 3>, 1>();
  robot_case<arbor::test::RandomRobot<13, 3>, 2>();
  robot_case<arbor::test::RandomRobot<17, 7>, 1>();
}

}  // namespace
