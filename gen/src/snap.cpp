// arbor-gen: axis alignment and --snap (see snap.hpp).
#include "snap.hpp"

#include <algorithm>
#include <cmath>

#include "math3.hpp"

namespace arbor::gen {

AxisAlignment nearest_axis(const Vec3& u) {
  AxisAlignment a;
  for (int i = 1; i < 3; ++i)
    if (std::abs(u[i]) > std::abs(u[a.axis]))
      a.axis = i;
  const int k = a.axis;
  const double side = std::hypot(u[(k + 1) % 3], u[(k + 2) % 3]);
  a.angle = std::atan2(side, std::abs(u[k]));
  a.sign = u[k] > 0 ? 1.0 : -1.0;
  return a;
}

bool nearest_aligned(const Mat3& R, Mat3& P) {
  P = Mat3{};
  std::array<bool, 3> used{};
  for (int i = 0; i < 3; ++i) {
    int c = 0;
    for (int j = 1; j < 3; ++j)
      if (std::abs(R[i][j]) > std::abs(R[i][c]))
        c = j;
    if (used[c])
      return false;
    used[c] = true;
    P[i][c] = R[i][c] > 0 ? 1.0 : -1.0;
  }
  const double det = P[0][0] * (P[1][1] * P[2][2] - P[1][2] * P[2][1]) -
                     P[0][1] * (P[1][0] * P[2][2] - P[1][2] * P[2][0]) +
                     P[0][2] * (P[1][0] * P[2][1] - P[1][1] * P[2][0]);
  return det > 0;
}

namespace {
/// The one --snap decision for a rotation or axis `angle` [rad] from aligned: true when it is
/// to be replaced by the aligned one; otherwise a misalignment is recorded (if not aligned).
bool snaps(double angle, double tol, RobotDesc& robot) {
  if (angle < kAxisAlignedTol)
    return false;
  if (tol > 0 && angle <= tol) {
    ++robot.snapped;
    robot.snap_max_angle = std::max(robot.snap_max_angle, angle);
    return true;
  }
  robot.misalignment.push_back(angle);
  return false;
}
}  // namespace

Mat3 snap_rotation(const Mat3& R, double tol, RobotDesc& robot) {
  Mat3 P;
  if (!nearest_aligned(R, P))
    return R;
  return snaps(rotation_distance(R, P), tol, robot) ? P : R;
}

Vec3 snap_axis(const Vec3& u, double tol, RobotDesc& robot) {
  const AxisAlignment a = nearest_axis(u);
  if (!snaps(a.angle, tol, robot))
    return u;
  Vec3 e{0, 0, 0};
  e[a.axis] = a.sign;
  return e;
}

namespace {
/// World placements at q = 0 of every frame of a built robot.
std::vector<Transform> world_frames(const RobotDesc& r) {
  std::vector<Transform> body(r.bodies.size());
  for (std::size_t i = 0; i < r.bodies.size(); ++i) {
    const int p = r.bodies[i].parent;
    body[i] = p < 0 ? r.bodies[i].placement : compose(body[std::size_t(p)], r.bodies[i].placement);
  }
  std::vector<Transform> out;
  for (const auto& f : r.frames)
    out.push_back(f.body < 0 ? f.placement : compose(body[std::size_t(f.body)], f.placement));
  return out;
}
}  // namespace

void snap_frame_change(RobotDesc& snapped, const RobotDesc& plain) {
  const auto a = world_frames(snapped), b = world_frames(plain);
  if (a.size() != b.size())
    return;
  for (std::size_t i = 0; i < a.size(); ++i) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k)
      d2 += (a[i].p[k] - b[i].p[k]) * (a[i].p[k] - b[i].p[k]);
    snapped.snap_max_position = std::max(snapped.snap_max_position, std::sqrt(d2));
    snapped.snap_max_rotation =
        std::max(snapped.snap_max_rotation, rotation_distance(a[i].R, b[i].R));
  }
}

}  // namespace arbor::gen
