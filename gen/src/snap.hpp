// arbor-gen: axis alignment of joint rotations and axes, --snap, and what snapping moved. No
// urdfdom here; each call is O(1) except snap_frame_change (O(frames)).
#pragma once

#include "generator.hpp"

namespace arbor::gen {

/// A joint rotation or axis within this angle [rad] of axis-aligned is aligned: it is neither
/// reported as misaligned nor changed by --snap, and an axis this close gets an axis-aligned
/// joint kind (written exactly). 1e-13 is ~1000x the round-off of building a unit vector or a
/// rotation from URDF text (~1e-16 per entry) and far below any angle an exporter rounds to
/// (6 significant digits leave ~1e-6 rad).
inline constexpr double kAxisAlignedTol = 1e-13;

/// The coordinate axis nearest to a unit vector and the angle to it.
struct AxisAlignment {
  int axis = 0;      ///< 0, 1, 2 for x, y, z
  double sign = 1;   ///< direction along that axis
  double angle = 0;  ///< [rad]
};
AxisAlignment nearest_axis(const Vec3& u);

/// Nearest signed permutation matrix (axis-aligned rotation) to R; false if R is not near one.
bool nearest_aligned(const Mat3& R, Mat3& P);

/// A joint origin rotation with --snap `tol` applied (0 = off): made exact when its angle to
/// the nearest aligned rotation is in [kAxisAlignedTol, tol], else recorded in
/// robot.misalignment when not aligned. Updates robot.snapped and robot.snap_max_angle.
Mat3 snap_rotation(const Mat3& R, double tol, RobotDesc& robot);
/// The same for a unit joint axis.
Vec3 snap_axis(const Vec3& u, double tol, RobotDesc& robot);

/// What --snap changed: the largest change of a frame's world position and orientation at
/// q = 0 between `snapped` and `plain` (the same robot built without --snap), stored in
/// snapped.snap_max_position and snapped.snap_max_rotation.
void snap_frame_change(RobotDesc& snapped, const RobotDesc& plain);

}  // namespace arbor::gen
