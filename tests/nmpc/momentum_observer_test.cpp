// The generalized-momentum observer (nmpc/momentum_observer.hpp):
//   - beta = C' qd - g against an independent route: dT/dq of the kinetic energy by central
//     differences of M(q) (the textbook CRBA of support/textbook_rbd.hpp) minus g (textbook RNEA);
//     p = M qd against the textbook M; on the 2-DoF arm and the Kinova Gen3;
//   - the estimate of a constant unknown joint torque on the 2-DoF arm, simulated in plain code
//     (textbook forward dynamics, RK4 at 50 substeps per sample, torque held over each sample),
//     follows the closed form d (1 - e^(-K k dt)) of the first-order observer, for two gains;
//   - a heavier second link on the plant (the model does not know it): at rest the estimate
//     converges to the torque of the model error, g_nominal(q) - g_true(q);
//   - no allocation, non-finite inputs rejected with the estimate kept.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include <robots/double_pendulum.hpp>
#include <robots/kinova_gen3.hpp>
#include "alloc_guard.hpp"
#include "arbor/nmpc/momentum_observer.hpp"
#include "textbook_rbd.hpp"

namespace {

using Arm = arbor::robots::DoublePendulum;
using Gen3 = arbor::robots::KinovaGen3;
namespace tb = arbor::textbook;
const Eigen::Vector3d kGravity(0, 0, -9.81);

/// beta = dT/dq - g by central differences of the textbook M and the textbook gravity torque.
template <class R>
tb::VecX reference_beta(const tb::Model& m, const tb::VecX& q, const tb::VecX& v) {
  const int n = int(q.size());
  tb::VecX dT(n);
  const double eps = 1e-6;
  for (int j = 0; j < n; ++j) {
    tb::VecX qp = q, qm = q;
    qp[j] += eps;
    qm[j] -= eps;
    dT[j] = 0.5 * v.dot((tb::crba(m, qp) - tb::crba(m, qm)) * v) / (2 * eps);
  }
  const tb::VecX g = tb::rnea(m, q, tb::VecX::Zero(n), tb::VecX::Zero(n), kGravity);
  return dT - g;
}

template <class R>
void check_terms(unsigned seed) {
  constexpr int n = R::nv;
  using Obs = arbor::nmpc::MomentumObserver<R>;
  static Obs obs(10.0, 0.01);
  const tb::Model m = tb::make_model<R>();
  std::srand(seed);
  for (int trial = 0; trial < 5; ++trial) {
    const typename Obs::Vq q = Obs::Vq::Random();
    const typename Obs::Vv v = 2.0 * Obs::Vv::Random();
    typename Obs::Vv p, beta;
    obs.momentum_terms(q, v, p, beta);
    const tb::VecX qx = q, vx = v;
    const tb::VecX p_ref = tb::crba(m, qx) * vx;
    const tb::VecX b_ref = reference_beta<R>(m, qx, vx);
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(p[i], p_ref[i], 1e-12 * (1 + p_ref.cwiseAbs().maxCoeff())) << "p " << i;
      // central differences: O(eps^2) truncation, O(1e-16 / eps) round-off
      EXPECT_NEAR(beta[i], b_ref[i], 1e-7 * (1 + b_ref.cwiseAbs().maxCoeff())) << "beta " << i;
    }
  }
}

TEST(MomentumObserver, MomentumAndBetaMatchTheKineticEnergyGradient) {
  check_terms<Arm>(3);
  check_terms<Gen3>(5);
}

/// The arm simulated in plain code: textbook forward dynamics with an extra torque d_true and an
/// extra point mass (kg) on link 2 at its joint's axis offset (0, 0, l) in link 2's frame (the
/// model is the URDF's; the plant's is changed here).
struct ArmPlant {
  tb::Model m = tb::make_model<Arm>();
  Eigen::Vector2d d_true = Eigen::Vector2d::Zero();
  Eigen::Vector2d q = Eigen::Vector2d(0.4, -0.3), v = Eigen::Vector2d::Zero();
  Eigen::Vector2d f(const Eigen::Vector2d& qq, const Eigen::Vector2d& vv,
                    const Eigen::Vector2d& tau) const {
    return tb::aba(m, qq, vv, tau + d_true, kGravity);
  }
  /// One sample of length dt under the held torque tau: RK4, `sub` substeps.
  void step(const Eigen::Vector2d& tau, double dt, int sub = 50) {
    const double hs = dt / sub;
    for (int s = 0; s < sub; ++s) {
      const Eigen::Vector2d k1q = v, k1v = f(q, v, tau);
      const Eigen::Vector2d k2q = v + 0.5 * hs * k1v, k2v = f(q + 0.5 * hs * k1q, k2q, tau);
      const Eigen::Vector2d k3q = v + 0.5 * hs * k2v, k3v = f(q + 0.5 * hs * k2q, k3q, tau);
      const Eigen::Vector2d k4q = v + hs * k3v, k4v = f(q + hs * k3q, k4q, tau);
      q += hs / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
      v += hs / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
  }
};

/// A torque that keeps the arm moving (computed-torque PD to a moving target), held per sample.
Eigen::Vector2d drive(const tb::Model& m, const Eigen::Vector2d& q, const Eigen::Vector2d& v,
                      double t) {
  const Eigen::Vector2d target(0.4 + 0.3 * std::sin(2 * t), -0.3 + 0.2 * std::cos(3 * t));
  const tb::VecX g = tb::rnea(m, q, tb::VecX::Zero(2), tb::VecX::Zero(2), kGravity);
  const tb::MatX M = tb::crba(m, q);
  return g + M * (25.0 * (target - q) - 10.0 * v);  // 5 rad/s, critically damped
}

TEST(MomentumObserver, ConstantTorqueFollowsTheFirstOrderClosedForm) {
  for (const double K : {5.0, 40.0}) {
    const double dt = 0.01;
    using Obs = arbor::nmpc::MomentumObserver<Arm>;
    static Obs obs(K, dt);
    obs.set_gain(K, dt);
    ArmPlant plant;
    plant.d_true = Eigen::Vector2d(0.15, -0.08);
    ASSERT_TRUE(obs.reset(plant.q, plant.v));
    double worst = 0;
    for (int k = 1; k <= 150; ++k) {
      const Eigen::Vector2d tau = drive(plant.m, plant.q, plant.v, (k - 1) * dt);
      plant.step(tau, dt);
      bool ok = false;
      ARBOR_EXPECT_NO_ALLOC(ok = obs.update(plant.q, plant.v, tau));
      ASSERT_TRUE(ok);
      const Eigen::Vector2d closed = plant.d_true * (1 - std::exp(-K * k * dt));
      worst = std::max(worst, (obs.estimate() - closed).cwiseAbs().maxCoeff());
    }
    // the trapezoid rule on beta over 10 ms on this motion (O(dt^2) beta''): below 0.5 % of d
    EXPECT_LT(worst, 7.5e-4) << "K = " << K;
    EXPECT_NEAR(obs.estimate()[0], plant.d_true[0], 7.5e-4) << "K = " << K;
    EXPECT_NEAR(obs.estimate()[1], plant.d_true[1], 7.5e-4) << "K = " << K;
    std::printf("K = %g: max |d_hat - d (1 - e^(-K t))| = %.2e N m over 1.5 s\n", K, worst);
  }
}

TEST(MomentumObserver, ExtraMassOnThePlantIsEstimatedAsItsTorque) {
  const double dt = 0.01, K = 20;
  using Obs = arbor::nmpc::MomentumObserver<Arm>;
  static Obs obs(K, dt);
  ArmPlant plant;
  // link 2 30 % heavier on the plant (mass and rotational inertia, the same centre of mass: a
  // rigid body still); the observer's model is the URDF's
  plant.m.inertia[std::size_t(plant.m.n - 1)] *= 1.3;
  const tb::Model nominal = tb::make_model<Arm>();
  ASSERT_TRUE(obs.reset(plant.q, plant.v));
  // hold still under the nominal gravity torque: the arm moves (the payload pulls), the estimate
  // converges to the torque of the model error at the plant's slow motion
  Eigen::Vector2d tau = Eigen::Vector2d::Zero();
  for (int k = 1; k <= 800; ++k) {
    tau = drive(nominal, plant.q, plant.v, 0.0);  // nominal gravity + PD to a fixed target
    plant.step(tau, dt);
    ASSERT_TRUE(obs.update(plant.q, plant.v, tau));
  }
  // at rest the error torque is the extra mass's gravity torque: g_true(q) - g_nominal(q)
  ASSERT_LT(plant.v.norm(), 1e-6);
  const tb::VecX gt = tb::rnea(plant.m, plant.q, tb::VecX::Zero(2), tb::VecX::Zero(2), kGravity);
  const tb::VecX gn = tb::rnea(nominal, plant.q, tb::VecX::Zero(2), tb::VecX::Zero(2), kGravity);
  const tb::VecX d = -(gt - gn);  // plant: M qdd = tau - g_true = tau - g_nominal + d
  EXPECT_GT(d.cwiseAbs().maxCoeff(), 1e-2);
  EXPECT_NEAR(obs.estimate()[0], d[0], 1e-6);
  EXPECT_NEAR(obs.estimate()[1], d[1], 1e-6);
}

TEST(MomentumObserver, NonFiniteInputKeepsTheEstimate) {
  using Obs = arbor::nmpc::MomentumObserver<Arm, float>;
  static Obs obs(10.0f, 0.01f);
  const Obs::Vv zero = Obs::Vv::Zero();
  EXPECT_FALSE(obs.update(zero, zero, zero));  // before reset
  ASSERT_TRUE(obs.reset(Obs::Vq(0.1f, 0.2f), zero, Obs::Vv(0.5f, -0.5f)));
  Obs::Vv bad = zero;
  bad[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(obs.update(Obs::Vq(0.1f, 0.2f), bad, zero));
  EXPECT_FALSE(obs.reset(Obs::Vq(0.1f, 0.2f), bad));
  EXPECT_EQ(obs.estimate(), Obs::Vv(0.5f, -0.5f));
  EXPECT_NEAR(obs.alpha(), 1 - std::exp(-0.1f), 1e-6f);
}

}  // namespace
