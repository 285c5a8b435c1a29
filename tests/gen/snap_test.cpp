// The generator's axis alignment and --snap on plain rotations and axes (no URDF): one
// tolerance, kAxisAlignedTol, separates round-off from a misalignment; --snap TOL makes the
// misalignments up to TOL exact and counts them; the rest are recorded for the report.
#include <gtest/gtest.h>

#include <cmath>

#include "math3.hpp"
#include "snap.hpp"

namespace {

using namespace arbor::gen;

TEST(Snap, NearestAxisAndItsAngle) {
  const double s = std::sin(1e-3), c = std::cos(1e-3);
  const AxisAlignment a = nearest_axis(Vec3{0, -c, s});
  EXPECT_EQ(a.axis, 1);
  EXPECT_EQ(a.sign, -1.0);
  EXPECT_NEAR(a.angle, 1e-3, 1e-15);
}

TEST(Snap, RoundOffIsNeitherReportedNorSnapped) {
  RobotDesc robot;
  const double e = kAxisAlignedTol / 2;
  const Vec3 u{e, 0, std::sqrt(1 - e * e)};
  const Vec3 out = snap_axis(u, 1e-3, robot);
  EXPECT_EQ(out, u);
  EXPECT_EQ(robot.snapped, 0);
  EXPECT_TRUE(robot.misalignment.empty());
}

TEST(Snap, AMisalignedAxisIsRecordedWithoutSnapAndMadeExactWithIt) {
  const double e = 5e-6;
  const Vec3 u{0, std::sin(e), std::cos(e)};
  RobotDesc plain;
  EXPECT_EQ(snap_axis(u, 0, plain), u);
  ASSERT_EQ(plain.misalignment.size(), 1u);
  EXPECT_NEAR(plain.misalignment[0], e, 1e-18);
  RobotDesc tight;  // a tolerance below the misalignment: recorded, not snapped
  EXPECT_EQ(snap_axis(u, 1e-6, tight), u);
  EXPECT_EQ(tight.misalignment.size(), 1u);
  RobotDesc snapped;
  EXPECT_EQ(snap_axis(u, 1e-5, snapped), (Vec3{0, 0, 1}));
  EXPECT_EQ(snapped.snapped, 1);
  EXPECT_NEAR(snapped.snap_max_angle, e, 1e-18);
  EXPECT_TRUE(snapped.misalignment.empty());
}

TEST(Snap, ARotationNearAQuarterTurnSnapsToTheSignedPermutation) {
  // rpy (pi/2 rounded to 1.5708) about x: 3.67e-6 rad from the exact quarter turn.
  const Mat3 R = axis_angle(Vec3{1, 0, 0}, 1.5708);
  const Mat3 P{{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}};
  Mat3 nearest;
  ASSERT_TRUE(nearest_aligned(R, nearest));
  EXPECT_EQ(nearest, P);
  EXPECT_NEAR(rotation_distance(R, P), 1.5708 - std::acos(-1.0) / 2, 1e-15);
  RobotDesc robot;
  EXPECT_EQ(snap_rotation(R, 1e-5, robot), P);
  EXPECT_EQ(robot.snapped, 1);
  // Far from any signed permutation (45 degrees): left alone and not recorded.
  RobotDesc far;
  const Mat3 Q = axis_angle(Vec3{0, 0, 1}, std::acos(-1.0) / 4);
  EXPECT_EQ(snap_rotation(Q, 0.05, far), Q);
  EXPECT_EQ(far.snapped, 0);
}

}  // namespace
