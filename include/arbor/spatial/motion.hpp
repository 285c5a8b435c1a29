// arbor: spatial motion and force vectors (Plucker coordinates, linear part first as in
// Pinocchio) and their cross products.
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::spatial {

/// Spatial motion vector (twist or spatial acceleration) at the origin of some frame.
template <class Scalar>
struct Motion {
  Vec3<Scalar> v;  ///< linear part (velocity of the point at the frame origin)
  Vec3<Scalar> w;  ///< angular part

  /// The zero motion.
  static Motion Zero() { return {Vec3<Scalar>::Zero(), Vec3<Scalar>::Zero()}; }
  /// Stacked 6-vector [v; w].
  Vec6<Scalar> vector() const {
    Vec6<Scalar> x;
    x << v, w;
    return x;
  }
  /// From a stacked 6-vector [v; w].
  template <class D>
  static Motion from(const Eigen::MatrixBase<D>& x) {
    return {x.template head<3>(), x.template tail<3>()};
  }
  Motion operator+(const Motion& o) const { return {v + o.v, w + o.w}; }
  Motion operator-(const Motion& o) const { return {v - o.v, w - o.w}; }
  Motion operator-() const { return {-v, -w}; }
  Motion& operator+=(const Motion& o) {
    v += o.v;
    w += o.w;
    return *this;
  }
  Motion& operator-=(const Motion& o) {
    v -= o.v;
    w -= o.w;
    return *this;
  }
  Motion operator*(const Scalar& k) const { return {v * k, w * k}; }
};

/// Spatial force vector (wrench) at the origin of some frame.
template <class Scalar>
struct Force {
  Vec3<Scalar> f;  ///< linear part (force)
  Vec3<Scalar> n;  ///< angular part (moment about the frame origin)

  /// The zero force.
  static Force Zero() { return {Vec3<Scalar>::Zero(), Vec3<Scalar>::Zero()}; }
  /// Stacked 6-vector [f; n].
  Vec6<Scalar> vector() const {
    Vec6<Scalar> x;
    x << f, n;
    return x;
  }
  /// From a stacked 6-vector [f; n].
  template <class D>
  static Force from(const Eigen::MatrixBase<D>& x) {
    return {x.template head<3>(), x.template tail<3>()};
  }
  Force operator+(const Force& o) const { return {f + o.f, n + o.n}; }
  Force operator-(const Force& o) const { return {f - o.f, n - o.n}; }
  Force operator-() const { return {-f, -n}; }
  Force& operator+=(const Force& o) {
    f += o.f;
    n += o.n;
    return *this;
  }
  Force& operator-=(const Force& o) {
    f -= o.f;
    n -= o.n;
    return *this;
  }
  Force operator*(const Scalar& k) const { return {f * k, n * k}; }
};

/// Motion cross product m1 x m2 = [w1 x v2 + v1 x w2; w1 x w2].
template <class Scalar>
ARBOR_INLINE Motion<Scalar> cross(const Motion<Scalar>& m1, const Motion<Scalar>& m2) {
  return {m1.w.cross(m2.v) + m1.v.cross(m2.w), m1.w.cross(m2.w)};
}

/// Force cross product m x* f = [w x f; w x n + v x f].
template <class Scalar>
ARBOR_INLINE Force<Scalar> cross(const Motion<Scalar>& m, const Force<Scalar>& f) {
  return {m.w.cross(f.f), m.w.cross(f.n) + m.v.cross(f.f)};
}

/// Power (duality pairing) <f, m> = f . v + n . w.
template <class Scalar>
ARBOR_INLINE Scalar dot(const Force<Scalar>& f, const Motion<Scalar>& m) {
  return f.f.dot(m.v) + f.n.dot(m.w);
}

/// 6x6 matrix of the motion cross product operator m x (acting on motions).
template <class Scalar>
Mat6<Scalar> motion_cross_matrix(const Motion<Scalar>& m) {
  auto skew = [](const Vec3<Scalar>& x) {
    Mat3<Scalar> K;
    K << Scalar(0), -x[2], x[1], x[2], Scalar(0), -x[0], -x[1], x[0], Scalar(0);
    return K;
  };
  Mat6<Scalar> X;
  X << skew(m.w), skew(m.v), Mat3<Scalar>::Zero(), skew(m.w);
  return X;
}

}  // namespace arbor::spatial
