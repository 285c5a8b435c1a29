// arbor: rigid-body spatial inertia, stored as (mass, first moment h = m c, rotational inertia
// about the frame origin) so that sums of inertias (composite bodies) stay exact and cheap.
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/motion.hpp"
#include "arbor/spatial/se3.hpp"

namespace arbor::spatial {

/// Spatial inertia of a rigid body (or a composite of rigid bodies) in some frame.
template <class Scalar>
struct Inertia {
  Scalar m;         ///< mass
  Vec3<Scalar> h;   ///< first moment of mass m * c (c: centre of mass)
  Mat3<Scalar> Io;  ///< rotational inertia about the frame origin (not about the centre of mass)

  /// The zero inertia.
  static Inertia Zero() { return {Scalar(0), Vec3<Scalar>::Zero(), Mat3<Scalar>::Zero()}; }
  /// From mass, centre of mass and rotational inertia about the centre of mass.
  static Inertia FromMassComInertia(const Scalar& mass, const Vec3<Scalar>& com,
                                    const Mat3<Scalar>& Ic) {
    const Mat3<Scalar> C = skew(com);
    return {mass, com * mass, Ic - mass * (C * C)};
  }
  /// Centre of mass (undefined for zero mass).
  Vec3<Scalar> com() const { return h / m; }
  Inertia operator+(const Inertia& o) const { return {m + o.m, h + o.h, Io + o.Io}; }
  Inertia& operator+=(const Inertia& o) {
    m += o.m;
    h += o.h;
    Io += o.Io;
    return *this;
  }
  /// Momentum I * v = [m v - h x w; Io w + h x v].
  Force<Scalar> operator*(const Motion<Scalar>& x) const {
    return {x.v * m - h.cross(x.w), Io * x.w + h.cross(x.v)};
  }
  /// 6x6 matrix in [v; w] -> [f; n] ordering.
  Mat6<Scalar> matrix() const {
    Mat6<Scalar> M;
    const Mat3<Scalar> H = skew(h);
    M << Mat3<Scalar>::Identity() * m, -H, H, Io;
    return M;
  }
  /// The same inertia expressed in the parent frame of placement X (X = parentMthis).
  Inertia se3Action(const SE3<Scalar>& X) const {
    const Vec3<Scalar> hr = X.R * h;
    const Mat3<Scalar> P = skew(X.p);
    const Mat3<Scalar> Hr = skew(hr);
    return {m, hr + X.p * m, X.R * Io * X.R.transpose() - (Hr * P + P * Hr) - m * (P * P)};
  }
};

/// Time derivative of a (composite) rigid-body inertia whose bodies move with velocities v_i:
/// sum_i (v_i x* I_i - I_i v_i x). The mass is constant, so it has the shape of a rigid inertia
/// with zero mass: [0, -[hd]; [hd], Iod] in [v; w] -> [f; n] ordering, Iod symmetric.
template <class Scalar>
struct InertiaRate {
  Vec3<Scalar> hd;   ///< rate of the first moment of mass
  Mat3<Scalar> Iod;  ///< rate of the rotational inertia about the frame origin (symmetric)

  static InertiaRate Zero() { return {Vec3<Scalar>::Zero(), Mat3<Scalar>::Zero()}; }
  InertiaRate& operator+=(const InertiaRate& o) {
    hd += o.hd;
    Iod += o.Iod;
    return *this;
  }
  /// The rate times a motion: [-hd x w; Iod w + hd x v].
  Force<Scalar> operator*(const Motion<Scalar>& x) const {
    return {-hd.cross(x.w), Iod * x.w + hd.cross(x.v)};
  }
  /// The 6x6 matrix.
  Mat6<Scalar> matrix() const {
    Mat6<Scalar> M;
    const Mat3<Scalar> H = skew(hd);
    M << Mat3<Scalar>::Zero(), -H, H, Iod;
    return M;
  }
};

}  // namespace arbor::spatial
