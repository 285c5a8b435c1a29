// arbor: joint kinds known at compile time.
#pragma once

#include <cstdint>

namespace arbor::model {

/// Kind of the joint that connects a body to its parent. Every kind has one degree of freedom.
/// Aligned kinds move about/along a coordinate axis of the joint frame, with the sign stored in
/// the robot's `joint_axis` (e.g. RevoluteX with axis (-1, 0, 0) turns about -X). Unaligned kinds
/// use the general unit axis stored in `joint_axis`. Continuous joints are revolute joints with
/// infinite position limits (one angle per DoF, never cos/sin pairs).
enum class JointKind : std::uint8_t {
  RevoluteX,
  RevoluteY,
  RevoluteZ,
  RevoluteUnaligned,
  PrismaticX,
  PrismaticY,
  PrismaticZ,
  PrismaticUnaligned,
};

/// True for the four revolute kinds.
constexpr bool is_revolute(JointKind k) {
  return k == JointKind::RevoluteX || k == JointKind::RevoluteY || k == JointKind::RevoluteZ ||
         k == JointKind::RevoluteUnaligned;
}

/// True for the four prismatic kinds.
constexpr bool is_prismatic(JointKind k) {
  return !is_revolute(k);
}

/// True when the axis is a signed coordinate axis of the joint frame.
constexpr bool is_aligned(JointKind k) {
  return k != JointKind::RevoluteUnaligned && k != JointKind::PrismaticUnaligned;
}

/// Index (0, 1, 2) of the coordinate axis of an aligned kind; -1 for unaligned kinds.
constexpr int axis_index(JointKind k) {
  switch (k) {
    case JointKind::RevoluteX:
    case JointKind::PrismaticX:
      return 0;
    case JointKind::RevoluteY:
    case JointKind::PrismaticY:
      return 1;
    case JointKind::RevoluteZ:
    case JointKind::PrismaticZ:
      return 2;
    default:
      return -1;
  }
}

/// Short human-readable name of a joint kind ("RZ", "PX", "R*" for unaligned revolute...).
constexpr const char* short_name(JointKind k) {
  switch (k) {
    case JointKind::RevoluteX:
      return "RX";
    case JointKind::RevoluteY:
      return "RY";
    case JointKind::RevoluteZ:
      return "RZ";
    case JointKind::RevoluteUnaligned:
      return "R*";
    case JointKind::PrismaticX:
      return "PX";
    case JointKind::PrismaticY:
      return "PY";
    case JointKind::PrismaticZ:
      return "PZ";
    case JointKind::PrismaticUnaligned:
      return "P*";
  }
  return "?";
}

}  // namespace arbor::model
