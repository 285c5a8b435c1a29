// arbor: articulated-body inertia (ABA, M^-1) kept as its three 3x3 blocks; a product with a
// motion costs 45 multiplications (fewer with known zeros: art_times), a rank-one update 27.
#pragma once

#include <bit>

#include "arbor/core/config.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/motion.hpp"

namespace arbor::spatial {

/// Articulated-body inertia (symmetric 6x6, [v; w] -> [f; n]) kept as its 3x3 blocks
/// [[A, B], [B^T, C]] with A and C symmetric.
template <class Scalar>
struct ArticulatedInertia {
  Mat3<Scalar> A;  ///< linear-linear block
  Mat3<Scalar> B;  ///< linear-angular block
  Mat3<Scalar> C;  ///< angular-angular block

  /// The full 6x6 matrix.
  Mat6<Scalar> matrix() const {
    Mat6<Scalar> M;
    M << A, B, B.transpose(), C;
    return M;
  }
  /// From a symmetric 6x6 matrix.
  template <class D>
  static ArticulatedInertia from(const Eigen::MatrixBase<D>& M) {
    return {M.template topLeftCorner<3, 3>(), M.template topRightCorner<3, 3>(),
            M.template bottomRightCorner<3, 3>()};
  }
  /// Y * m.
  Force<Scalar> operator*(const Motion<Scalar>& m) const {
    return {A * m.v + B * m.w, B.transpose() * m.v + C * m.w};
  }
  ArticulatedInertia& operator+=(const ArticulatedInertia& o) {
    A += o.A;
    B += o.B;
    C += o.C;
    return *this;
  }
  /// Y - U Dinv U^T for U = [uf; un].
  void rank1_update(const Vec3<Scalar>& uf, const Vec3<Scalar>& un, const Scalar& Dinv) {
    const Vec3<Scalar> gf = uf * Dinv, gn = un * Dinv;
    A.noalias() -= gf * uf.transpose();
    B.noalias() -= gf * un.transpose();
    C.noalias() -= gn * un.transpose();
  }
};

/// Ya x for a motion x whose entries outside Mask (bit j: entry j of [v; w]) are known zero,
/// written out entry by entry (the zero entries skipped).
template <unsigned Mask = 0x3fu, class S>
ARBOR_INLINE Force<S> art_times(const ArticulatedInertia<S>& Y, const Motion<S>& x) {
  constexpr int j0 = std::countr_zero(Mask);
  Force<S> F;
  static_for<3>([&](auto Rr) {
    constexpr int r = decltype(Rr)::value;
    S f, n;
    static_for<6>([&](auto J) {
      constexpr int j = decltype(J)::value;
      if constexpr ((Mask >> j) & 1u) {
        const S& xj = j < 3 ? x.v[j % 3] : x.w[j % 3];
        const S yf = j < 3 ? Y.A(r, j % 3) : Y.B(r, j % 3);
        const S yn = j < 3 ? Y.B(j % 3, r) : Y.C(r, j % 3);
        if constexpr (j == j0) {
          f = yf * xj;
          n = yn * xj;
        } else {
          f += yf * xj;
          n += yn * xj;
        }
      }
    });
    F.f[r] = f;
    F.n[r] = n;
  });
  return F;
}
/// <U, x> for x whose entries outside Mask are zero.
template <unsigned Mask = 0x3fu, class S>
ARBOR_INLINE S dot_masked(const Force<S>& U, const Motion<S>& x) {
  constexpr int j0 = std::countr_zero(Mask);
  S acc;
  static_for<6>([&](auto J) {
    constexpr int j = decltype(J)::value;
    if constexpr ((Mask >> j) & 1u) {
      const S t = j < 3 ? S(U.f[j % 3] * x.v[j % 3]) : S(U.n[j % 3] * x.w[j % 3]);
      if constexpr (j == j0)
        acc = t;
      else
        acc += t;
    }
  });
  return acc;
}

}  // namespace arbor::spatial
