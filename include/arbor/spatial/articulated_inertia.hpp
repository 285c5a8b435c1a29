// arbor: articulated-body inertia (ABA, M^-1) kept as its three 3x3 blocks; a product with a
// motion costs 45 multiplications, a rank-one update 27.
#pragma once

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

}  // namespace arbor::spatial
