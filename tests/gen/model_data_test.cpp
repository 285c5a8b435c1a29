// Generated robot data checked against values known independently of the generator: the URDF
// files as read by hand (DoF, joint names and order, limits), the masses published with the robot
// files, the joint lists of the Pinocchio reference files, and a hand-made URDF whose merged
// inertia is derived by hand below.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <robots/atlas.hpp>
#include <robots/double_pendulum.hpp>
#include <robots/gripper.hpp>
#include <robots/iiwa7.hpp>
#include <robots/kinova_gen3.hpp>
#include <robots/merged.hpp>
#include <robots/names.hpp>
#include <robots/yumi.hpp>
#include <robots/yumi_no_grippers.hpp>
#include <robots/yumi_tips.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "arbor/model/robot.hpp"

namespace {

using namespace arbor::robots;
using arbor::model::JointKind;
constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double deg = std::numbers::pi / 180.0;

// Every generated robot satisfies the full contract (syntax and invariants).
static_assert(arbor::Robot<DoublePendulum> && arbor::Robot<Iiwa7> && arbor::Robot<KinovaGen3> &&
              arbor::Robot<YumiNoGrippers> && arbor::Robot<Atlas> && arbor::Robot<Yumi> &&
              arbor::Robot<YumiTips> && arbor::Robot<MergedTest> &&
              arbor::Robot<ShoulderPanRobot> && arbor::Robot<GripperTest>);

/// The `joints` line of a reference file (Pinocchio's joint order).
std::vector<std::string> reference_joints(const std::string& robot) {
  std::ifstream in(std::string(ARBOR_TEST_DATA_DIR) + "/reference/" + robot + ".txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("joints ", 0) == 0) {
      std::istringstream s(line.substr(7));
      std::vector<std::string> names;
      for (std::string n; s >> n;)
        names.push_back(n);
      return names;
    }
  }
  ADD_FAILURE() << "no joints line for " << robot;
  return {};
}

template <class R>
std::vector<std::string> joint_names() {
  return {R::joint_names.begin(), R::joint_names.end()};
}

template <class R>
void expect_depth_first() {
  // parent[i] < i, and every subtree is a contiguous index range (depth-first numbering).
  for (int i = 0; i < R::nb; ++i) {
    EXPECT_LT(R::parent[i], i);
    int end = i + 1;
    auto below = [&](int j) {
      for (int k = j; k >= 0; k = R::parent[k])
        if (k == i)
          return true;
      return false;
    };
    while (end < R::nb && below(end))
      ++end;
    for (int j = end; j < R::nb; ++j)
      EXPECT_FALSE(below(j)) << R::name << " body " << j;
  }
}

template <class R>
void expect_same_joint_set(const std::string& reference) {
  auto ours = joint_names<R>();
  auto ref = reference_joints(reference);
  EXPECT_EQ(ours.size(), ref.size());
  std::sort(ours.begin(), ours.end());
  std::sort(ref.begin(), ref.end());
  EXPECT_EQ(ours, ref);
}

TEST(ModelData, DegreesOfFreedom) {
  EXPECT_EQ(DoublePendulum::nv, 2);
  EXPECT_EQ(Iiwa7::nv, 7);
  EXPECT_EQ(KinovaGen3::nv, 7);
  EXPECT_EQ(YumiNoGrippers::nv, 14);
  EXPECT_EQ(Yumi::nv, 14);
  EXPECT_EQ(YumiTips::nv, 14);
  EXPECT_EQ(Atlas::nv, 30);
}

TEST(ModelData, JointNamesAndOrder) {
  EXPECT_EQ(joint_names<DoublePendulum>(), (std::vector<std::string>{"joint1", "joint2"}));
  EXPECT_EQ(
      joint_names<Iiwa7>(),
      (std::vector<std::string>{"iiwa_joint_1", "iiwa_joint_2", "iiwa_joint_3", "iiwa_joint_4",
                                "iiwa_joint_5", "iiwa_joint_6", "iiwa_joint_7"}));
  EXPECT_EQ(joint_names<KinovaGen3>(),
            (std::vector<std::string>{"joint_1", "joint_2", "joint_3", "joint_4", "joint_5",
                                      "joint_6", "joint_7"}));
  // ABB order along each arm is 1, 2, 7, 3, 4, 5, 6; the right arm comes first in the file.
  const std::vector<std::string> yumi = {
      "yumi_joint_1_r", "yumi_joint_2_r", "yumi_joint_7_r", "yumi_joint_3_r", "yumi_joint_4_r",
      "yumi_joint_5_r", "yumi_joint_6_r", "yumi_joint_1_l", "yumi_joint_2_l", "yumi_joint_7_l",
      "yumi_joint_3_l", "yumi_joint_4_l", "yumi_joint_5_l", "yumi_joint_6_l"};
  EXPECT_EQ(joint_names<YumiNoGrippers>(), yumi);
  EXPECT_EQ(joint_names<Yumi>(), yumi);
  EXPECT_EQ(joint_names<YumiTips>(), yumi);
  // Same joints as the independent reference implementation (its order may differ).
  expect_same_joint_set<DoublePendulum>("double_pendulum");
  expect_same_joint_set<Iiwa7>("iiwa7");
  expect_same_joint_set<KinovaGen3>("kinova_gen3");
  expect_same_joint_set<YumiNoGrippers>("yumi_no_grippers");
  expect_same_joint_set<Atlas>("atlas");
  expect_depth_first<Atlas>();
  expect_depth_first<YumiNoGrippers>();
  EXPECT_EQ(Atlas::parent[0], -1);
  EXPECT_EQ(Atlas::root_link, "pelvis");
}

TEST(ModelData, JointKinds) {
  // Both pendulum axes are "1 0 0"; every arm joint is about +Z in its own frame.
  for (auto k : DoublePendulum::joint_kind)
    EXPECT_EQ(k, JointKind::revolute_x);
  for (auto k : Iiwa7::joint_kind)
    EXPECT_EQ(k, JointKind::revolute_z);
  for (auto k : KinovaGen3::joint_kind)
    EXPECT_EQ(k, JointKind::revolute_z);
  for (auto k : YumiNoGrippers::joint_kind)
    EXPECT_EQ(k, JointKind::revolute_z);
  // Atlas: l_arm_shx has axis "-1 0 0" in the URDF (kept as revolute_x with a negative axis).
  const int shx = arbor::model::joint_index<Atlas>("l_arm_shx");
  ASSERT_GE(shx, 0);
  EXPECT_EQ(Atlas::joint_kind[shx], JointKind::revolute_x);
  EXPECT_EQ(Atlas::joint_axis[shx][0], -1.0);
}

TEST(ModelData, Limits) {
  // Double pendulum: all-zero <limit> is the exporter's "no limits".
  for (const auto& l : DoublePendulum::limits) {
    EXPECT_EQ(l.lower, -inf);
    EXPECT_EQ(l.upper, inf);
    EXPECT_EQ(l.velocity, inf);
    EXPECT_EQ(l.effort, inf);
  }
  // iiwa7: +-170, 120, 170, 120, 170, 120, 175 degrees; effort 300, velocity 10.
  const double iiwa_deg[7] = {170, 120, 170, 120, 170, 120, 175};
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(Iiwa7::limits[i].upper, iiwa_deg[i] * deg, 1e-12);
    EXPECT_NEAR(Iiwa7::limits[i].lower, -iiwa_deg[i] * deg, 1e-12);
    EXPECT_EQ(Iiwa7::limits[i].effort, 300.0);
    EXPECT_EQ(Iiwa7::limits[i].velocity, 10.0);
  }
  // Kinova: joints 1, 3, 5, 7 continuous; 2, 4, 6 limited.
  const double kinova_upper[7] = {inf, 2.24, inf, 2.57, inf, 2.09, inf};
  const double kinova_vel[7] = {1.3963, 1.3963, 1.3963, 1.3963, 1.2218, 1.2218, 1.2218};
  const double kinova_eff[7] = {39, 39, 39, 39, 9, 9, 9};
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(KinovaGen3::limits[i].upper, kinova_upper[i]) << i;
    EXPECT_EQ(KinovaGen3::limits[i].lower, -kinova_upper[i]) << i;
    EXPECT_EQ(KinovaGen3::limits[i].velocity, kinova_vel[i]) << i;
    EXPECT_EQ(KinovaGen3::limits[i].effort, kinova_eff[i]) << i;
  }
  // YuMi joint 2: asymmetric [-2.50454747661, 0.759218224618].
  EXPECT_EQ(YumiNoGrippers::limits[1].lower, -2.50454747661);
  EXPECT_EQ(YumiNoGrippers::limits[1].upper, 0.759218224618);
  EXPECT_EQ(YumiNoGrippers::limits[4].velocity, 6.98131700798);
}

TEST(ModelData, TotalMass) {
  // Published with the robot files (shared/robots/README.md), to their printed precision.
  EXPECT_NEAR(arbor::model::total_mass<Iiwa7>(), 27.11, 0.005);
  EXPECT_NEAR(arbor::model::total_mass<KinovaGen3>(), 8.19, 0.005);
  EXPECT_NEAR(arbor::model::total_mass<Atlas>(), 175.1, 0.05);
  EXPECT_NEAR(arbor::model::total_mass<YumiNoGrippers>(), 43.0, 1e-9);
  // Tips on the flanges: the gripper bases (0.2 kg, fixed to link 7) stay, the fingers (2 x 0.01
  // kg, prismatic, not locked) are dropped (with a warning, tests/gen/gen_cli_test.cpp).
  EXPECT_NEAR(arbor::model::total_mass<YumiTips>(), 43.4, 1e-9);
  // Grippers locked: 2 x 0.22 kg more than the arms-only model.
  EXPECT_NEAR(arbor::model::total_mass<Yumi>(), 43.44, 1e-9);
}

TEST(ModelData, EveryLinkIsAFrame) {
  EXPECT_EQ(Iiwa7::nf, 10);       // world, iiwa_link_0..7, iiwa_link_ee
  EXPECT_EQ(KinovaGen3::nf, 12);  // 12 links
  EXPECT_EQ(YumiNoGrippers::nf, 17);
  EXPECT_EQ(Atlas::nf, 70);
  const int ee = arbor::model::frame_index<Iiwa7>("iiwa_link_ee");
  ASSERT_GE(ee, 0);
  EXPECT_EQ(Iiwa7::frames[ee].body, 6);
  EXPECT_EQ(Iiwa7::frame_id::iiwa_link_ee, ee);
  EXPECT_EQ(arbor::model::frame_index<Iiwa7>("world"), 0);
  EXPECT_EQ(Iiwa7::frames[0].body, -1);
}

// ---- the hand-made URDF (tests/gen/data/merged.urdf) -------------------------------------
TEST(MergedUrdf, TopologyInDocumentOrder) {
  using R = MergedTest;
  // Depth-first in document order: j1 -> j2 -> j3, then the later branch j0_branch (whose name
  // sorts first, so a name-ordered walk would put it first).
  EXPECT_EQ(joint_names<R>(), (std::vector<std::string>{"j1", "j2", "j3", "j0_branch"}));
  EXPECT_EQ(R::parent, (std::array<int, 4>{-1, 0, 1, -1}));
  EXPECT_EQ(R::joint_kind[0], JointKind::revolute_z);
  EXPECT_EQ(R::joint_kind[1], JointKind::prismatic_y);
  EXPECT_EQ(R::joint_axis[1][1], -1.0);
  EXPECT_EQ(R::joint_kind[2], JointKind::revolute_unaligned);
  EXPECT_NEAR(R::joint_axis[2][0], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(R::joint_axis[2][1], std::sqrt(0.5), 1e-15);
  EXPECT_EQ(R::joint_axis[2][2], 0.0);
  EXPECT_EQ(R::joint_kind[3], JointKind::revolute_x);
  EXPECT_EQ(R::joint_axis[3][0], -1.0);
}

TEST(MergedUrdf, MergedInertiaByHand) {
  // Body 0 = link a + link b (fixed joint fa: xyz (1 0 0), rpy (pi/2 0 0)).
  // a: m = 1 at the origin, inertial rpy (0 0 pi/2) turns diag(1, 2, 3) into diag(2, 1, 3).
  // b: m = 3, inertial xyz (0 0 1) in b = Rx(90) (0 0 1) + (1 0 0) = (1, -1, 0) in a;
  //    Rx(90) diag(1, 1, 2) Rx(90)' = diag(1, 2, 1).
  // Combined: m = 4, c = (3 (1, -1, 0)) / 4 = (0.75, -0.75, 0).
  // Parallel axis m (|d|^2 E - d d'): a: d = (-0.75, 0.75, 0) -> [[.5625 .5625 0][.5625 .5625 0]
  // [0 0 1.125]]; b: d = (0.25, -0.25, 0), x3 -> [[.1875 .1875 0][.1875 .1875 0][0 0 .375]].
  // Sum: [[3.75 0.75 0][0.75 3.75 0][0 0 5.5]].
  const auto& Y = MergedTest::body_inertia[0];
  EXPECT_DOUBLE_EQ(Y.mass, 4.0);
  EXPECT_NEAR(Y.com[0], 0.75, 1e-14);
  EXPECT_NEAR(Y.com[1], -0.75, 1e-14);
  EXPECT_NEAR(Y.com[2], 0.0, 1e-14);
  const double expected[3][3] = {{3.75, 0.75, 0}, {0.75, 3.75, 0}, {0, 0, 5.5}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(Y.I[i][j], expected[i][j], 1e-12) << i << j;
  // The massless tool merges into d without changing it; the base has no mass.
  EXPECT_EQ(MergedTest::body_inertia[2].mass, 0.5);
  EXPECT_EQ(MergedTest::base_inertia.mass, 0.0);
  EXPECT_DOUBLE_EQ(arbor::model::total_mass<MergedTest>(), 7.5);
}

TEST(MergedUrdf, PlacementsThroughFixedJoints) {
  // j2 in body 0: fa then j2's origin (0 0 0.5): p = (1 0 0) + Rx(90) (0 0 0.5) = (1, -0.5, 0).
  const auto& X = MergedTest::joint_placement[1];
  const double Rx90[3][3] = {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_EQ(X.R[i][j], Rx90[i][j]);  // snapped exactly
  EXPECT_NEAR(X.p[0], 1.0, 1e-15);
  EXPECT_NEAR(X.p[1], -0.5, 1e-15);
  EXPECT_NEAR(X.p[2], 0.0, 1e-15);
  // Frames: link b on body 0 at (1 0 0) rotated Rx(90); the tool on body 2 at (0 0 0.1).
  const auto& b = MergedTest::frames[MergedTest::frame_id::b];
  EXPECT_EQ(b.name, "b");
  EXPECT_EQ(b.body, 0);
  EXPECT_EQ(b.placement.p[0], 1.0);
  EXPECT_EQ(b.placement.R[1][2], -1.0);
  const auto& tool = MergedTest::frames[MergedTest::frame_id::tool];
  EXPECT_EQ(tool.body, 2);
  EXPECT_EQ(tool.placement.p[2], 0.1);
  EXPECT_EQ(MergedTest::nf, 7);
}

TEST(MergedUrdf, Limits) {
  const auto& L = MergedTest::limits;
  EXPECT_EQ(L[0].lower, -2.0);
  EXPECT_EQ(L[0].upper, 2.0);
  EXPECT_EQ(L[0].velocity, 3.0);
  EXPECT_EQ(L[0].effort, 5.0);
  EXPECT_EQ(L[1].lower, -0.1);
  EXPECT_EQ(L[1].upper, 0.2);
  EXPECT_EQ(L[2].lower, -inf);  // continuous
  EXPECT_EQ(L[2].upper, inf);
  EXPECT_EQ(L[3].upper, inf);  // all-zero limit element
}

// ---- --tip with a gripper below the tip (tests/gen/data/gripper.urdf) ----------------------
// Generated with TIP tool0 LOCK gripper_joint=0.02 (tests/gen/CMakeLists.txt).

/// One rigid part in the frame of body j2 (= link l2): mass, centre of mass, rotational inertia
/// about that centre.
struct Part {
  double m;
  double c[3];
  double I[3][3];
};

TEST(GripperUrdf, TipBodyKeepsTheRigidlyAttachedMass) {
  // Every part below in l2's frame, by hand from the URDF (Rz(90): (x, y, z) -> (-y, x, z), swaps
  // the x and y moments; Ry(90): (x, y, z) -> (z, y, -x), [[a, p, 0], [p, b, 0], [0, 0, c]] ->
  // [[c, 0, 0], [0, b, -p], [0, -p, a]]).
  // gripper_base's frame in l2: flange (0 0 0.2), gripper_mount (0 0 0.01) rpy (0 pi/2 0): origin
  // (0, 0, 0.21), axes Ry(90). Both fingers sit at (0, +-0.02, 0.08) in gripper_base (the prismatic
  // +Y axis at gripper_joint = 0.02 and its mimic at -1 x 0.02).
  const Part parts[] = {
      // l2: (0 0 0.1), 1.5 kg, diag(0.02, 0.02, 0.01).
      {1.5, {0, 0, 0.1}, {{0.02, 0, 0}, {0, 0.02, 0}, {0, 0, 0.01}}},
      // sensor (fixed): (0.05 0 0.1) + Rz(90) (0.02 0 0) = (0.05, 0.02, 0.1); diag(1, 2, 3) mg m^2
      // -> diag(2, 1, 3).
      {0.2, {0.05, 0.02, 0.1}, {{0.002, 0, 0}, {0, 0.001, 0}, {0, 0, 0.003}}},
      // gripper_base (fixed below the tip): (0 0 0.21) + Ry(90) (0 0 0.04) = (0.04, 0, 0.21).
      {0.5, {0.04, 0, 0.21}, {{0.0015, 0, 0}, {0, 0.002, -0.0002}, {0, -0.0002, 0.001}}},
      // finger_l (locked): (0 0 0.21) + Ry(90) (0, 0.02, 0.08 + 0.02) = (0.1, 0.02, 0.21);
      // diag(1e-4, 1e-4, 2e-5) -> diag(2e-5, 1e-4, 1e-4).
      {0.1, {0.1, 0.02, 0.21}, {{2e-5, 0, 0}, {0, 1e-4, 0}, {0, 0, 1e-4}}},
      // pad (fixed to finger_l at (0 -0.005 0.04)): (0, 0.015, 0.12) in gripper_base
      // -> (0.12, 0.015, 0.21); isotropic 1e-6.
      {0.02, {0.12, 0.015, 0.21}, {{1e-6, 0, 0}, {0, 1e-6, 0}, {0, 0, 1e-6}}},
      // finger_r (mimic of the locked joint, at -0.02): (0.1, -0.02, 0.21).
      {0.1, {0.1, -0.02, 0.21}, {{2e-5, 0, 0}, {0, 1e-4, 0}, {0, 0, 1e-4}}},
  };
  // The camera (revolute camera_pan, not locked) is dropped; tool0 has no mass.
  double m = 0, c[3] = {0, 0, 0};
  for (const Part& p : parts) {
    m += p.m;
    for (int k = 0; k < 3; ++k)
      c[k] += p.m * p.c[k];
  }
  for (double& ck : c)
    ck /= m;
  double I[3][3] = {};
  for (const Part& p : parts) {  // parallel axis: I_p + m (|d|^2 E - d d'), d = c_p - c
    const double d[3] = {p.c[0] - c[0], p.c[1] - c[1], p.c[2] - c[2]};
    const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        I[i][j] += p.I[i][j] + p.m * ((i == j ? d2 : 0.0) - d[i] * d[j]);
  }
  static_assert(GripperTest::nb == 2);
  EXPECT_EQ(joint_names<GripperTest>(), (std::vector<std::string>{"j1", "j2"}));
  const auto& Y = GripperTest::body_inertia[1];
  EXPECT_NEAR(m, 2.42, 1e-15);
  EXPECT_NEAR(Y.mass, m, 1e-14);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(Y.com[k], c[k], 1e-14) << k;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(Y.I[i][j], I[i][j], 1e-14) << i << j;
  // The first link is untouched, the cart on the fixed base is dropped (no base mass).
  EXPECT_EQ(GripperTest::body_inertia[0].mass, 2.0);
  EXPECT_EQ(GripperTest::base_inertia.mass, 0.0);
  EXPECT_NEAR(arbor::model::total_mass<GripperTest>(), 4.42, 1e-14);
}

TEST(GripperUrdf, MergedLinksStayFramesOnTheTipBody) {
  using R = GripperTest;
  for (const char* link :
       {"l2", "sensor", "tool0", "gripper_base", "finger_l", "pad", "finger_r"}) {
    const int f = arbor::model::frame_index<R>(link);
    ASSERT_GE(f, 0) << link;
    EXPECT_EQ(R::frames[f].body, 1) << link;
  }
  for (const char* dropped : {"camera", "cart"})
    EXPECT_LT(arbor::model::frame_index<R>(dropped), 0) << dropped;
  EXPECT_EQ(R::nf, 9);  // base, l1 and the seven above
  // finger_r's frame: (0 0 0.21) + Ry(90) (0, -0.02, 0.08) = (0.08, -0.02, 0.21) in l2, axes
  // Ry(90).
  const auto& fr = R::frames[R::frame_id::finger_r];
  EXPECT_NEAR(fr.placement.p[0], 0.08, 1e-15);
  EXPECT_NEAR(fr.placement.p[1], -0.02, 1e-15);
  EXPECT_NEAR(fr.placement.p[2], 0.21, 1e-15);
  EXPECT_EQ(fr.placement.R[0][2], 1.0);
  EXPECT_EQ(fr.placement.R[2][0], -1.0);
}

TEST(NamesUrdf, IdentifiersAreSanitizedAndNamesKept) {
  using R = ShoulderPanRobot;  // from "shoulder-pan robot"
  EXPECT_EQ(R::name, "shoulder-pan robot");
  EXPECT_EQ(R::joint_id::new_, 0);
  EXPECT_EQ(R::frames[R::frame_id::class_].name, "class");
  EXPECT_EQ(R::frames[R::frame_id::_2nd_link].name, "2nd-link");
  EXPECT_EQ(R::frames[R::frame_id::a_b].name, "a__b");
  EXPECT_EQ(R::frames[R::frame_id::a_b_2].name, "a-b");
  EXPECT_EQ(R::frames[R::frame_id::A_b].name, "A b");
  EXPECT_EQ(R::frames[R::frame_id::n_Upper].name, "_Upper");
  EXPECT_EQ(R::frames[R::frame_id::quote_back_slash].name, "quote\"back\\slash");
}

}  // namespace
