// arbor-gen: mass distributions, the inertia policy for a link's <inertial> and the check that
// every joint moves inertia. No urdfdom here: MassProps in, MassProps or a GenError out.
#pragma once

#include <string>
#include <vector>

#include "generator.hpp"

namespace arbor::gen {

/// A principal moment below -(kRelInertiaTol * trace + kAbsInertiaTol) is an error, one above
/// it but negative is round-off; the same sum is the slack of the triangle inequality. 1e-6 of
/// the trace is far above double round-off of exported data (~1e-15) and below any physically
/// meant asymmetry; kAbsInertiaTol [kg m^2] keeps the test meaningful for tiny (sensor) links.
inline constexpr double kRelInertiaTol = 1e-6;
inline constexpr double kAbsInertiaTol = 1e-12;
/// Relative to the trace: the round-off of the Jacobi eigen-solver on a 3x3 tensor (a few ulps).
/// Eigenvalues this small are zeros and a negative one this small is not reported.
inline constexpr double kEigenRoundOff = 1e-14;
/// A revolute joint must move more inertia about its axis than this [kg m^2] (the floor of
/// kAbsInertiaTol): below it its row of the joint-space inertia matrix is zero to round-off.
inline constexpr double kMinAxialInertia = kAbsInertiaTol;

/// What to do with an inertia that is round-off negative or violates the triangle inequality.
enum class InertiaPolicy {
  warn,    ///< clamp round-off negatives, keep triangle violations; a warning each
  strict,  ///< --strict-inertia: either is an error
  fix,     ///< --fix-inertia: as warn, but a triangle violation is projected (a warning too)
};
InertiaPolicy inertia_policy(const Options& opt);

/// Sum of two mass distributions expressed in the same frame (parallel-axis theorem).
MassProps combine(const MassProps& a, const MassProps& b);

/// The nearest point (Euclidean) to the principal moments `l` in the cone of physically
/// consistent ones {l_a + l_b >= l_c for every permutation} (which implies l >= 0). With the
/// eigenvectors kept this gives the nearest consistent inertia in the Frobenius norm (the set
/// is spectral and convex).
Vec3 project_consistent(const Vec3& l);

/// A link's mass and rotational inertia (about its centre of mass) checked by the policy of
/// README, "The generator": a non-finite or negative mass, a non-finite inertia or a clearly
/// negative principal moment is a GenError; a round-off negative moment is clamped to zero and
/// a violated triangle inequality is kept, each with one warning appended to `warnings`
/// (errors with `strict`; with `fix` the inertia is replaced by the nearest consistent one).
/// `what` names the link in messages. The returned inertia is symmetric; com is unchanged.
MassProps apply_inertia_policy(const MassProps& link, InertiaPolicy policy, const std::string& what,
                               std::vector<std::string>& warnings);

/// Every body must move mass, and a revolute one must move inertia about its axis at q = 0
/// (otherwise its row of the joint-space inertia matrix is zero): GenError naming the first
/// joint (from the leaves up) that does not. O(bodies).
void check_moves_inertia(const RobotDesc& robot);

}  // namespace arbor::gen
