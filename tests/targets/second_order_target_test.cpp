// The Kinova Gen3's second-order routines on the targets (issue 17): the contracted Hessians of
// lambda' ID (rnea_second_order_derivatives) and lambda' FD (aba_second_order_derivatives), in
// double, against central differences of the first-order routines' gradients (rnea_derivatives,
// aba_derivatives: checked against Pinocchio's values by derivatives_target_*), their gradients
// against those routines, and exact symmetry. Static storage, as firmware keeps it; no files.
// Cost: one Hessian of each kind plus 2 x 3n first-order calls per kind for the differences.
#include <robots/kinova_gen3.hpp>

#include <cmath>

#include "arbor/derivatives/derivatives.hpp"
#include "arbor_test.hpp"

namespace {
using R = arbor::robots::KinovaGen3;
constexpr int n = R::nv;
using Vec = Eigen::Matrix<double, n, 1>;
using Vec3n = Eigen::Matrix<double, 3 * n, 1>;
using Mat3n = Eigen::Matrix<double, 3 * n, 3 * n>;

arbor::Data<R, double> data;
arbor::DerivativeData<R, double> deriv;
arbor::SecondOrderData<R, double> so;
Mat3n fd_matrix;

/// A fixed state in [-1, 1] (a linear congruential sequence; the same on every target).
struct State {
  Vec q, v, a, lambda;
};
State state() {
  unsigned s = 2024u;
  auto next = [&] {
    s = s * 1664525u + 1013904223u;
    return double(s >> 8) / double(1u << 24) * 2.0 - 1.0;
  };
  State st;
  for (int i = 0; i < n; ++i) {
    st.q[i] = next();
    st.v[i] = next();
    st.a[i] = next();
    st.lambda[i] = next();
  }
  return st;
}

/// lambda' [dtau/dq, dtau/dv, M] at x = (q, v, a) (ID) or lambda' [dddq/dq, dddq/dv, M^-1] at
/// x = (q, v, tau) (FD), from the first-order routines.
template <bool FD>
[[gnu::noinline]] Vec3n gradient(const Vec3n& x, const Vec& lambda) {
  const Vec q = x.segment<n>(0), v = x.segment<n>(n), u = x.segment<n>(2 * n);
  Vec3n r;
  if constexpr (FD) {
    arbor::aba_derivatives<R>(data, deriv, q, v, u);
    r << deriv.ddq_dq.transpose() * lambda, deriv.ddq_dv.transpose() * lambda, data.Minv * lambda;
  } else {
    arbor::rnea_derivatives<R>(data, deriv, q, v, u);
    r << deriv.dtau_dq.transpose() * lambda, deriv.dtau_dv.transpose() * lambda, data.M * lambda;
  }
  return r;
}

/// Central differences of a gradient (step 1e-5) into fd_matrix.
template <class F>
void central_diff(const Vec3n& x, F&& grad) {
  constexpr double h = 1e-5;
  for (int k = 0; k < 3 * n; ++k) {
    Vec3n xp = x, xm = x;
    xp[k] += h;
    xm[k] -= h;
    fd_matrix.col(k) = (grad(xp) - grad(xm)) / (2 * h);
  }
}

/// max |A - B| / max(1, max |B|).
template <class A, class B>
double rel_error(const A& x, const B& ref) {
  return (x - ref).cwiseAbs().maxCoeff() / std::fmax(1.0, ref.cwiseAbs().maxCoeff());
}

/// so (just computed at x) against the first-order routines: gradient (gradient_tol), exact
/// symmetry, the zero u-u and u-v blocks, the Hessian against central differences (1e-6).
template <bool FD>
void check_against_first_order(const Vec3n& x, const Vec& lambda, double gradient_tol) {
  EXPECT_LE(rel_error(so.gradient, gradient<FD>(x, lambda)), gradient_tol);
  EXPECT_TRUE(so.hessian == so.hessian.transpose());
  EXPECT_TRUE((so.hessian.bottomRightCorner<n, 2 * n>().array() == 0).all());
  const Mat3n H = so.hessian;
  central_diff(x, [&](const Vec3n& y) { return gradient<FD>(y, lambda); });
  EXPECT_LE(rel_error(H, fd_matrix), 1e-6);
}

TEST(KinovaGen3, SecondOrderIdMatchesDifferencesOfFirstOrder) {
  const State s = state();
  {
    arbor::test::NoAllocScope guard;
    arbor::rnea_second_order_derivatives<R>(data, so, s.q, s.v, s.a, s.lambda);
  }
  Vec3n z;
  z << s.q, s.v, s.a;
  check_against_first_order<false>(z, s.lambda, 1e-11);
}

TEST(KinovaGen3, SecondOrderFdMatchesDifferencesOfFirstOrder) {
  const State s = state();
  const Vec tau = 10.0 * s.a;
  {
    arbor::test::NoAllocScope guard;
    arbor::aba_second_order_derivatives<R>(data, deriv, so, s.q, s.v, tau, s.lambda);
  }
  Vec3n x;
  x << s.q, s.v, tau;
  check_against_first_order<true>(x, s.lambda, 1e-10);
}
}  // namespace
