// arbor::qp::detail: the Riccati backend's updates after a working-set change
// (ocp_riccati_backend.hpp): a bound or path row of stage k changes M_k by +-v v'; the rank-one
// update or downdate of L_k is carried down to stage 0, O(NW^2 + NX NW) per stage. False from any
// of them means unsafe (a downdate close to singular, a non-finite value): the caller refactorizes.
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
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::rotate_stage(int s, VecW& v, int j0,
                                                                        VecX& vx, Scalar sigma,
                                                                        Scalar tol) {
  Scalar* l = l_stage[s].data();
  for (int j = j0; j < NU; ++j) {
    if (!rotate_packed_column<NW, 0>(l, nullptr, v.data(), nullptr, j, sigma, tol))
      return false;
  }
  vx = v.template tail<NX>();
  for (int j = j0 > NU ? j0 : NU; j < NW; ++j) {
    if (!rotate_packed_column<NW, 0>(l, nullptr, v.data(), nullptr, j, sigma, tol))
      return false;
  }
  return true;
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::sweep_down(int s, VecX vx, Scalar sigma,
                                                                      Scalar tol) {
  VecW v;
  for (; s > dirty_to && s >= 0; --s) {
    const auto& st = p->stage[s];
    if constexpr (lazy_products) {
      v.template head<NU>().noalias() = st.B.transpose().lazyProduct(vx);
      v.template tail<NX>().noalias() = st.A.transpose().lazyProduct(vx);
    } else {
      v.template head<NU>().noalias() = st.B.transpose() * vx;
      v.template tail<NX>().noalias() = st.A.transpose() * vx;
    }
    zero_fixed(s, v);
    if (!rotate_stage(s, v, 0, vx, sigma, tol))
      return false;
  }
  return true;
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::fix_variable(int i, int k) {
  const Scalar tol = std::sqrt(std::numeric_limits<Scalar>::epsilon());
  const int pj = block_pos(i);
  Scalar* l = l_stage[k].data();
  VecW v = VecW::Zero();
  Scalar* cj = col<NW>(l, pj);
  for (int r = pj + 1; r < NW; ++r) {
    v(r) = cj[r];
    cj[r] = 0;
  }
  cj[pj] = 1;
  for (int c = 0; c < pj; ++c)
    col<NW>(l, c)[pj] = 0;
  VecX vx = VecX::Zero();
  if (!rotate_stage(k, v, pj + 1, vx, Scalar(1), tol))
    return false;
  return k == 0 || sweep_down(k - 1, vx, Scalar(1), tol);
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::free_variable(int i, int k,
                                                                         const VecA& wa) {
  const Scalar tol = std::sqrt(std::numeric_limits<Scalar>::epsilon());
  const int pj = block_pos(i);
  const auto& s = p->stage[k];
  in_factor[i] = 0;  // (refactorized from ws when this fails)
  VecX fc, t, sx;
  if constexpr (NU > 0) {
    if (pj < NU)
      fc = s.B.col(pj);
    else
      fc = s.A.col(pj - NU);
  } else {
    fc = s.A.col(pj - NU);
  }
  if (k == N - 1) {
    lt_mul_tail<NX>(l_term.data(), fc.data(), t.data());
    l_mul_tail<NX>(l_term.data(), t.data(), sx.data());
  } else {
    lt_mul_tail<NW>(l_stage[k + 1].data(), fc.data(), t.data());
    l_mul_tail<NW>(l_stage[k + 1].data(), t.data(), sx.data());
  }
  VecW m;
  m.template head<NU>().noalias() = prod(s.B.transpose(), sx);
  m.template tail<NX>().noalias() = prod(s.A.transpose(), sx);
  if (pj < NU) {
    if constexpr (NU > 0) {
      m.template head<NU>() += s.R.col(pj);
      m.template tail<NX>() += s.S.row(pj).transpose();
    }
  } else {
    m.template head<NU>() += s.S.col(pj - NU);
    m.template tail<NX>() += s.Q.col(pj - NU);
  }
  m(pj) += delta_;
  for (int r = 0; r < NG; ++r) {
    const int row = k * NR + NX + r;
    if (in_factor[NV + row] == 0)
      continue;
    const VecW ar = path_row(k, r);
    m += (wa(row) * ar(pj)) * ar;
  }
  zero_fixed(k, m);
  Scalar* l = l_stage[k].data();
  VecW lr = VecW::Zero();
  Scalar d2 = m(pj);
  for (int c = 0; c < pj; ++c) {
    Scalar v = m(c);
    for (int c2 = 0; c2 < c; ++c2)
      v -= col<NW>(l, c2)[c] * lr(c2);
    lr(c) = v / col<NW>(l, c)[c];
    d2 -= lr(c) * lr(c);
  }
  if (!(d2 > tol * m(pj)) || !std::isfinite(d2))
    return false;
  const Scalar ljj = std::sqrt(d2);
  VecW v = VecW::Zero();
  for (int r = pj + 1; r < NW; ++r) {
    Scalar val = m(r);
    for (int c = 0; c < pj; ++c)
      val -= col<NW>(l, c)[r] * lr(c);
    v(r) = val / ljj;
  }
  for (int c = 0; c < pj; ++c)
    col<NW>(l, c)[pj] = lr(c);
  Scalar* cj = col<NW>(l, pj);
  cj[pj] = ljj;
  for (int r = pj + 1; r < NW; ++r)
    cj[r] = v(r);
  VecX vx = VecX::Zero();
  if (!rotate_stage(k, v, pj + 1, vx, Scalar(-1), tol))
    return false;
  return k == 0 || sweep_down(k - 1, vx, Scalar(-1), tol);
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::rank_one(int i, int k, bool active,
                                                                    Scalar w, const VecA& wa) {
  const Scalar sigma = active ? Scalar(1) : Scalar(-1);
  const Scalar tol = std::sqrt(std::numeric_limits<Scalar>::epsilon());
  VecX vx = VecX::Zero();
  if (k == N) {
    if (i < NV) {
      vx(i - N * NW) = std::sqrt(w);
    } else {
      const int j = i - NV - N * NR;
      const Scalar sw = std::sqrt(wa(i - NV));
      for (int c = 0; c < NX; ++c)
        vx(c) = sw * p->terminal.C(j, c);
    }
    VecX t = vx;
    for (int j = 0; j < NX; ++j) {
      if (!rotate_packed_column<NX, 0>(l_term.data(), nullptr, t.data(), nullptr, j, sigma, tol))
        return false;
    }
    return sweep_down(N - 1, vx, sigma, tol);
  }
  if (k <= dirty_to)
    return true;
  VecW v = VecW::Zero();
  if (i < NV) {
    v(block_pos(i)) = std::sqrt(w);
  } else {
    const int j = i - NV - k * NR - NX;
    v = std::sqrt(wa(i - NV)) * path_row(k, j);
  }
  zero_fixed(k, v);
  if (!rotate_stage(k, v, 0, vx, sigma, tol))
    return false;
  return sweep_down(k - 1, vx, sigma, tol);
}

}  // namespace arbor::qp::detail
