// arbor: the plain constexpr data types that generated robot headers are made of.
#pragma once

#include <string_view>

namespace arbor::model {

/// A 3-vector of constexpr data (joint axes).
struct Vec3 {
  double v[3];  ///< components x, y, z
  /// Component i (0, 1, 2).
  constexpr double operator[](int i) const { return v[i]; }
};

/// Rigid placement of a child frame in its parent frame: x_parent = R * x_child + p.
struct Placement {
  double R[3][3];  ///< rotation, row-major; columns are the child axes in the parent frame
  double p[3];     ///< position of the child origin in the parent frame
};

/// Rigid-body inertia expressed in a body frame.
struct Inertia {
  double mass;     ///< mass [kg], >= 0
  double com[3];   ///< centre of mass in the body frame [m]
  double I[3][3];  ///< rotational inertia about the centre of mass, body-frame axes [kg m^2]
};

/// Limits of one degree of freedom; infinite where the URDF gives none.
struct Limits {
  double lower;     ///< lowest position [rad or m]; -inf for continuous joints
  double upper;     ///< highest position [rad or m]; +inf for continuous joints
  double velocity;  ///< largest |velocity| [rad/s or m/s]; +inf when unspecified
  double effort;    ///< largest |torque or force| [N m or N]; +inf when unspecified
};

/// An operational frame: one per URDF link, attached to a body (or to the fixed base, -1).
struct Frame {
  std::string_view name;  ///< the URDF link name, unchanged
  int body;               ///< index of the body it moves with; -1 for the fixed base
  Placement placement;    ///< placement of the frame in that body's frame
};

}  // namespace arbor::model
