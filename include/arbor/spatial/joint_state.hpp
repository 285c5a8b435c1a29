// arbor: the state of one joint, computed once per configuration and shared by every action of
// the joint (one sincos per revolute joint, nothing for prismatic joints).
#pragma once

namespace arbor::spatial {

/// Joint state of one body: the trigonometric values of its angle (revolute) or its signed
/// displacement (prismatic). For aligned kinds the axis sign is folded in: s = sign * sin(q),
/// d = sign * q, so the joint always turns/slides about/along +e_k.
template <class Scalar>
struct JointState {
  Scalar c;  ///< cos(q) (revolute)
  Scalar s;  ///< sign * sin(q) (revolute; plain sin(q) for unaligned axes)
  Scalar d;  ///< sign * q (prismatic; plain q for unaligned axes)
};

}  // namespace arbor::spatial
