// The robot contract: hand-written robots with one defect each are rejected with that defect's
// error, and a correct one is accepted.
#include "arbor_test.hpp"

#include <array>
#include <limits>
#include <string_view>
#include <utility>

#include "arbor/model/robot.hpp"
#include "status_names.hpp"

// Failure messages name the RobotError (to_string), not its number.
namespace arbor::model {
using ::arbor::test::status_names::operator<<;
}

namespace {

using namespace arbor::model;
constexpr double inf = std::numeric_limits<double>::infinity();
constexpr Placement kIdentity = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
constexpr Inertia kUnit = {1.0, {0, 0, 0}, {{0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0.1}}};
constexpr Inertia kMassless = {0.0, {0, 0, 0}, {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};

/// A correct two-body chain; each defect below derives from it and changes one member.
struct Good {
  static constexpr std::string_view name = "good";
  static constexpr int nq = 2, nv = 2, nb = 2, nf = 2;
  static constexpr std::array<int, nb> parent = {-1, 0};
  static constexpr std::array<JointKind, nb> joint_kind = {JointKind::revolute_z,
                                                           JointKind::prismatic_unaligned};
  static constexpr std::array<Vec3, nb> joint_axis = {{{{0, 0, 1}}, {{0.6, 0.8, 0}}}};
  static constexpr std::array<Placement, nb> joint_placement = {kIdentity, kIdentity};
  static constexpr std::array<Inertia, nb> body_inertia = {kUnit, kUnit};
  static constexpr Inertia base_inertia = kMassless;
  static constexpr std::array<Limits, nv> limits = {{{-1, 1, 2, 3}, {-inf, inf, inf, inf}}};
  static constexpr std::array<std::string_view, nb> joint_names = {"j0", "j1"};
  static constexpr std::array<std::string_view, nb> body_names = {"b0", "b1"};
  static constexpr std::array<Frame, nf> frames = {{{"b0", 0, kIdentity}, {"b1", 1, kIdentity}}};
};

struct BadTopology : Good {
  static constexpr std::array<int, nb> parent = {-1, 1};
};
struct BadAxisNorm : Good {
  static constexpr std::array<Vec3, nb> joint_axis = {{{{0, 0, 1}}, {{1, 1, 0}}}};
};
struct BadAlignedAxis : Good {
  static constexpr std::array<Vec3, nb> joint_axis = {{{{0, 1, 0}}, {{0.6, 0.8, 0}}}};
};
struct BadRotation : Good {
  static constexpr std::array<Placement, nb> joint_placement = {
      kIdentity, Placement{{{1, 0, 0}, {0, 1, 0}, {0, 0, -1}}, {0, 0, 0}}};  // a reflection
};
struct BadMass : Good {
  static constexpr std::array<Inertia, nb> body_inertia = {
      kUnit, Inertia{-1.0, {0, 0, 0}, {{0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0.1}}}};
};
struct MasslessLeaf : Good {
  static constexpr std::array<Inertia, nb> body_inertia = {kUnit, kMassless};
};
struct BadInertia : Good {
  static constexpr std::array<Inertia, nb> body_inertia = {
      kUnit, Inertia{1.0, {0, 0, 0}, {{0.1, 0, 0}, {0, -0.1, 0}, {0, 0, 0.1}}}};
};
struct BadLimits : Good {
  static constexpr std::array<Limits, nv> limits = {{{1, -1, 2, 3}, {-inf, inf, inf, inf}}};
};
struct BadFrame : Good {
  static constexpr std::array<Frame, nf> frames = {{{"b0", 0, kIdentity}, {"b1", 2, kIdentity}}};
};
struct BadSizes : Good {
  static constexpr int nq = 3;
};

static_assert(RobotModel<Good> && arbor::Robot<Good>);
static_assert(RobotModel<BadTopology> && !arbor::Robot<BadTopology>);
static_assert(!RobotModel<int>);

TEST(RobotContract, EachDefectHasItsOwnError) {
  EXPECT_EQ(check_robot<Good>(), RobotError::none);
  EXPECT_EQ(check_robot<BadTopology>(), RobotError::topology);
  EXPECT_EQ(check_robot<BadAxisNorm>(), RobotError::axis);
  EXPECT_EQ(check_robot<BadAlignedAxis>(), RobotError::axis);
  EXPECT_EQ(check_robot<BadRotation>(), RobotError::rotation);
  EXPECT_EQ(check_robot<BadMass>(), RobotError::mass);
  EXPECT_EQ(check_robot<MasslessLeaf>(), RobotError::massless_subtree);
  EXPECT_EQ(check_robot<BadInertia>(), RobotError::inertia);
  EXPECT_EQ(check_robot<BadLimits>(), RobotError::limits);
  EXPECT_EQ(check_robot<BadFrame>(), RobotError::frame);
  EXPECT_EQ(check_robot<BadSizes>(), RobotError::sizes);
}

TEST(RobotContract, EveryErrorHasItsOwnDescription) {
  // Every enumerator, from none to the last one: a distinct text starting with its own name.
  const std::array<std::pair<RobotError, std::string_view>, 10> all = {{
      {RobotError::none, "none"},
      {RobotError::sizes, "sizes"},
      {RobotError::topology, "topology"},
      {RobotError::axis, "axis"},
      {RobotError::rotation, "rotation"},
      {RobotError::mass, "mass"},
      {RobotError::massless_subtree, "massless_subtree"},
      {RobotError::inertia, "inertia"},
      {RobotError::limits, "limits"},
      {RobotError::frame, "frame"},
  }};
  static_assert(int(RobotError::frame) == 9, "a new enumerator needs a line above");
  for (std::size_t i = 0; i < all.size(); ++i) {
    const std::string_view text = to_string(all[i].first);
    EXPECT_EQ(text.substr(0, all[i].second.size()), all[i].second) << text;
    if (i > 0) {
      EXPECT_EQ(text.substr(all[i].second.size(), 2), ": ") << text;
    }
    for (std::size_t j = 0; j < i; ++j)
      EXPECT_NE(text, std::string_view(to_string(all[j].first)));
  }
  static_assert(to_string(RobotError::none)[0] == 'n', "usable at compile time");
  EXPECT_EQ(std::string_view(to_string(RobotError(99))), "unknown RobotError");
}

TEST(RobotContract, Lookups) {
  EXPECT_EQ(joint_index<Good>("j1"), 1);
  EXPECT_EQ(joint_index<Good>("nope"), -1);
  EXPECT_EQ(body_index<Good>("b0"), 0);
  EXPECT_EQ(frame_index<Good>("b1"), 1);
  EXPECT_DOUBLE_EQ(total_mass<Good>(), 2.0);
}

TEST(JointKinds, Classification) {
  EXPECT_TRUE(is_revolute(JointKind::revolute_unaligned));
  EXPECT_TRUE(is_prismatic(JointKind::prismatic_x));
  EXPECT_FALSE(is_aligned(JointKind::prismatic_unaligned));
  EXPECT_EQ(axis_index(JointKind::revolute_y), 1);
  EXPECT_EQ(axis_index(JointKind::prismatic_z), 2);
  EXPECT_EQ(axis_index(JointKind::revolute_unaligned), -1);
}

}  // namespace
