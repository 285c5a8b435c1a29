// The robots arbor-gen accepts from defective descriptions (tests/gen/data/real: inconsistent
// inertias kept or fixed, round-off negatives clamped, mimic groups locked, rounded angles with
// and without --snap, everyday export details) give finite dynamics with a positive definite
// mass matrix at random configurations; the fixes and locks have the values derived by hand in
// the URDFs' comments.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <arbor/dynamics/dynamics.hpp>
#include <cmath>
#include <memory>
#include <random>
#include <robots/defect_everyday.hpp>
#include <robots/defect_mimic_hand.hpp>
#include <robots/defect_rounded.hpp>
#include <robots/defect_rounded_snapped.hpp>
#include <robots/defect_roundoff.hpp>
#include <robots/defect_singular.hpp>
#include <robots/defect_singular_fixed.hpp>
#include <robots/defect_triangle.hpp>
#include <robots/defect_triangle_fixed.hpp>

#include "alloc_guard.hpp"

namespace {

using namespace arbor::robots;
using arbor::test::NoAllocScope;

template <class R>
Eigen::Matrix<double, R::nv, 1> random_q(std::mt19937& gen) {
  Eigen::Matrix<double, R::nv, 1> q;
  for (int i = 0; i < R::nv; ++i) {
    const double lo = std::isfinite(R::limits[i].lower) ? R::limits[i].lower : -3.0;
    const double hi = std::isfinite(R::limits[i].upper) ? R::limits[i].upper : 3.0;
    q[i] = std::uniform_real_distribution<double>(lo, hi)(gen);
  }
  return q;
}

/// rnea, nle, crba and aba finite; M symmetric positive definite; M aba(tau) + nle = tau.
template <class R>
void expect_sound_dynamics() {
  static_assert(arbor::Robot<R>);
  using Vec = Eigen::Matrix<double, R::nv, 1>;
  std::mt19937 gen(18);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  auto d = std::make_unique<arbor::Data<R, double>>();
  for (int sample = 0; sample < 25; ++sample) {
    const Vec q = random_q<R>(gen);
    Vec v, a, tau;
    for (int i = 0; i < R::nv; ++i) {
      v[i] = u(gen);
      a[i] = u(gen);
      tau[i] = u(gen);
    }
    Vec id, bias, ddq;
    typename arbor::Data<R, double>::Matrix M;
    {
      NoAllocScope guard;
      id = arbor::rnea(*d, q, v, a);
      bias = arbor::nle(*d, q, v);
      M = arbor::crba(*d, q);
      ddq = arbor::aba(*d, q, v, tau);
    }
    ASSERT_TRUE(id.allFinite()) << R::name << " sample " << sample;
    ASSERT_TRUE(bias.allFinite()) << R::name;
    ASSERT_TRUE(M.allFinite()) << R::name;
    ASSERT_TRUE(ddq.allFinite()) << R::name;
    EXPECT_LE((M - M.transpose()).norm(), 1e-12 * M.norm()) << R::name;
    const Eigen::SelfAdjointEigenSolver<decltype(M)> eig(M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << R::name << " sample " << sample;
    const Vec back = M * ddq + bias;
    EXPECT_LE((back - tau).norm(), 1e-9 * (1 + tau.norm())) << R::name;
    EXPECT_LE((M * a + bias - id).norm(), 1e-9 * (1 + id.norm())) << R::name;
  }
}

TEST(DefectDynamics, EveryAcceptedModelIsSound) {
  expect_sound_dynamics<DefectTriangle>();
  expect_sound_dynamics<DefectTriangleFixed>();
  expect_sound_dynamics<DefectRoundoff>();
  expect_sound_dynamics<DefectSingular>();
  expect_sound_dynamics<DefectSingularFixed>();
  expect_sound_dynamics<DefectMimicHand>();
  expect_sound_dynamics<DefectRounded>();
  expect_sound_dynamics<DefectRoundedSnapped>();
  expect_sound_dynamics<DefectEveryday>();
}

TEST(DefectDynamics, FixedSingularInertiaIsTheHandDerivedProjection) {
  // 1e-4 * ones(3, 3) -> 1e-4 * (identity + ones(3, 3) / 3) (see inertia_singular.urdf).
  const auto& I = DefectSingularFixed::body_inertia[0].I;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(I[i][j], 1e-4 * ((i == j ? 1.0 : 0.0) + 1.0 / 3.0), 1e-18) << i << j;
  const auto& raw = DefectSingular::body_inertia[0].I;  // kept as given without --fix-inertia
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(raw[i][j], 1e-4, 1e-18) << i << j;
}

TEST(DefectDynamics, MimicGroupsAreLockedAtTheStatedValues) {
  // thumb at 0.4 (mid-range of [0.2, 0.6]); thumb_tip = 2 * 0.4 + 0.1 = 0.9; thumb_nail =
  // 0.5 * 0.9 = 0.45. All about y, so the frames of thumb_mid and thumb_end are rotated about
  // y by 0.4 + 0.9 = 1.3 and 1.75 relative to the forearm body.
  using R = DefectMimicHand;
  static_assert(R::nv == 2);
  for (const auto& [link, angle] : {std::pair<const char*, double>{"thumb_base", 0.4},
                                    {"thumb_mid", 1.3},
                                    {"thumb_end", 1.75}}) {
    const int f = arbor::model::frame_index<R>(link);
    ASSERT_GE(f, 0) << link;
    EXPECT_EQ(R::frames[f].body, 1) << link;
    const auto& Rm = R::frames[f].placement.R;
    EXPECT_NEAR(Rm[0][0], std::cos(angle), 1e-15) << link;
    EXPECT_NEAR(Rm[0][2], std::sin(angle), 1e-15) << link;
    EXPECT_NEAR(Rm[2][0], -std::sin(angle), 1e-15) << link;
    EXPECT_EQ(Rm[1][1], 1.0) << link;
  }
  // The grip group at 0: the fingers sit at their joint origins, (0, +-0.01, 0.35) in 'fore'.
  const int left = arbor::model::frame_index<R>("finger_left");
  const int right = arbor::model::frame_index<R>("finger_right");
  EXPECT_NEAR(R::frames[left].placement.p[1], 0.01, 1e-15);
  EXPECT_NEAR(R::frames[right].placement.p[1], -0.01, 1e-15);
  EXPECT_NEAR(R::frames[right].placement.p[2], 0.35, 1e-15);
}

TEST(DefectDynamics, SnapGivesExactStructureAndASmallModelChange) {
  using A = DefectRounded;
  using B = DefectRoundedSnapped;
  EXPECT_EQ(A::joint_kind[2], arbor::model::JointKind::revolute_unaligned);
  EXPECT_EQ(B::joint_kind[2], arbor::model::JointKind::revolute_z);
  for (int b = 0; b < B::nb; ++b)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double x = B::joint_placement[b].R[i][j];
        EXPECT_TRUE(x == 0.0 || x == 1.0 || x == -1.0) << b << i << j << " " << x;
      }
  // The rotations changed by at most 7.35e-6 rad: M changes by about that much, relatively.
  std::mt19937 gen(7);
  auto da = std::make_unique<arbor::Data<A, double>>();
  auto db = std::make_unique<arbor::Data<B, double>>();
  double worst = 0;
  for (int sample = 0; sample < 25; ++sample) {
    const auto q = random_q<A>(gen);
    const auto Ma = arbor::crba(*da, q);
    const auto Mb = arbor::crba(*db, q);
    worst = std::max(worst, (Ma - Mb).norm() / Ma.norm());
  }
  EXPECT_GT(worst, 0.0);
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
