// arbor::qp::detail: the products with an OcpQp's fixed-size stage blocks that the OCP backend
// and the active-set core need (H v, A v, A' v over the whole horizon, the squared row norms) and
// the stage of a flat variable or constraint index. Cost per call: one pass over every stage
// block, (NX + NU)^2 (H v) and (NX + NG) (NX + NU) (A v, A' v) multiply-adds per stage. With SIMD
// (EIGEN_VECTORIZE) the products are written per column (broadcast multiply-adds into fixed-size
// accumulators, dot products of contiguous columns), otherwise Eigen's gemv; both read the blocks
// through Eigen expressions and assume no alignment beyond what Eigen's own fixed-size types
// declare.
#pragma once

#include <Eigen/Core>
#include <algorithm>

#include "arbor/qp/problem.hpp"

namespace arbor::qp::detail {

/// The products with the problem's fixed-size blocks (H v, A v, A' v, the [A B] products of the
/// Riccati solve) as fixed-size products unrolled per column (M v: broadcast multiply-adds; M' v:
/// dot products of columns; a few as Eigen lazy products) where Eigen vectorises, and through its
/// runtime-size gemv otherwise: on the Cortex-M7 (no SIMD) the unrolled ones cost 2-5 % more
/// instructions (bench/qp/RESULTS.md).
#if defined(EIGEN_VECTORIZE)
inline constexpr bool lazy_products = true;
#else
inline constexpr bool lazy_products = false;
#endif

/// The products with the data of an OcpQp that every OCP backend needs (H v, A v, A' v, the
/// squared row norms) and the stage of a flat constraint index; the problem is referenced.
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct OcpProducts {
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  static constexpr int NW = NX + NU;
  static constexpr int NR = NX + NG;  ///< rows per path stage
  static constexpr int NV = Problem::nv;
  static constexpr int NA = Problem::na;
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;

  const Problem* p = nullptr;  ///< referenced problem

  // With lazy_products (SIMD): products written per column, M v as one broadcast multiply-add
  // per column of M into a fixed-size accumulator and M' v as one dot product per (contiguous)
  // column of M: Eigen 3.4's lazy products of these shapes, and of their sums, took ~3x the
  // instructions (bench/qp/RESULTS.md: H x 16.5 k -> 5.5 k per call). Without SIMD: Eigen's
  // gemv.
  void hess_mul(const VecV& x, VecV& y) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int o = k * NW;
      const auto xk = x.template segment<NX>(o);
      const auto uk = x.template segment<NU>(o + NX);
      if constexpr (lazy_products) {
        // columns of Q, S and R by broadcast multiply-adds; S' u as dot products of S's
        // (contiguous) columns with u
        Eigen::Matrix<Scalar, NX, 1> ax = s.Q.col(0) * xk(0);
        Eigen::Matrix<Scalar, NU, 1> au = s.S.col(0) * xk(0);
        for (int j = 1; j < NX; ++j) {
          ax += s.Q.col(j) * xk(j);
          au += s.S.col(j) * xk(j);
        }
        if constexpr (NU > 0) {
          for (int j = 0; j < NU; ++j)
            au += s.R.col(j) * uk(j);
        }
        Eigen::Matrix<Scalar, NX, 1> st;
        for (int i = 0; i < NX; ++i)
          st(i) = s.S.col(i).dot(uk);
        y.template segment<NX>(o) = ax + st;
        y.template segment<NU>(o + NX) = au;
      } else {
        y.template segment<NX>(o).noalias() = s.Q * xk;
        y.template segment<NX>(o).noalias() += s.S.transpose() * uk;
        y.template segment<NU>(o + NX).noalias() = s.S * xk;
        y.template segment<NU>(o + NX).noalias() += s.R * uk;
      }
    }
    if constexpr (lazy_products)
      y.template tail<NX>().noalias() = p->terminal.Q.lazyProduct(x.template tail<NX>());
    else
      y.template tail<NX>().noalias() = p->terminal.Q * x.template tail<NX>();
  }

  /// y = A_P x on the rows that are not solved exactly (the path rows; the others keep their
  /// values): the step's A dx needs no product with the dynamics rows, whose D dx is the e the
  /// solve was given.
  void path_mul(const VecV& x, VecA& y) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const auto xk = x.template segment<NX>(k * NW);
      const auto uk = x.template segment<NU>(k * NW + NX);
      if constexpr (lazy_products) {
        Eigen::Matrix<Scalar, NG, 1> ag = s.C.col(0) * xk(0);
        for (int j = 1; j < NX; ++j)
          ag += s.C.col(j) * xk(j);
        if constexpr (NU > 0) {
          for (int j = 0; j < NU; ++j)
            ag += s.D.col(j) * uk(j);
        }
        y.template segment<NG>(k * NR + NX) = ag;
      } else {
        auto gen = y.template segment<NG>(k * NR + NX);
        gen.noalias() = s.C * xk;
        gen.noalias() += s.D * uk;
      }
    }
    if constexpr (lazy_products)
      y.template tail<NGN>().noalias() = p->terminal.C.lazyProduct(x.template tail<NX>());
    else
      y.template tail<NGN>().noalias() = p->terminal.C * x.template tail<NX>();
  }

  /// y = A x: the path and terminal rows (path_mul), then the dynamics rows
  /// x_{k+1} - A_k x_k - B_k u_k.
  void cons_mul(const VecV& x, VecA& y) const {
    path_mul(x, y);
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int o = k * NW, r = k * (NX + NG);
      const auto xk = x.template segment<NX>(o);
      const auto uk = x.template segment<NU>(o + NX);
      if constexpr (lazy_products) {
        Eigen::Matrix<Scalar, NX, 1> ad = x.template segment<NX>(o + NW);
        for (int j = 0; j < NX; ++j)
          ad -= s.A.col(j) * xk(j);
        if constexpr (NU > 0) {
          for (int j = 0; j < NU; ++j)
            ad -= s.B.col(j) * uk(j);
        }
        y.template segment<NX>(r) = ad;
      } else {
        auto dyn = y.template segment<NX>(r);
        dyn = x.template segment<NX>(o + NW);
        dyn.noalias() -= s.A * xk;
        dyn.noalias() -= s.B * uk;
      }
    }
  }

  /// y = A_P' l over the rows that are not solved exactly (the entries of l on the dynamics rows
  /// are not read).
  void path_tmul(const VecA& l, VecV& y) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const auto lg = l.template segment<NG>(k * NR + NX);
      if constexpr (lazy_products) {
        for (int i = 0; i < NX; ++i)
          y(k * NW + i) = s.C.col(i).dot(lg);
        if constexpr (NU > 0) {
          for (int i = 0; i < NU; ++i)
            y(k * NW + NX + i) = s.D.col(i).dot(lg);
        }
      } else {
        y.template segment<NX>(k * NW).noalias() = s.C.transpose() * lg;
        y.template segment<NU>(k * NW + NX).noalias() = s.D.transpose() * lg;
      }
    }
    if constexpr (lazy_products)
      y.template tail<NX>().noalias() =
          p->terminal.C.transpose().lazyProduct(l.template tail<NGN>());
    else
      y.template tail<NX>().noalias() = p->terminal.C.transpose() * l.template tail<NGN>();
  }

  /// y = A' l: the path and terminal rows (path_tmul), then the dynamics rows' terms.
  void cons_tmul(const VecA& l, VecV& y) const {
    path_tmul(l, y);
    for (int k = N - 1; k >= 0; --k) {
      const auto& s = p->stage[k];
      const int o = k * NW;
      const auto ld = l.template segment<NX>(k * NR);
      if constexpr (lazy_products) {
        for (int i = 0; i < NX; ++i)
          y(o + i) -= s.A.col(i).dot(ld);
        if constexpr (NU > 0) {
          for (int i = 0; i < NU; ++i)
            y(o + NX + i) -= s.B.col(i).dot(ld);
        }
      } else {
        y.template segment<NX>(o).noalias() -= s.A.transpose() * ld;
        y.template segment<NU>(o + NX).noalias() -= s.B.transpose() * ld;
      }
      y.template segment<NX>(o + NW) += ld;  // x_{k+1}
    }
  }

  static int stage_of(int i) {
    const int k = i < NV ? i / NW : (i - NV) / (NX + NG);
    return k < N ? k : N;
  }
  /// The largest |diagonal entry| of the stage Hessians (Q, R, Q_N): one pass over N NW + NX
  /// scalars.
  Scalar hessian_scale() const {
    Scalar h = p->terminal.Q.diagonal().cwiseAbs().maxCoeff();
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      h = std::max(h, s.Q.diagonal().cwiseAbs().maxCoeff());
      if constexpr (NU > 0)
        h = std::max(h, s.R.diagonal().cwiseAbs().maxCoeff());
    }
    return h;
  }
  void row_norms_sq(VecA& n) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int r = k * (NX + NG);
      n.template segment<NX>(r) = s.A.rowwise().squaredNorm() + s.B.rowwise().squaredNorm();
      n.template segment<NX>(r).array() += Scalar(1);
      n.template segment<NG>(r + NX) = s.C.rowwise().squaredNorm() + s.D.rowwise().squaredNorm();
    }
    n.template tail<NGN>() = p->terminal.C.rowwise().squaredNorm();
  }
};

}  // namespace arbor::qp::detail
