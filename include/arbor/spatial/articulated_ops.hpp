// arbor: articulated-body inertia operations of body i (ABA and M^-1): the constant body inertia
// as an articulated inertia, U = Ya S, and the projection Ya - U Dinv U^T carried to the parent.
// For revolute joints about a coordinate axis the projection has a structurally zero row and
// column, which the transport skips (detail::SMat products over the nonzero entries only).
#pragma once

#include "arbor/spatial/articulated_inertia.hpp"
#include "arbor/spatial/body_inertia.hpp"
#include "arbor/spatial/sparse_mat3.hpp"

namespace arbor::spatial {

namespace detail {

/// Entry (r, c) of block Blk of BP::art_inertia() (BodyOps of a parent) as a compile-time
/// constant, 0 when !Init: Blk 0 is A = m 1, 1 is B = -[h], 2 is C = Io.
template <class BP, bool Init, int Blk, int r, int c>
struct ArtInertiaEntry {
  static constexpr double value = [] {
    if constexpr (!Init)
      return 0.0;
    else if constexpr (Blk == 0)
      return r == c ? BP::Y.m : 0.0;
    else if constexpr (Blk == 1)
      return -cst::Skew<typename BP::HV>::at(r, c);
    else
      return BP::Y.Io[r][c];
  }();
};

}  // namespace detail

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
  using typename Base::Kp;
  using typename Base::KR;
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
  /// U = Ya S as [uf; un] (aligned kinds: a signed column of Ya, no arithmetic).
  ARBOR_INLINE static void art_S(const ArticulatedInertia<Scalar>& Ya, Vec3<Scalar>& uf,
                                 Vec3<Scalar>& un) {
    if constexpr (aligned) {
      for (int r = 0; r < 3; ++r) {
        if constexpr (revolute) {
          uf[r] = Base::signed_(Ya.B(r, k));
          un[r] = Base::signed_(Ya.C(r, k));
        } else {
          uf[r] = Base::signed_(Ya.A(r, k));
          un[r] = Base::signed_(Ya.B(k, r));
        }
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
  ARBOR_INLINE static void art_S(const ArticulatedInertia<Scalar>& Ya, Force<Scalar>& U) {
    art_S(Ya, U.f, U.n);
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
  /// inertia that its parent sees, expressed in the parent frame.
  ARBOR_INLINE static ArticulatedInertia<Scalar> art_project_to_parent(
      const JointState<Scalar>& js, const ArticulatedInertia<Scalar>& Yi, const Force<Scalar>& U,
      const Scalar& Dinv) {
    if constexpr (revolute && aligned) {
      ArticulatedInertia<Scalar> Yp{Mat3<Scalar>::Zero(), Mat3<Scalar>::Zero(),
                                    Mat3<Scalar>::Zero()};
      add_art_projection(js, Yi, U, Dinv, Yp);
      return Yp;
    } else {
      ArticulatedInertia<Scalar> Ya = Yi;
      Ya.rank1_update(U.f, U.n, Dinv);
      return art_to_parent(js, Ya);
    }
  }
  /// Yp += (Yi - U Dinv U^T) carried to the parent frame. For a revolute joint about a
  /// coordinate axis: the projection's zero row and column k (C) and column k (B) known at
  /// compile time through the joint rotation (Ya S = 0), the constant rotation and translation of
  /// the placement applied to the nonzero entries only (detail::SMat), A and C as their upper
  /// triangles.
  /// BP (the parent's BodyOps, not void): Yp is set to the parent's constant body inertia plus
  /// the projection (the first child of the parent to project) instead of added to.
  template <class BP = void>
  ARBOR_INLINE static void add_art_projection(const JointState<Scalar>& js,
                                              const ArticulatedInertia<Scalar>& Yi,
                                              const Force<Scalar>& U, const Scalar& Dinv,
                                              ArticulatedInertia<Scalar>& Yp) {
    constexpr bool init = !std::is_void_v<BP>;
    if constexpr (!(aligned && revolute)) {
      if constexpr (init)
        Yp = BP::art_inertia();
      Yp += art_project_to_parent(js, Yi, U, Dinv);
    } else {
      // the entries of Yp before the sum: Yp itself, or the parent's constant art_inertia()
      // (-0.0 for its zeros: -0.0 + x is x, folded at compile time)
      auto start = [&](const Scalar& y, auto Kc) -> Scalar {
        if constexpr (!init) {
          return y;
        } else {
          constexpr double kc = decltype(Kc)::value;
          if constexpr (kc == 0.0)
            return Scalar(-0.0);
          else
            return Scalar(kc);
        }
      };
      constexpr int a = ia, b = ib;
      constexpr unsigned full = 0x1ffu;
      constexpr unsigned no_col_k = full & ~((1u << k) | (1u << (3 + k)) | (1u << (6 + k)));
      constexpr unsigned ab_block =
          (1u << (3 * a + a)) | (1u << (3 * a + b)) | (1u << (3 * b + a)) | (1u << (3 * b + b));
      using KpT = cst::Transpose<Kp>;
      // Block by block (A, then B, then C), so that few values live at once: the rank-one
      // projection, the joint rotation Rj (.) Rj^T (a and b mixed), the constant rotation, the
      // translation p (B - A [p], C + [p] B + ([p] B)^T - [p] A [p]), the sum into Yp.
      const Scalar c = js.c, sn = js.s;
      const Scalar cc = c * c, ss = sn * sn, cs = c * sn;
      const Scalar gf[3] = {U.f[0] * Dinv, U.f[1] * Dinv, U.f[2] * Dinv};
      detail::SMat<Scalar, full> Am;
      {
        Scalar A[3][3];
        for (int r = 0; r < 3; ++r)
          for (int q = r; q < 3; ++q) {
            A[r][q] = Yi.A(r, q) - gf[r] * U.f[q];
            A[q][r] = A[r][q];
          }
        const Scalar ta = Scalar(2) * cs * A[a][b];
        Am.e[k][k] = A[k][k];
        Am.e[a][k] = Am.e[k][a] = c * A[a][k] - sn * A[b][k];
        Am.e[b][k] = Am.e[k][b] = sn * A[a][k] + c * A[b][k];
        Am.e[a][a] = cc * A[a][a] + ss * A[b][b] - ta;
        Am.e[b][b] = ss * A[a][a] + cc * A[b][b] + ta;
        Am.e[a][b] = Am.e[b][a] = cs * (A[a][a] - A[b][b]) + (cc - ss) * A[a][b];
      }
      const auto A2 = detail::kl<KR, true>(detail::kr<KR>(Am));
      using MA = std::remove_cvref_t<decltype(A2)>;
      static_for<9>([&](auto RC) {
        constexpr int r = decltype(RC)::value / 3, q = decltype(RC)::value % 3;
        if constexpr (r <= q) {
          Scalar t = start(Yp.A(r, q), detail::ArtInertiaEntry<BP, init, 0, r, q>{});
          if constexpr (MA::at(r, q))
            t += A2.e[r][q];
          Yp.A(r, q) = t;
          if constexpr (r != q)
            Yp.A(q, r) = t;
        }
      });
      const auto AP = [&] {  // A [p]
        if constexpr (p_zero)
          return detail::SMat<Scalar, 0u>{};
        else
          return detail::kr<KpT>(A2);
      }();
      const auto PAP = [&] {  // [p] A [p]
        if constexpr (p_zero)
          return detail::SMat<Scalar, 0u>{};
        else
          return detail::kl<Kp, true>(AP);
      }();
      detail::SMat<Scalar, no_col_k> Bm;
      {
        Scalar Ta[3], Tb[3];
        for (int r = 0; r < 3; ++r) {
          const Scalar Ba = Yi.B(r, a) - gf[r] * U.n[a];
          const Scalar Bb = Yi.B(r, b) - gf[r] * U.n[b];
          Ta[r] = Ba * c - Bb * sn;
          Tb[r] = Ba * sn + Bb * c;
        }
        Bm.e[k][a] = Ta[k];
        Bm.e[k][b] = Tb[k];
        Bm.e[a][a] = c * Ta[a] - sn * Ta[b];
        Bm.e[b][a] = sn * Ta[a] + c * Ta[b];
        Bm.e[a][b] = c * Tb[a] - sn * Tb[b];
        Bm.e[b][b] = sn * Tb[a] + c * Tb[b];
      }
      const auto B2 = detail::kl<KR>(detail::kr<KR>(Bm));
      using MB = std::remove_cvref_t<decltype(B2)>;
      using MAP = std::remove_cvref_t<decltype(AP)>;
      static_for<9>([&](auto RC) {
        constexpr int r = decltype(RC)::value / 3, q = decltype(RC)::value % 3;
        Scalar t = start(Yp.B(r, q), detail::ArtInertiaEntry<BP, init, 1, r, q>{});
        if constexpr (MB::at(r, q))
          t += B2.e[r][q];
        if constexpr (MAP::at(r, q))
          t -= AP.e[r][q];
        Yp.B(r, q) = t;
      });
      const auto PB = [&] {  // [p] B
        if constexpr (p_zero)
          return detail::SMat<Scalar, 0u>{};
        else
          return detail::kl<Kp>(B2);
      }();
      detail::SMat<Scalar, ab_block> Cm;
      {
        const Scalar gna = U.n[a] * Dinv, gnb = U.n[b] * Dinv;
        const Scalar Caa = Yi.C(a, a) - gna * U.n[a];
        const Scalar Cab = Yi.C(a, b) - gna * U.n[b];
        const Scalar Cbb = Yi.C(b, b) - gnb * U.n[b];
        const Scalar tc = Scalar(2) * cs * Cab;
        Cm.e[a][a] = cc * Caa + ss * Cbb - tc;
        Cm.e[b][b] = ss * Caa + cc * Cbb + tc;
        Cm.e[a][b] = Cm.e[b][a] = cs * (Caa - Cbb) + (cc - ss) * Cab;
      }
      const auto C2 = detail::kl<KR, true>(detail::kr<KR>(Cm));
      using MC = std::remove_cvref_t<decltype(C2)>;
      using MPB = std::remove_cvref_t<decltype(PB)>;
      using MPAP = std::remove_cvref_t<decltype(PAP)>;
      static_for<9>([&](auto RC) {
        constexpr int r = decltype(RC)::value / 3, q = decltype(RC)::value % 3;
        if constexpr (r <= q) {
          Scalar t = start(Yp.C(r, q), detail::ArtInertiaEntry<BP, init, 2, r, q>{});
          if constexpr (MC::at(r, q))
            t += C2.e[r][q];
          if constexpr (MPB::at(r, q))
            t += PB.e[r][q];
          if constexpr (MPB::at(q, r))
            t += PB.e[q][r];
          if constexpr (MPAP::at(r, q))
            t -= PAP.e[r][q];
          Yp.C(r, q) = t;
          if constexpr (r != q)
            Yp.C(q, r) = t;
        }
      });
    }
  }

  /// The constant placement Pl applied to an articulated inertia (rotation, then translation).
  ARBOR_INLINE static ArticulatedInertia<Scalar> const_placement_art(
      const ArticulatedInertia<Scalar>& Yi) {
    Mat3<Scalar> A = rot_const_sym(Yi.A);
    Mat3<Scalar> B = rot_const(Yi.B);
    Mat3<Scalar> C = rot_const_sym(Yi.C);
    if constexpr (!p_zero) {
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
