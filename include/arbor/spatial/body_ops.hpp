// arbor: BodyOps<R, i, Scalar>, everything the recursions do with body i of robot R, specialised
// at compile time on the robot data. Each piece lives in its own header and adds to the one
// before it: the joint (JointMotion), its placement (BodyPlacement), the constant body inertia
// (BodyInertia) and articulated-inertia operations (ArticulatedOps); this header names the whole
// chain. The motion, force and subspace actions are written once on coordinate triples
// (spatial/coords.hpp): one call acts on a 3-vector, or on all columns of a block of columns.
#pragma once

#include "arbor/spatial/articulated_ops.hpp"

namespace arbor::spatial {

/// All compile-time facts and sparse spatial operations of body i of robot R.
template <class R, int i, class Scalar>
struct BodyOps : ArticulatedOps<R, i, Scalar> {};

}  // namespace arbor::spatial
