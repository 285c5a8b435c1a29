// arbor: articulated-body inertia operations of body i (ABA and M^-1): the constant body inertia
// as an articulated inertia, U = Ya S, and the projection Ya - U Dinv U^T carried to the parent.
// For joints about a coordinate axis the projection has a structurally zero row and column,
// which the transport skips.
#pragma once

#include "arbor/spatial/articulated_inertia.hpp"
#include "arbor/spatial/body_inertia.hpp"

namespace arbor::spatial {

/// Articulated-inertia actions of body i of robot R.
template <class R, int i, class Scalar>
struct ArticulatedOps : BodyInertia<R, i, Scalar> {
  using Base = BodyInertia<R, i, Scalar>;
  using Base::aligned;
  using Base::ia;
  using Base::ib;
  using Base::jtrans;
  using Base::k;
  using Base::p_zero;
  using Base::revolute;
  using Base::rot_const;
  using Base::rot_const_sym;
  using Base::rot_mat;
  using Base::rot_sym;
  using Base::sign;
  using Base::Y;
  using typename Base::AxisV;
  using typename Base::Vp;

  /// The constant body inertia as an articulated inertia.
  ARBOR_INLINE static ArticulatedInertia<Scalar> art_inertia() {
    ArticulatedInertia<Scalar> Ya;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        Ya.A(r, c) = r == c ? Scalar(Y.m) : Scalar(0);
        Ya.C(r, c) = Scalar(Y.Io[r][c]);
      }
    // B = -[h]
    Ya.B(0, 0) = Scalar(0);
    Ya.B(1, 1) = Scalar(0);
    Ya.B(2, 2) = Scalar(0);
    Ya.B(0, 1) = Scalar(Y.h[2]);
    Ya.B(0, 2) = Scalar(-Y.h[1]);
    Ya.B(1, 0) = Scalar(-Y.h[2]);
    Ya.B(1, 2) = Scalar(Y.h[0]);
    Ya.B(2, 0) = Scalar(Y.h[1]);
    Ya.B(2, 1) = Scalar(-Y.h[0]);
    return Ya;
  }
  /// U = Ya S as [uf; un].
  ARBOR_INLINE static void art_S(const ArticulatedInertia<Scalar>& Ya, Vec3<Scalar>& uf,
                                 Vec3<Scalar>& un) {
    if constexpr (aligned) {
      if constexpr (revolute) {
        uf = Ya.B.col(k);
        un = Ya.C.col(k);
      } else {
        uf = Ya.A.col(k);
        un = Ya.B.row(k).transpose();
      }
      if constexpr (sign < 0) {
        uf = -uf;
        un = -un;
      }
    } else {
      const Vec3<Scalar> a(Scalar(AxisV::at(0)), Scalar(AxisV::at(1)), Scalar(AxisV::at(2)));
      if constexpr (revolute) {
        uf = Ya.B * a;
        un = Ya.C * a;
      } else {
        uf = Ya.A * a;
        un = Ya.B.transpose() * a;
      }
    }
  }
  /// Articulated inertia in body i's frame -> parent frame.
  ARBOR_INLINE static ArticulatedInertia<Scalar> art_to_parent(
      const JointState<Scalar>& js, const ArticulatedInertia<Scalar>& Yc) {
    Mat3<Scalar> A, B, C;
    if constexpr (revolute) {
      A = rot_sym(js, Yc.A);
      B = rot_mat(js, Yc.B);
      C = rot_sym(js, Yc.C);
    } else {
      const Mat3<Scalar> Pd = skew(jtrans(js));
      const Mat3<Scalar> AP = Yc.A * Pd;
      const Mat3<Scalar> PB = Pd * Yc.B;
      A = Yc.A;
      B = Yc.B - AP;
      C = Yc.C + PB + PB.transpose() - Pd * AP;
    }
    return const_placement_art({A, B, C});
  }

  /// Projected articulated inertia Y - U Dinv U^T (U = Y S), the part of body i's articulated
  /// inertia that its parent sees, expressed in the parent frame. For aligned revolute joints
  /// the projection has an exactly zero row and column for the joint axis (Y_a S = 0), which is
  /// set structurally and skipped by the joint rotation.
  ARBOR_INLINE static ArticulatedInertia<Scalar> art_project_to_parent(
      const JointState<Scalar>& js, const ArticulatedInertia<Scalar>& Yi, const Force<Scalar>& U,
      const Scalar& Dinv) {
    if constexpr (revolute && aligned) {
      constexpr int a = ia, b = ib;
      const Vec3<Scalar> gf = U.f * Dinv;
      const Scalar gna = U.n[a] * Dinv, gnb = U.n[b] * Dinv;
      // rank-one update, skipping the zero row/column k of C and column k of B
      Mat3<Scalar> A;
      for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c)
          A(r, c) = Yi.A(r, c) - gf[r] * U.f[c];
      A(1, 0) = A(0, 1);
      A(2, 0) = A(0, 2);
      A(2, 1) = A(1, 2);
      Vec3<Scalar> Ba, Bb;
      for (int r = 0; r < 3; ++r) {
        Ba[r] = Yi.B(r, a) - gf[r] * U.n[a];
        Bb[r] = Yi.B(r, b) - gf[r] * U.n[b];
      }
      const Scalar Caa = Yi.C(a, a) - gna * U.n[a];
      const Scalar Cab = Yi.C(a, b) - gna * U.n[b];
      const Scalar Cbb = Yi.C(b, b) - gnb * U.n[b];
      // joint rotation Rj (.) Rj^T
      const Scalar c = js.c, sn = js.s;
      A = rot_sym(js, A);
      // B Rj^T: columns a, b mixed; then Rj on the left: rows a, b mixed
      const Vec3<Scalar> Ta = Ba * c - Bb * sn;
      const Vec3<Scalar> Tb = Ba * sn + Bb * c;
      Mat3<Scalar> B;
      B.col(k).setZero();
      B(k, a) = Ta[k];
      B(k, b) = Tb[k];
      B(a, a) = c * Ta[a] - sn * Ta[b];
      B(b, a) = sn * Ta[a] + c * Ta[b];
      B(a, b) = c * Tb[a] - sn * Tb[b];
      B(b, b) = sn * Tb[a] + c * Tb[b];
      const Scalar cc = c * c, ss = sn * sn, cs = c * sn;
      const Scalar t = Scalar(2) * cs * Cab;
      Mat3<Scalar> C;
      C.row(k).setZero();
      C.col(k).setZero();
      C(a, a) = cc * Caa + ss * Cbb - t;
      C(b, b) = ss * Caa + cc * Cbb + t;
      C(a, b) = cs * (Caa - Cbb) + (cc - ss) * Cab;
      C(b, a) = C(a, b);
      return const_placement_art({A, B, C});
    } else {
      ArticulatedInertia<Scalar> Ya = Yi;
      Ya.rank1_update(U.f, U.n, Dinv);
      return art_to_parent(js, Ya);
    }
  }
  /// The constant placement Pl applied to an articulated inertia (rotation, then translation).
  ARBOR_INLINE static ArticulatedInertia<Scalar> const_placement_art(
      const ArticulatedInertia<Scalar>& Yi) {
    Mat3<Scalar> A = rot_const_sym(Yi.A);
    Mat3<Scalar> B = rot_const(Yi.B);
    Mat3<Scalar> C = rot_const_sym(Yi.C);
    if constexpr (!p_zero) {
      using Kp = cst::Skew<Vp>;
      const Mat3<Scalar> AP = cst::mul_cols<Scalar, Kp, 3>(A);  // A [p]
      const Mat3<Scalar> PB = cst::mul_rows<Scalar, Kp, 3>(B);  // [p] B
      const Mat3<Scalar> PAP = cst::mul_rows<Scalar, Kp, 3>(AP);
      B -= AP;
      C += PB + PB.transpose() - PAP;
    }
    return {A, B, C};
  }
};

}  // namespace arbor::spatial
