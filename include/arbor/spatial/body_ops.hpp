// arbor: BodyOps<R, i, Scalar>, everything the recursions do with body i of robot R, specialised
// at compile time on the robot data. Each piece lives in its own header and adds to the one
// before it: the joint (JointMotion), its placement (BodyPlacement), the constant body inertia
// (BodyInertia), articulated-inertia operations (ArticulatedOps) and column-block actions
// (ColumnOps); this header names the whole chain.
#pragma once

#include "arbor/spatial/articulated_ops.hpp"
#include "arbor/spatial/column_ops.hpp"

namespace arbor::spatial {

/// All compile-time facts and sparse spatial operations of body i of robot R.
template <class R, int i, class Scalar>
struct BodyOps : ColumnOps<R, i, Scalar> {};

}  // namespace arbor::spatial
