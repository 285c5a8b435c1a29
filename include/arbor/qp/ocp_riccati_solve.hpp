// arbor::qp::detail: the Riccati backend's solve (ocp_riccati_backend.hpp): a backward sweep
// y_k = L_k^-1 h_k and a forward one for the steps, the costates of the dynamics rows and the
// multipliers of the fixed variables; ~NW^2 / 2 + NU NW + 4 NX NW + 2 NX^2 multiply-adds per stage.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "arbor/qp/backend.hpp"
#include "arbor/qp/kernels.hpp"
#include "arbor/qp/ocp_riccati_factor.hpp"
#include "arbor/qp/packed_kernels.hpp"

namespace arbor::qp::detail {

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
template <bool ZeroRhs, bool InitialOnly>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::solve_exact(VecV& v, VecA& a, VecV& c,
                                                                       const VecA& wa) const {
  static_assert(!(ZeroRhs && InitialOnly), "one kind of right-hand side");
  Scalar* f = v.data();
  // backward: y_k = L_k^-1 h_k, kept in v's stage segment in (u, x) order
  Scalar* yn = f + N * NW;
  if constexpr (!InitialOnly)
    solve_lower_packed<NX>(l_term.data(), yn);
  const Scalar* ynext = yn;  // y_{x,k+1}
  const Scalar* lnext = l_term.data();
  int nnext = NX;  // order of the packed factor holding Lxx_{k+1} (its trailing NX block)
  for (int k = N - 1; k >= 0; --k) {
    const auto& s = p->stage[k];
    Scalar* fk = f + k * NW;
    if constexpr (InitialOnly) {
      if (k > 0) {  // zero right-hand side, no fixed step: y_k = 0 (v is zero there)
        ynext = fk + NU;
        lnext = l_stage[k].data();
        nnext = NW;
        continue;
      }
    }
    // fixed variables (step cw): f -= G_k cw on the free ones (f_j kept in c for the
    // multiplier), e_k += F_k cw; their own entries of h are set to cw below
    VecW cw;
    VecX ekf;
    const Scalar* ek = a.data() + k * NR;
    const int any = fixed_rhs(k, fk, c, wa, cw);
    if (any == 2) {
      if (k == 0)
        ekf.noalias() = Eigen::Map<const VecX>(ek) + prod(s.B, cw.template head<NU>()) +
                        prod(s.A, cw.template tail<NX>());
      else
        ekf.noalias() = Eigen::Map<const VecX>(ek) + prod(s.B, cw.template head<NU>());
      ek = ekf.data();
    }
    // r = y_{x,k+1} - Lxx_{k+1}' e_k, then s = Lxx_{k+1} r
    VecX r, sx;
    const Scalar* rp = ynext;  // r = y_{x,k+1} when e_k = 0
    if constexpr (!ZeroRhs) {
      if (nnext == NX) {
        lt_mul_tail<NX>(lnext, ek, r.data());
      } else {
        lt_mul_tail<NW>(lnext, ek, r.data());
      }
      for (int i = 0; i < NX; ++i)
        r(i) = ynext[i] - r(i);
      rp = r.data();
    }
    if (nnext == NX) {
      l_mul_tail<NX>(lnext, rp, sx.data());
    } else {
      l_mul_tail<NW>(lnext, rp, sx.data());
    }
    // h = [f_u; f_x] + [B A]' s
    VecW h;
    if constexpr (lazy_products) {
      if constexpr (NU > 0) {
        for (int i = 0; i < NU; ++i)
          h(i) = fk[NX + i] + s.B.col(i).dot(sx);
      }
      for (int i = 0; i < NX; ++i)
        h(NU + i) = fk[i] + s.A.col(i).dot(sx);
    } else {
      h.template head<NU>() = Eigen::Map<const Eigen::Matrix<Scalar, NU, 1>>(fk + NX);
      h.template head<NU>().noalias() += s.B.transpose() * sx;
      h.template tail<NX>() = Eigen::Map<const VecX>(fk);
      h.template tail<NX>().noalias() += s.A.transpose() * sx;
    }
    if (any > 0) {
      for (int j = 0; j < (k == 0 ? NW : NU); ++j) {
        if (is_fixed(k, j))
          h(j) = cw(j);
      }
    }
    solve_lower_packed<NW>(l_stage[k].data(), h.data());
    Eigen::Map<VecW>{fk} = h;
    ynext = fk + NU;
    lnext = l_stage[k].data();
    nnext = NW;
  }
  // forward: stage 0 solves its whole block (x_0 has no costate before it)
  VecW dw;  // (u, x) order
  dw = Eigen::Map<const VecW>(f);
  solve_lower_transposed_packed<NW>(l_stage[0].data(), dw.data());
  for (int k = 0; k < N; ++k) {
    const auto& s = p->stage[k];
    Scalar* fk = f + k * NW;
    if (k > 0) {
      // dw holds [y_u; dx_k]: the costate of x_k, then du_k
      Scalar* nu = a.data() + (k - 1) * NR;
      costate<NW>(l_stage[k].data(), fk + NU, dw.data() + NU, nu);
      for (int i = 0; i < NU; ++i)
        dw(i) = fk[i];
      solve_lower_transposed_head<NW, NU>(l_stage[k].data(), dw.data());
    }
    // dx_{k+1} = A dx_k + B du_k + e_k
    VecX xn;
    if constexpr (ZeroRhs || InitialOnly)
      xn.setZero();
    else
      xn = Eigen::Map<const VecX>(a.data() + k * NR);
    if constexpr (lazy_products) {
      for (int j = 0; j < NX; ++j)
        xn += s.A.col(j) * dw(NU + j);
      if constexpr (NU > 0) {
        for (int j = 0; j < NU; ++j)
          xn += s.B.col(j) * dw(j);
      }
    } else {
      xn.noalias() += s.A * dw.template tail<NX>();
      xn.noalias() += s.B * dw.template head<NU>();
    }
    Eigen::Map<VecX>{fk} = dw.template tail<NX>();
    Eigen::Map<Eigen::Matrix<Scalar, NU, 1>>(fk + NX) = dw.template head<NU>();
    dw.template tail<NX>() = xn;
  }
  Scalar* fn = f + N * NW;
  costate<NX>(l_term.data(), fn, dw.data() + NU, a.data() + (N - 1) * NR);
  Eigen::Map<VecX>{fn} = dw.template tail<NX>();
  // multipliers of the fixed variables: dlam_j = f_j - (G_k dw_k)_j - (D' dnu)_j
  for (int k = 0; k < N; ++k)
    fixed_multipliers(k, f + k * NW, a.data() + k * NR, c, wa);
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
template <typename VU, typename VX>
inline Eigen::Matrix<Scalar, NG, 1> OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::path_weighted(
    int k, const VU& u, const VX& x, bool with_x, const VecA& wa) const {
  const auto& s = p->stage[k];
  Eigen::Matrix<Scalar, NG, 1> t;
  if (with_x)
    t.noalias() = prod(s.D, u) + prod(s.C, x);
  else
    t.noalias() = prod(s.D, u);
  for (int r = 0; r < NG; ++r) {
    const int row = k * NR + NX + r;
    t(r) = in_factor[NV + row] != 0 ? wa(row) * t(r) : Scalar(0);
  }
  return t;
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline int OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::fixed_rhs(int k, Scalar* fk, VecV& c,
                                                                    const VecA& wa,
                                                                    VecW& cw) const {
  int any = 0;
  const int jend = k == 0 ? NW : NU;  // x_0 is fixed in stage 0 only
  for (int j = 0; j < jend; ++j) {
    if (!is_fixed(k, j)) {
      cw(j) = 0;
      continue;
    }
    const int i = flat_bound(k, j);
    cw(j) = c(i);
    c(i) = fk[i - k * NW];
    any = std::max(any, cw(j) != Scalar(0) ? 2 : 1);
  }
  // (set although only the fixed entries are read when any < 2: GCC -O3 cannot see that,
  // -Wmaybe-uninitialized on the bare-metal targets)
  for (int j = jend; j < NW; ++j)
    cw(j) = 0;
  if (any < 2)
    return any;
  const auto& s = p->stage[k];
  // G_k cw, (u, x) order: [R S; S' Q] cw + the active path rows' w_r a_r a_r' cw (delta I
  // touches the fixed entries only); x_0's part only in stage 0
  const auto cu = cw.template head<NU>();
  const auto cx = cw.template tail<NX>();
  Eigen::Matrix<Scalar, NU, 1> gu;
  VecX gx;
  gu.noalias() = prod(s.R, cu);
  gx.noalias() = prod(s.S.transpose(), cu);
  if (k == 0) {
    gu.noalias() += prod(s.S, cx);
    gx.noalias() += prod(s.Q, cx);
  }
  if constexpr (NG > 0) {
    const Eigen::Matrix<Scalar, NG, 1> t = path_weighted(k, cu, cx, k == 0, wa);
    gu.noalias() += prod(s.D.transpose(), t);
    gx.noalias() += prod(s.C.transpose(), t);
  }
  Eigen::Map<VecX>{fk} -= gx;
  Eigen::Map<Eigen::Matrix<Scalar, NU, 1>>{fk + NX} -= gu;
  return 2;
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::fixed_multipliers(
    int k, const Scalar* dwk, const Scalar* nu, VecV& c, const VecA& wa) const {
  const int jend = k == 0 ? NW : NU;
  bool any = false;
  for (int j = 0; j < jend && !any; ++j)
    any = is_fixed(k, j);
  if (!any)
    return;
  const auto& s = p->stage[k];
  const Eigen::Map<const VecX> dx(dwk), dn(nu);
  const Eigen::Map<const Eigen::Matrix<Scalar, NU, 1>> du(dwk + NX);
  // the weighted residuals of the active path rows, then row j of G_k dw - F_k' dnu for each
  // fixed j only (a stage has few)
  Scalar t[NG > 0 ? NG : 1];
  for (int r = 0; r < NG; ++r) {
    const int row = k * NR + NX + r;
    t[r] = 0;
    if (in_factor[NV + row] == 0)
      continue;
    Scalar v = 0;
    for (int c = 0; c < NU; ++c)
      v += s.D(r, c) * du(c);
    for (int c = 0; c < NX; ++c)
      v += s.C(r, c) * dx(c);
    t[r] = wa(row) * v;
  }
  for (int j = 0; j < jend; ++j) {
    if (!is_fixed(k, j))
      continue;
    Scalar gj = 0;
    if (j < NU) {
      if constexpr (NU > 0) {
        gj = s.R.col(j).dot(du) + s.S.row(j).dot(dx) - s.B.col(j).dot(dn) + delta_ * du(j);
        for (int r = 0; r < NG; ++r)
          gj += s.D(r, j) * t[r];
      }
    } else {
      const int q = j - NU;
      gj = s.S.col(q).dot(du) + s.Q.col(q).dot(dx) - s.A.col(q).dot(dn) + delta_ * dx(q);
      for (int r = 0; r < NG; ++r)
        gj += s.C(r, q) * t[r];
    }
    c(flat_bound(k, j)) -= gj;
  }
}

}  // namespace arbor::qp::detail
