// The Generated AD provider on every target (host, AArch64, Cortex-M7 in double and float,
// Cortex-M4F in float): the double pendulum's generated Jacobians of FD and ID (straight-line
// code written by arbor-adgen on the host, gen/ad; cross builds take the host build's header,
// tests/targets/CMakeLists.txt) against the analytical derivative routines run on the same target.
#include <cmath>
#include <robots/double_pendulum.hpp>
#include <robots/double_pendulum_ad.hpp>

#include "arbor/ad/rbd_functions.hpp"
#include "arbor_test.hpp"

namespace {

using R = arbor::robots::DoublePendulum;

/// max |a - b| / max(1, max |b|) over all entries.
template <class A, class B>
double rel_error(const A& a, const B& b) {
  double d = 0.0, s = 1.0;
  for (int i = 0; i < a.size(); ++i) {
    d = std::fmax(d, std::fabs(double(a.data()[i]) - double(b.data()[i])));
    s = std::fmax(s, std::fabs(double(b.data()[i])));
  }
  return d / s;
}

/// Generated J (at scalar T) against the analytical J (at T) for a few inputs; the worst error.
template <class F, class T>
double worst_error() {
  constexpr int n = F::nin, m = F::nout;
  arbor::ad::JacobianWorkspace<F, arbor::ad::Analytical, T> wa{};
  double worst = 0.0;
  for (int s = 0; s < 4; ++s) {
    arbor::VecN<T, n> x = arbor::VecN<T, n>::Zero();
    for (int i = 0; i < n; ++i)
      x[i] = T(0.9 * std::sin(1.7 * s + 0.61 * i + 0.3));
    arbor::VecN<T, m> yg = arbor::VecN<T, m>::Zero(), ya = arbor::VecN<T, m>::Zero();
    Eigen::Matrix<T, m, n> Jg = Eigen::Matrix<T, m, n>::Zero();
    Eigen::Matrix<T, m, n> Ja = Eigen::Matrix<T, m, n>::Zero();
    {
      arbor::test::NoAllocScope guard;
      arbor::ad::GeneratedCode<F>::jacobian(x.data(), yg.data(), Jg.data());
      arbor::ad::bind<F>(wa).template value_and_jacobian<arbor::ad::Analytical>(x, ya, Ja);
    }
    worst = std::fmax(worst, std::fmax(rel_error(yg, ya), rel_error(Jg, Ja)));
  }
  return worst;
}

#if ARBOR_TEST_DOUBLE
TEST(AdGeneratedTarget, DoublePendulumJacobiansEqualAnalyticalDouble) {
  EXPECT_LE((worst_error<arbor::ad::ForwardDynamics<R>, double>()), 1e-11);
  EXPECT_LE((worst_error<arbor::ad::InverseDynamics<R>, double>()), 1e-11);
}
#endif

#if ARBOR_TEST_FLOAT
TEST(AdGeneratedTarget, DoublePendulumJacobiansEqualAnalyticalFloat) {
  EXPECT_LE((worst_error<arbor::ad::ForwardDynamics<R>, float>()), 1e-4);
  EXPECT_LE((worst_error<arbor::ad::InverseDynamics<R>, float>()), 1e-4);
}
#endif

}  // namespace
