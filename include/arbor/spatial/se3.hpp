// arbor: rigid placements (SE3) and their actions on motions and forces.
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/motion.hpp"

namespace arbor::spatial {

/// 3x3 skew-symmetric matrix [x] with [x] y = x cross y.
template <class Scalar>
ARBOR_INLINE Mat3<Scalar> skew(const Vec3<Scalar>& x) {
  Mat3<Scalar> K;
  K << Scalar(0), -x[2], x[1], x[2], Scalar(0), -x[0], -x[1], x[0], Scalar(0);
  return K;
}

/// Placement of a child frame in a parent frame: x_parent = R x_child + p (aMb in Pinocchio).
template <class Scalar>
struct SE3 {
  Mat3<Scalar> R;  ///< rotation; columns are the child axes in the parent frame
  Vec3<Scalar> p;  ///< child origin in the parent frame

  /// The identity placement.
  static SE3 Identity() { return {Mat3<Scalar>::Identity(), Vec3<Scalar>::Zero()}; }
  /// Composition aMc = aMb * bMc.
  SE3 operator*(const SE3& o) const { return {R * o.R, p + R * o.p}; }
  /// Inverse placement bMa.
  SE3 inverse() const { return {R.transpose(), -(R.transpose() * p)}; }
  /// Point in the parent frame from a point in the child frame.
  Vec3<Scalar> act(const Vec3<Scalar>& x) const { return R * x + p; }

  /// Motion expressed in the parent frame from the same motion in the child frame.
  Motion<Scalar> act(const Motion<Scalar>& m) const {
    const Vec3<Scalar> w = R * m.w;
    return {R * m.v + p.cross(w), w};
  }
  /// Motion expressed in the child frame from the same motion in the parent frame.
  Motion<Scalar> actInv(const Motion<Scalar>& m) const {
    return {R.transpose() * (m.v - p.cross(m.w)), R.transpose() * m.w};
  }
  /// Force expressed in the parent frame from the same force in the child frame.
  Force<Scalar> act(const Force<Scalar>& f) const {
    const Vec3<Scalar> fp = R * f.f;
    return {fp, R * f.n + p.cross(fp)};
  }
  /// Force expressed in the child frame from the same force in the parent frame.
  Force<Scalar> actInv(const Force<Scalar>& f) const {
    return {R.transpose() * f.f, R.transpose() * (f.n - p.cross(f.f))};
  }
  /// 6x6 motion transformation matrix (child -> parent), [v; w] ordering.
  Mat6<Scalar> toActionMatrix() const {
    Mat6<Scalar> X;
    X << R, skew(p) * R, Mat3<Scalar>::Zero(), R;
    return X;
  }
  /// 6x6 force transformation matrix (child -> parent), [f; n] ordering.
  Mat6<Scalar> toDualActionMatrix() const {
    Mat6<Scalar> X;
    X << R, Mat3<Scalar>::Zero(), skew(p) * R, R;
    return X;
  }
  /// Homogeneous 3x4 matrix [R | p].
  Eigen::Matrix<Scalar, 3, 4> matrix3x4() const {
    Eigen::Matrix<Scalar, 3, 4> M;
    M << R, p;
    return M;
  }
};

}  // namespace arbor::spatial
