// The generator's inertia policy on plain mass/inertia values (no URDF, no urdfdom), against
// closed forms: consistent inertias pass untouched, round-off negative moments are clamped to
// exact zeros, triangle violations are kept, rejected or projected onto the nearest consistent
// inertia (hand-derived projections), and the tree check finds joints that move no inertia.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "inertia.hpp"
#include "math3.hpp"

namespace {

using namespace arbor::gen;

MassProps link(double mass, const Mat3& I) {
  MassProps p;
  p.mass = mass;
  p.I = I;
  return p;
}
Mat3 diag(double a, double b, double c) {
  return Mat3{{{a, 0, 0}, {0, b, 0}, {0, 0, c}}};
}
/// A rotation with no axis-aligned structure (30 deg about (1, 2, 2)/3).
Mat3 tilt() {
  return axis_angle(Vec3{1.0 / 3, 2.0 / 3, 2.0 / 3}, std::acos(-1.0) / 6);
}
void expect_near(const Mat3& a, const Mat3& b, double tol) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(a[i][j], b[i][j], tol) << i << "," << j;
}
/// The message of the GenError `f` throws, or "" if it throws none.
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const GenError& e) {
    return e.what();
  }
  return "";
}

constexpr InertiaPolicy kPolicies[] = {InertiaPolicy::warn, InertiaPolicy::strict,
                                       InertiaPolicy::fix};

TEST(InertiaPolicy, ConsistentInertiaPassesUntouchedUnderEveryPolicy) {
  // Solid box 0.2 x 0.4 x 0.6 m of 3 kg: I = m (b^2 + c^2) / 12, ...; rotated arbitrarily.
  const double m = 3, a = 0.2, b = 0.4, c = 0.6;
  const Mat3 box = rotate_tensor(
      tilt(), diag(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12));
  for (InertiaPolicy p : kPolicies) {
    std::vector<std::string> warnings;
    const MassProps out = apply_inertia_policy(link(m, box), p, "link 'box'", warnings);
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(out.mass, m);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        EXPECT_EQ(out.I[i][j], box[i][j]);
  }
}

TEST(InertiaPolicy, InvalidMassesAndInertiasAreErrors) {
  std::vector<std::string> w;
  EXPECT_EQ(error_of([&] { apply_inertia_policy(link(-2, diag(1, 1, 1)), {}, "link 'a'", w); }),
            "link 'a': negative mass -2 kg");
  EXPECT_EQ(error_of([&] { apply_inertia_policy(link(NAN, diag(1, 1, 1)), {}, "link 'a'", w); }),
            "link 'a': mass is not finite");
  EXPECT_EQ(
      error_of([&] { apply_inertia_policy(link(1, diag(1, INFINITY, 1)), {}, "link 'a'", w); }),
      "link 'a': inertia is not finite");
  // Moments 0.1, 0.2, -0.05: |trace| 0.35, far beyond round-off, under every policy.
  for (InertiaPolicy p : kPolicies)
    EXPECT_EQ(
        error_of([&] { apply_inertia_policy(link(1, diag(0.1, 0.2, -0.05)), p, "link 'a'", w); }),
        "link 'a': inertia has a negative principal moment -0.05 kg m^2 (trace 0.35): not a "
        "rotational inertia");
  EXPECT_TRUE(w.empty());
}

TEST(InertiaPolicy, RoundOffNegativeMomentIsClampedToAnExactZero) {
  // A thin rod along x (0.1 kg, 2.236 m: I = m l^2 / 12 = 0.0417) exported with ixx = -5e-20.
  const Mat3 rod = diag(-5e-20, 0.0417, 0.0417);
  for (InertiaPolicy p : {InertiaPolicy::warn, InertiaPolicy::fix}) {
    std::vector<std::string> warnings;
    const MassProps out = apply_inertia_policy(link(0.1, rod), p, "link 'rod'", warnings);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0],
              "link 'rod': inertia has a round-off negative principal moment -5e-20 kg m^2 "
              "(exporter's zero?): clamped to zero");
    const Mat3 expected = diag(0, 0.0417, 0.0417);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        EXPECT_EQ(out.I[i][j], expected[i][j]) << i << "," << j;
  }
  std::vector<std::string> w;
  EXPECT_EQ(error_of([&] {
              apply_inertia_policy(link(0.1, rod), InertiaPolicy::strict, "link 'rod'", w);
            }),
            "link 'rod': inertia has a round-off negative principal moment -5e-20 kg m^2 "
            "(exporter's zero?) [--strict-inertia]");
}

TEST(InertiaPolicy, TriangleInequalityHasTheRelativeSlackOfTheTolerance) {
  // Moments 1, 1, 2 + d: the slack is kRelInertiaTol * trace + kAbsInertiaTol = ~4e-6.
  std::vector<std::string> warnings;
  apply_inertia_policy(link(1, diag(1, 1, 2 + 1e-7)), {}, "link 'a'", warnings);
  EXPECT_TRUE(warnings.empty());
  apply_inertia_policy(link(1, diag(1, 1, 2 + 1e-5)), {}, "link 'a'", warnings);
  EXPECT_EQ(warnings.size(), 1u);
}

TEST(InertiaPolicy, TriangleViolationIsKeptRejectedOrProjected) {
  const Mat3 given = rotate_tensor(tilt(), diag(0.1, 0.1, 0.5));
  const std::string head =
      "link 'a': inertia violates the triangle inequality (principal moments 0.1, 0.1, 0.5 kg "
      "m^2): physically inconsistent";
  {
    std::vector<std::string> warnings;
    const MassProps out = apply_inertia_policy(link(1, given), {}, "link 'a'", warnings);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0],
              head + "; kept as given (--fix-inertia repairs it, --strict-inertia rejects it)");
    expect_near(out.I, given, 0);
  }
  {
    std::vector<std::string> w;
    EXPECT_EQ(error_of([&] {
                apply_inertia_policy(link(1, given), InertiaPolicy::strict, "link 'a'", w);
              }),
              head + " [--strict-inertia]");
  }
  {
    // (0.1, 0.1, 0.5) projected onto the face l0 + l1 = l2, normal (1, 1, -1)/sqrt(3):
    // (0.1, 0.1, 0.5) - (0.1 + 0.1 - 0.5)/3 (1, 1, -1) = (0.2, 0.2, 0.4); change 0.1 sqrt(3)
    // in the Frobenius norm, in the principal axes of the given inertia.
    std::vector<std::string> warnings;
    const MassProps out =
        apply_inertia_policy(link(1, given), InertiaPolicy::fix, "link 'a'", warnings);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0], head +
                               "; --fix-inertia: replaced by the nearest consistent inertia, "
                               "principal moments 0.2, 0.2, 0.4 kg m^2 (change 0.1732 kg m^2, "
                               "Frobenius)");
    expect_near(out.I, rotate_tensor(tilt(), diag(0.2, 0.2, 0.4)), 1e-15);
  }
}

TEST(InertiaPolicy, ProjectionOntoTheConsistentConeHasItsClosedForms) {
  auto expect = [](const Vec3& l, const Vec3& want) {
    const Vec3 got = project_consistent(l);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(got[i], want[i], 1e-15) << l[0] << " " << l[1] << " " << l[2] << " [" << i << "]";
  };
  expect({1, 2, 2.5}, {1, 2, 2.5});                // inside: unchanged
  expect({0.1, 0.1, 0.5}, {0.2, 0.2, 0.4});        // one face, symmetric
  expect({0, 1, 3}, {2.0 / 3, 5.0 / 3, 7.0 / 3});  // one face: l - (n.l / 3) n
  expect({0, 0, 3e-4}, {1e-4, 1e-4, 2e-4});        // inertia_singular.urdf's cover
  expect({3, 0, 0}, {2, 1, 1});                    // the largest moment first: l + (-1, 1, 1)
  expect({-1, -1, -1}, {0, 0, 0});                 // in the polar cone: the apex
  // Two faces active: l0 + l1 = l2 and l0 + l2 = l1 give l0 = 0, l1 = l2 = (l1 + l2) / 2.
  expect({-1, 1, 3}, {0, 2, 2});
}

TEST(InertiaCombine, ParallelAxisTheoremForTwoPointMasses) {
  MassProps a, b;
  a.mass = 1;
  a.com = {0.5, 0, 0};
  b.mass = 3;
  b.com = {-0.5, 0, 0};
  const MassProps c = combine(a, b);
  EXPECT_EQ(c.mass, 4);
  EXPECT_NEAR(c.com[0], -0.25, 1e-16);
  // About the common centre: 1 * 0.75^2 + 3 * 0.25^2 = 0.75 about y and z, 0 about x.
  expect_near(c.I, diag(0, 0.75, 0.75), 1e-16);
}

TEST(InertiaTreeCheck, EveryJointMustMoveInertiaAboutItsAxis) {
  RobotDesc robot;
  Body spin;
  spin.joint = "spin";
  spin.kind = Kind::RZ;
  spin.axis = {0, 0, 1};
  spin.inertia.mass = 2;
  spin.inertia.com = {0.1, 0, 0};  // 2 * 0.1^2 = 0.02 kg m^2 about z
  robot.bodies.push_back(spin);
  EXPECT_EQ(error_of([&] { check_moves_inertia(robot); }), "");
  robot.bodies[0].inertia.com = {0, 0, 0.3};  // a point mass on the axis
  EXPECT_NE(error_of([&] {
              check_moves_inertia(robot);
            }).find("joint 'spin' moves no inertia about its axis at q = 0"),
            std::string::npos);
  robot.bodies[0].kind = Kind::PZ;  // a slider moves it all the same
  EXPECT_EQ(error_of([&] { check_moves_inertia(robot); }), "");
  robot.bodies[0].inertia = MassProps{};
  EXPECT_NE(error_of([&] { check_moves_inertia(robot); }).find("joint 'spin' moves no mass"),
            std::string::npos);
}

}  // namespace
