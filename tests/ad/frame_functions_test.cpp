// The task-space function objects of ad/frame_functions.hpp (FramePose, FrameOrientationError in
// its LogMap and CrossSum forms, FrameVelocity) on the paper's Kinova Gen3, the iiwa7 and random
// robots of 3 and 13 joints (branched trees, revolute and prismatic joints): the Analytical
// Jacobian against AutoDiff (dual numbers through the value code) and central differences of the
// value, in double and float, every library call under the allocation guard; closed forms (the
// log map of a known rotation near 0 and pi, the cross sum's sin(angle) axis, the velocity as
// the time derivative of the pose along qd); the pose cache; the Generated tag's AutoDiff
// fallback. Random robots: frame_functions_random*_test.cpp.
#include <gtest/gtest.h>

#include <numbers>
#include <robots/iiwa7.hpp>
#include <robots/kinova_gen3.hpp>

#include "frame_functions_checks.hpp"
#include "random_draw.hpp"

namespace {

using namespace arbor;
using namespace arbor::test::frame_checks;

using Kinova = robots::KinovaGen3;
using Iiwa = robots::Iiwa7;

TEST(FrameFunctions, KinovaGen3) {
  check_all<Kinova, Kinova::frame_id::end_effector_link>(10);
  check_all<Kinova, 3, false>(20);
}
TEST(FrameFunctions, Iiwa7) {
  check_all<Iiwa, Iiwa::nf - 1, false>(30);
}

/// The log map at R_ref = R(q) Rot(a, angle)': e = angle a (R_ref's axes); near 0 and pi, both providers; the q-columns against central differences where the
/// angle stays below pi.
TEST(FrameFunctions, LogMapClosedFormNearZeroAndPi) {
  using R = Kinova;
  using F = ad::FrameOrientationError<R, R::frame_id::end_effector_link, ad::LogMap>;
  constexpr int nv = R::nv;
  const double pi = std::numbers::pi;
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (double angle : {0.0, 1e-9, 1e-5, 1e-3, 0.1, 1.0, 3.0, pi - 1e-3, pi - 1e-6, pi - 1e-9, pi}) {
    VecN<double, nv> q;
    for (int i = 0; i < nv; ++i)
      q[i] = u(gen);
    const Eigen::Vector3d a = arbor::test::draw3([&] { return u(gen); }).normalized();
    const auto pose = value<ad::FramePose<R, R::frame_id::end_effector_link>>(q);
    Eigen::Matrix3d Rf;
    for (int k = 0; k < 9; ++k)
      Rf(k % 3, k / 3) = pose[3 + k];
    const Eigen::Matrix3d Rr = Rf * rotation(a, angle).transpose();
    VecN<double, F::nin> x;
    x.head<nv>() = q;
    for (int k = 0; k < 9; ++k)
      x[nv + k] = Rr(k % 3, k / 3);
    VecN<double, 3> ya, yc;
    Eigen::Matrix<double, 3, F::nin> Ja, Jc;
    value_and_jacobian<F, ad::Analytical, double>(x, ya, Ja);
    value_and_jacobian<F, ad::AutoDiff, double>(x, yc, Jc);
    const Eigen::Vector3d expect = angle * a;
    if (angle == pi)  // the sign of the axis is arbitrary at pi
      EXPECT_LT(std::min((ya - expect).norm(), (ya + expect).norm()), 1e-12) << angle;
    else
      EXPECT_LT((ya - expect).norm(), 1e-12) << angle;
    EXPECT_LT((yc - ya).norm(), 1e-15 * 8) << angle;
    ASSERT_TRUE(Ja.allFinite()) << angle;
    // the q-columns: exact on SO(3) (the AutoDiff derivative of whichever branch)
    const double tol_q = angle > pi - 1e-5 ? 1e-6 : 1e-10;
    EXPECT_LT((Ja.leftCols<nv>() - Jc.leftCols<nv>()).cwiseAbs().maxCoeff(), tol_q) << angle;
    if (angle < pi - 1e-4) {  // differences stay on one side of pi
      EXPECT_LT((Ja.rightCols<9>() - Jc.rightCols<9>()).cwiseAbs().maxCoeff(), 1e-9) << angle;
      auto w = std::make_unique<ad::ValueWorkspace<F>>();
      const Eigen::Matrix<double, 3, nv> Jfd =
          dc::central_diff<3, nv>(q, [&](const VecN<double, nv>& qq) {
            VecN<double, F::nin> xx = x;
            xx.head<nv>() = qq;
            VecN<double, 3> yy;
            ad::bind<F>(*w).value(xx, yy);
            return yy;
          });
      ARBOR_EXPECT_REL(Ja.leftCols<nv>(), Jfd, dc::kFdTol);
    }
  }
}

/// The cross sum of a rotation about one axis a by angle t: e = sin(t) a (world axes).
TEST(FrameFunctions, CrossSumClosedForm) {
  using R = Iiwa;
  constexpr int f = R::nf - 1;
  using F = ad::FrameOrientationError<R, f, ad::CrossSum>;
  constexpr int nv = R::nv;
  std::mt19937 gen(6);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (double angle : {0.0, 0.3, 2.0, 3.1}) {
    VecN<double, nv> q;
    for (int i = 0; i < nv; ++i)
      q[i] = u(gen);
    const Eigen::Vector3d a = arbor::test::draw3([&] { return u(gen); }).normalized();
    const auto pose = value<ad::FramePose<R, f>>(q);
    Eigen::Matrix3d Rf;
    for (int k = 0; k < 9; ++k)
      Rf(k % 3, k / 3) = pose[3 + k];
    const Eigen::Matrix3d Rr = rotation(a, angle).transpose() * Rf;  // R = Rot(a, t) R_ref
    VecN<double, F::nin> x;
    x.head<nv>() = q;
    for (int k = 0; k < 9; ++k)
      x[nv + k] = Rr(k % 3, k / 3);
    EXPECT_LT((value<F>(x) - std::sin(angle) * a).norm(), 1e-14) << angle;
  }
}

/// A FramePosition after a FramePose at the same q on a WithPoseCache workspace takes the pose's
/// position rows; at another q it computes its own; both agree with a plain FramePosition.
TEST(FrameFunctions, PoseCacheServesFramePosition) {
  using R = Kinova;
  constexpr int f = R::frame_id::end_effector_link;
  using Pose = ad::FramePose<R, f>;
  using Pos = ad::FramePosition<R, f>;
  using W = ad::WithPoseCache<ad::JacobianWorkspace<Pose, ad::Analytical>>;
  auto ws = std::make_unique<W>();
  std::mt19937 gen(8);
  const auto q1 = random_input<Pos>(gen), q2 = random_input<Pos>(gen);
  VecN<double, 12> yp;
  Eigen::Matrix<double, 12, R::nv> Jp;
  VecN<double, 3> y1, y2, r1, r2;
  Eigen::Matrix<double, 3, R::nv> J1, J2, K1, K2;
  {
    NoAllocScope guard;
    ad::bind<Pose>(*ws).value_and_jacobian<ad::Analytical>(q1, yp, Jp);
    ad::bind<Pos>(*ws).value_and_jacobian<ad::Analytical>(q1, y1, J1);
  }
  EXPECT_EQ(ws->pose_cache.frame, f);
  EXPECT_TRUE((J1.array() == Jp.topRows<3>().array()).all());  // taken from the cache
  ad::bind<Pos>(*ws).value_and_jacobian<ad::Analytical>(q2, y2, J2);
  value_and_jacobian<Pos, ad::Analytical, double>(q1, r1, K1);
  value_and_jacobian<Pos, ad::Analytical, double>(q2, r2, K2);
  ARBOR_EXPECT_REL(y1, r1, 1e-14);
  ARBOR_EXPECT_REL(J1, K1, 1e-13);
  EXPECT_TRUE((J2.array() == K2.array()).all());  // recomputed
}

/// Under the Generated tag, functions without generated code run AutoDiff (same workspace).
TEST(FrameFunctions, GeneratedFallsBackToAutoDiff) {
  using F = ad::FrameOrientationError<Iiwa, Iiwa::nf - 1, ad::CrossSum>;
  static_assert(std::is_same_v<ad::ProviderOf<ad::Generated, F>, ad::AutoDiff>);
  static_assert(std::is_same_v<ad::JacobianWorkspace<F, ad::Generated>,
                               ad::JacobianWorkspace<F, ad::AutoDiff>>);
  static_assert(
      std::is_same_v<ad::ProviderOf<ad::Generated, ad::FramePosition<Iiwa, 1>>, ad::Generated>);
  std::mt19937 gen(9);
  const auto x = random_input<F>(gen);
  VecN<double, 3> yg, yc;
  Eigen::Matrix<double, 3, F::nin> Jg, Jc;
  value_and_jacobian<F, ad::Generated, double>(x, yg, Jg);
  value_and_jacobian<F, ad::AutoDiff, double>(x, yc, Jc);
  EXPECT_TRUE((Jg.array() == Jc.array()).all());
}

}  // namespace
