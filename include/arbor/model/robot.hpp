// arbor: the contract that a generated robot type satisfies.
//
// A robot is a type (never an object) whose static constexpr members describe a fixed-base
// kinematic tree of nb bodies, each attached to its parent by a one-DoF joint:
//
//   name                 std::string_view: the URDF robot name
//   nq, nv, nb, nf       int: configuration size, velocity size, bodies, operational frames
//   parent[nb]           int: parent body of each body, -1 for the fixed base; parent[i] < i
//   joint_kind[nb]       JointKind of the joint that moves each body
//   joint_axis[nb]       Vec3: unit axis in the joint frame (a signed coordinate axis when aligned)
//   joint_placement[nb]  Placement of the joint frame in the parent body frame at q = 0
//   body_inertia[nb]     Inertia of each body (fixed-joint children lumped in), in its frame
//   base_inertia         Inertia lumped into the fixed base (it does not move; kept for totals)
//   limits[nv]           Limits of each DoF
//   joint_names[nb], body_names[nb]   std::string_view: URDF joint and child-link names
//   frames[nf]           Frame: one per URDF link kept, with its body and placement
//   joint_id, frame_id   nested structs of `static constexpr int` indices by sanitized name
//
// The body frame of body i is its joint frame; configuration q[i] moves joint i (nq == nv == nb).
#pragma once

#include <array>
#include <concepts>
#include <cstddef>
#include <string_view>

#include "arbor/model/joint.hpp"
#include "arbor/model/types.hpp"

namespace arbor::model {

namespace detail {

template <class T, class E>
concept ArrayOf = requires(const T& a) {
  { a[0] } -> std::convertible_to<const E&>;
  { a.size() } -> std::convertible_to<std::size_t>;
};

constexpr double abs(double x) {
  return x < 0 ? -x : x;
}
constexpr bool finite(double x) {
  return x == x && x - x == 0.0;
}

}  // namespace detail

/// The syntactic part of the contract: the members exist with the right types.
template <class R>
concept RobotModel = requires {
  { R::name } -> std::convertible_to<std::string_view>;
  { R::nq } -> std::convertible_to<int>;
  { R::nv } -> std::convertible_to<int>;
  { R::nb } -> std::convertible_to<int>;
  { R::nf } -> std::convertible_to<int>;
  { R::base_inertia } -> std::convertible_to<const Inertia&>;
  requires detail::ArrayOf<decltype(R::parent), int>;
  requires detail::ArrayOf<decltype(R::joint_kind), JointKind>;
  requires detail::ArrayOf<decltype(R::joint_axis), Vec3>;
  requires detail::ArrayOf<decltype(R::joint_placement), Placement>;
  requires detail::ArrayOf<decltype(R::body_inertia), Inertia>;
  requires detail::ArrayOf<decltype(R::limits), Limits>;
  requires detail::ArrayOf<decltype(R::joint_names), std::string_view>;
  requires detail::ArrayOf<decltype(R::body_names), std::string_view>;
  requires detail::ArrayOf<decltype(R::frames), Frame>;
  requires R::parent.size() == std::size_t(R::nb);
  requires R::limits.size() == std::size_t(R::nv);
  requires R::frames.size() == std::size_t(R::nf);
};

/// Problems a robot's data can have; checked at compile time by `check_robot`.
enum class RobotError {
  none,
  sizes,             ///< nq, nv, nb disagree, or nb < 1
  topology,          ///< parent[i] is not in [-1, i)
  axis,              ///< joint axis is not a unit vector, or an aligned kind with another axis
  rotation,          ///< a placement's rotation is not orthonormal with determinant +1
  mass,              ///< a mass is negative or non-finite, or a centre of mass is non-finite
  massless_subtree,  ///< a DoF moves no mass at all: the mass matrix would be singular
  inertia,           ///< a rotational inertia is not symmetric positive semi-definite
  limits,            ///< lower > upper, or a negative velocity/effort limit
  frame,             ///< a frame refers to a body that does not exist
};

/// A short description of each error, for messages and logs (no iostream needed).
constexpr const char* to_string(RobotError e) {
  switch (e) {
    case RobotError::none:
      return "none";
    case RobotError::sizes:
      return "sizes: need nq == nv == nb >= 1";
    case RobotError::topology:
      return "topology: parent[i] must be in [-1, i)";
    case RobotError::axis:
      return "axis: joint axes must be unit vectors (signed coordinate axes for aligned kinds)";
    case RobotError::rotation:
      return "rotation: a placement rotation is not proper (orthonormal, determinant +1)";
    case RobotError::mass:
      return "mass: a mass is negative or non-finite, or a centre of mass is non-finite";
    case RobotError::massless_subtree:
      return "massless_subtree: a DoF moves no mass (singular mass matrix)";
    case RobotError::inertia:
      return "inertia: a rotational inertia is not symmetric positive semi-definite";
    case RobotError::limits:
      return "limits: lower > upper, or a negative velocity or effort limit";
    case RobotError::frame:
      return "frame: a frame refers to a body that does not exist";
  }
  return "unknown RobotError";
}

namespace detail {

constexpr bool rotation_ok(const Placement& X) {
  for (int i = 0; i < 3; ++i) {
    if (!finite(X.p[i]))
      return false;
    for (int j = 0; j < 3; ++j) {
      double d = 0;
      for (int k = 0; k < 3; ++k)
        d += X.R[k][i] * X.R[k][j];
      if (abs(d - (i == j ? 1.0 : 0.0)) > 1e-9)
        return false;
    }
  }
  const auto& R = X.R;
  const double det = R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) -
                     R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0]) +
                     R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]);
  return abs(det - 1.0) < 1e-9;
}

constexpr bool inertia_ok(const Inertia& Y) {
  if (!finite(Y.mass) || Y.mass < 0)
    return false;
  for (int i = 0; i < 3; ++i) {
    if (!finite(Y.com[i]))
      return false;
    for (int j = 0; j < 3; ++j)
      if (!finite(Y.I[i][j]))
        return false;
  }
  return true;
}

constexpr bool inertia_psd(const Inertia& Y) {
  const auto& I = Y.I;
  const double scale = abs(I[0][0]) + abs(I[1][1]) + abs(I[2][2]) + 1e-300;
  const double tol = 1e-9 * scale;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (abs(I[i][j] - I[j][i]) > tol)
        return false;
  // Sylvester-style check with tolerance: diagonal, 2x2 minors and determinant non-negative.
  if (I[0][0] < -tol || I[1][1] < -tol || I[2][2] < -tol)
    return false;
  const double m01 = I[0][0] * I[1][1] - I[0][1] * I[0][1];
  const double m02 = I[0][0] * I[2][2] - I[0][2] * I[0][2];
  const double m12 = I[1][1] * I[2][2] - I[1][2] * I[1][2];
  const double tol2 = tol * scale;
  if (m01 < -tol2 || m02 < -tol2 || m12 < -tol2)
    return false;
  const double det = I[0][0] * m12 - I[0][1] * (I[0][1] * I[2][2] - I[1][2] * I[0][2]) +
                     I[0][2] * (I[0][1] * I[1][2] - I[1][1] * I[0][2]);
  return det >= -tol2 * scale;
}

}  // namespace detail

/// Checks the invariants of a robot's data; `RobotError::none` when all hold.
template <RobotModel R>
constexpr RobotError check_robot() {
  using detail::abs;
  if (R::nb < 1 || R::nq != R::nb || R::nv != R::nb)
    return RobotError::sizes;
  for (int i = 0; i < R::nb; ++i)
    if (R::parent[i] < -1 || R::parent[i] >= i)
      return RobotError::topology;
  for (int i = 0; i < R::nb; ++i) {
    const Vec3& a = R::joint_axis[i];
    const double n2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    if (abs(n2 - 1.0) > 1e-12)
      return RobotError::axis;
    const int k = axis_index(R::joint_kind[i]);
    if (k >= 0) {
      for (int j = 0; j < 3; ++j)
        if (j != k && a[j] != 0.0)
          return RobotError::axis;
      if (a[k] != 1.0 && a[k] != -1.0)
        return RobotError::axis;
    }
    if (!detail::rotation_ok(R::joint_placement[i]))
      return RobotError::rotation;
  }
  if (!detail::inertia_ok(R::base_inertia))
    return RobotError::mass;
  for (int i = 0; i < R::nb; ++i) {
    if (!detail::inertia_ok(R::body_inertia[i]))
      return RobotError::mass;
    if (!detail::inertia_psd(R::body_inertia[i]))
      return RobotError::inertia;
  }
  // Subtree masses: children come after parents, so accumulate backwards.
  std::array<double, std::size_t(R::nb)> subtree{};
  for (int i = R::nb - 1; i >= 0; --i) {
    subtree[i] += R::body_inertia[i].mass;
    if (!(subtree[i] > 0))
      return RobotError::massless_subtree;
    if (R::parent[i] >= 0)
      subtree[R::parent[i]] += subtree[i];
  }
  for (int i = 0; i < R::nv; ++i) {
    const Limits& l = R::limits[i];
    if (l.lower > l.upper || l.velocity < 0 || l.effort < 0)
      return RobotError::limits;
  }
  for (int f = 0; f < R::nf; ++f) {
    if (R::frames[f].body < -1 || R::frames[f].body >= R::nb)
      return RobotError::frame;
    if (!detail::rotation_ok(R::frames[f].placement))
      return RobotError::rotation;
  }
  return RobotError::none;
}

/// The full contract: the members exist and every invariant holds. Algorithms take
/// `template <Robot R>`; `static_assert(check_robot<R>() == RobotError::none)` names the problem.
template <class R>
concept Robot = RobotModel<R> &&(check_robot<R>() == RobotError::none);

/// Compile-time validation with one message per kind of problem; use as
/// `static_assert(arbor::model::validate<MyRobot>())`. Generated headers end with it.
template <RobotModel R>
consteval bool validate() {
  constexpr RobotError e = check_robot<R>();
  static_assert(e != RobotError::sizes, "arbor robot: need nq == nv == nb >= 1");
  static_assert(e != RobotError::topology, "arbor robot: parent[i] must be in [-1, i)");
  static_assert(e != RobotError::axis, "arbor robot: joint axes must be unit (signed) axes");
  static_assert(e != RobotError::rotation, "arbor robot: a placement rotation is not proper");
  static_assert(e != RobotError::mass, "arbor robot: negative or non-finite mass or com");
  static_assert(e != RobotError::massless_subtree,
                "arbor robot: a DoF moves no mass (singular mass matrix); lock it");
  static_assert(e != RobotError::inertia, "arbor robot: rotational inertia is not PSD");
  static_assert(e != RobotError::limits, "arbor robot: inconsistent joint limits");
  static_assert(e != RobotError::frame, "arbor robot: a frame refers to a missing body");
  return e == RobotError::none;
}

/// Total mass of the robot, fixed base included [kg].
template <RobotModel R>
constexpr double total_mass() {
  double m = R::base_inertia.mass;
  for (int i = 0; i < R::nb; ++i)
    m += R::body_inertia[i].mass;
  return m;
}

/// Index of the body whose URDF child link is `name`, or -1.
template <RobotModel R>
constexpr int body_index(std::string_view name) {
  for (int i = 0; i < R::nb; ++i)
    if (R::body_names[i] == name)
      return i;
  return -1;
}

/// Index of the joint named `name` (equal to its body index and its DoF index), or -1.
template <RobotModel R>
constexpr int joint_index(std::string_view name) {
  for (int i = 0; i < R::nb; ++i)
    if (R::joint_names[i] == name)
      return i;
  return -1;
}

/// Index of the operational frame of URDF link `name`, or -1.
template <RobotModel R>
constexpr int frame_index(std::string_view name) {
  for (int i = 0; i < R::nf; ++i)
    if (R::frames[i].name == name)
      return i;
  return -1;
}

}  // namespace arbor::model

namespace arbor {
using model::Robot;
}  // namespace arbor
