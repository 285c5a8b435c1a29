// arbor: joint kinds known at compile time.
#pragma once

#include <cstdint>

namespace arbor::model {

/// Kind of the joint that connects a body to its parent. Every kind has one degree of freedom.
/// Aligned kinds move about/along a coordinate axis of the joint frame, with the sign stored in
/// the robot's `joint_axis` (e.g. revolute_x with axis (-1, 0, 0) turns about -X). Unaligned kinds
/// use the general unit axis stored in `joint_axis`. Continuous joints are revolute joints with
/// infinite position limits (one angle per DoF, never cos/sin pairs).
enum class JointKind : std::uint8_t {
  revolute_x,
  revolute_y,
  revolute_z,
  revolute_unaligned,
  prismatic_x,
  prismatic_y,
  prismatic_z,
  prismatic_unaligned,
};

/// True for the four revolute kinds.
constexpr bool is_revolute(JointKind k) {
  return k == JointKind::revolute_x || k == JointKind::revolute_y || k == JointKind::revolute_z ||
         k == JointKind::revolute_unaligned;
}

/// True for the four prismatic kinds.
constexpr bool is_prismatic(JointKind k) {
  return !is_revolute(k);
}

/// True when the axis is a signed coordinate axis of the joint frame.
constexpr bool is_aligned(JointKind k) {
  return k != JointKind::revolute_unaligned && k != JointKind::prismatic_unaligned;
}

/// Index (0, 1, 2) of the coordinate axis of an aligned kind; -1 for unaligned kinds.
constexpr int axis_index(JointKind k) {
  switch (k) {
    case JointKind::revolute_x:
    case JointKind::prismatic_x:
      return 0;
    case JointKind::revolute_y:
    case JointKind::prismatic_y:
      return 1;
    case JointKind::revolute_z:
    case JointKind::prismatic_z:
      return 2;
    default:
      return -1;
  }
}

/// Short human-readable name of a joint kind ("RZ", "PX", "R*" for unaligned revolute...).
constexpr const char* short_name(JointKind k) {
  switch (k) {
    case JointKind::revolute_x:
      return "RX";
    case JointKind::revolute_y:
      return "RY";
    case JointKind::revolute_z:
      return "RZ";
    case JointKind::revolute_unaligned:
      return "R*";
    case JointKind::prismatic_x:
      return "PX";
    case JointKind::prismatic_y:
      return "PY";
    case JointKind::prismatic_z:
      return "PZ";
    case JointKind::prismatic_unaligned:
      return "P*";
  }
  return "?";
}

}  // namespace arbor::model
