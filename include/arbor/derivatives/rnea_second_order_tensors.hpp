// arbor: the four n x n x n second-order tensors of inverse dynamics tau = ID(q, v, a), as
// Pinocchio's ComputeRNEASecondOrderDerivatives gives them: d2tau/dq2, d2tau/dv2, d2tau/dq dv and
// d2tau/da dq (index convention in SecondOrderTensors). Slice i is the Hessian of tau_i =
// e_i' ID: the contracted second-order sweep of rnea_second_order.hpp with lambda = e_i. One
// contracted sweep with lambda = 0 gives everything that does not depend on lambda (placements,
// velocities, accelerations, dS, ddS, the composites Y, Yd, h, F and the B-gradient columns Km,
// Wm, P); then per output i only the joints on the path to i and in its subtree are visited
// (mu_k = S_i on the subtree of i and 0 elsewhere, so the other joints contribute nothing), with
// their lambda sums L, N, Ydm in closed form from the composites, forming only the
// lambda-dependent forces Kt, Ka, Wv and writing the pair entries straight into slice i
// (depth-first numberings; others run the contracted backward step and copy from so.hessian).
// Cost: per output i, for each joint k related to i, a constant amount of work plus
// O(size of k's subtree) pair work: at most O(n^2 d) (d: tree depth; a chain: ~n^3 / 2 pair
// evaluations, the order of the tensors' own size), plus zeroing the 4 n^3 entries; no
// allocation. docs/second_order.md, "The four tensors".
#pragma once

#include <array>

#include "arbor/derivatives/rnea_second_order.hpp"
#include "arbor/derivatives/second_order_data.hpp"

namespace arbor {

/// The second-order tensors of inverse dynamics for robot R and scalar Scalar_, and the
/// lambda-independent work arrays of rnea_second_order_tensors. Fixed size, default
/// constructible, no allocation (4 n^3 scalars of results: mind the stack for large robots).
///
/// Convention (Pinocchio's Tensor3x T(i, j, k), tau index i first; here slice [i], entry (j, k)):
///   - d2tau_dqdq[i](j, k) = d^2 tau_i / dq_j dq_k   (symmetric in j, k)
///   - d2tau_dvdv[i](j, k) = d^2 tau_i / dv_j dv_k   (symmetric in j, k; independent of a)
///   - d2tau_dqdv[i](j, k) = d^2 tau_i / dq_j dv_k   (q index j, v index k: the j-k block of
///     d/dv_k (dtau/dq), as Pinocchio's unit test builds it by finite differences in v)
///   - d2tau_dadq[i](j, k) = d^2 tau_i / da_j dq_k = d M(i, j) / dq_k   (independent of v, a)
/// The other second derivatives vanish (ID is linear in a).
template <class R, class Scalar_ = double>
struct SecondOrderTensors {
  static constexpr int nb = R::nb;  ///< bodies
  static constexpr int nv = R::nv;  ///< DoF
  using Scalar = Scalar_;
  using Tensor = std::array<MatN<Scalar, nv>, nv>;  ///< slice i: the (j, k) matrix of tau_i

  Tensor d2tau_dqdq;  ///< [i](j, k) = d^2 tau_i / dq_j dq_k
  Tensor d2tau_dvdv;  ///< [i](j, k) = d^2 tau_i / dv_j dv_k
  Tensor d2tau_dqdv;  ///< [i](j, k) = d^2 tau_i / dq_j dv_k
  Tensor d2tau_dadq;  ///< [i](j, k) = d^2 tau_i / da_j dq_k

  std::array<Inertia<Scalar>, nb> Y;                ///< composite inertias (world frame)
  std::array<spatial::InertiaRate<Scalar>, nb> Yd;  ///< subtree sums of v x* I - I v x
  std::array<Force<Scalar>, nb> h;                  ///< composite momenta sum I v
  std::array<Force<Scalar>, nb> F;                  ///< composite net forces sum I a + v x* I v
};

namespace detail {

/// Writes zero into column j of a RowBlock.
template <class Blk>
ARBOR_INLINE void tens_zero_col(Blk& blk, int j) {
  blk.col(j).setZero();
}

/// For output i, a joint k neither in i's subtree nor on its path contributes nothing: clears its
/// lambda-dependent columns Kt, Ka, Wv and returns true; false for the joints related to i.
template <class R, int k, class Scalar>
ARBOR_INLINE bool tens_clear_if_unrelated(SecondOrderData<R, Scalar>& s, int i) {
  if (model::support<R>[k][i] || model::support<R>[i][k])
    return false;
  tens_zero_col(s.Kt, k);
  tens_zero_col(s.Ka, k);
  tens_zero_col(s.Wv, k);
  return true;
}

/// For lambda = e_i and a joint k related to i: its lambda sums L, Ydm, N into s, in closed form
/// from the cached composites (mu_m = S_i on the whole subtree of k when k is in the subtree of
/// i; for a strict ancestor the sums are those of i, already formed since i > k), and its
/// dM = mu_parent x S_k as the result (S_i x S_k below i, k != i; zero otherwise).
template <class R, int k, class Scalar>
ARBOR_INLINE Motion<Scalar> tens_lambda_sums(SecondOrderData<R, Scalar>& s,
                                             const SecondOrderTensors<R, Scalar>& t, int i,
                                             const Motion<Scalar>& Si, const Motion<Scalar>& Sc) {
  using B = spatial::BodyOps<R, k, Scalar>;
  using W = WorldInertia<R, k, Scalar>;
  Motion<Scalar> dM = Motion<Scalar>::Zero();
  if (model::support<R>[k][i]) {  // k in the subtree of i (k = i included)
    if constexpr (B::parent >= 0) {
      if (k != i)  // mu_parent = S_i
        dM = cross_col<B>(Si, Sc);
    }
    s.L[k] = t.Y[k] * Si;
    s.Ydm[k] = W::rate(t.Y[k], Si);
    s.N[k] = t.Yd[k] * Si - spatial::cross(Si, t.h[k]);
  } else {  // a strict ancestor of i
    s.L[k] = s.L[i];
    s.Ydm[k] = s.Ydm[i];
    s.N[k] = s.N[i];
  }
  return dM;
}

/// Caches joint k's lambda-independent subtree sums (composites, after the lambda = 0 sweep).
template <class R, int k, class Scalar>
ARBOR_INLINE void tens_cache_body(const SecondOrderData<R, Scalar>& s,
                                  SecondOrderTensors<R, Scalar>& t) {
  t.Y[k] = s.Y[k];
  t.Yd[k] = s.Yd[k];
  t.h[k] = s.h[k];
  t.F[k] = s.F[k];
}

/// The backward step of joint k for lambda = e_i. Joints neither in the subtree of i nor
/// ancestors of i have L = N = Ydm = 0 and dM = 0, so their own Hessian entries vanish and their
/// Kt, Ka, Wv columns are zero (Km, Wm, P do not depend on lambda and stay from the lambda = 0
/// sweep): only those columns are cleared. For the others the subtree sums are closed forms of
/// the cached composites (mu_m = S_i on the whole subtree of k when k is in the subtree of i; the
/// sums of i itself when k is an ancestor), then the contracted backward step runs (whose
/// additions into the parent are overwritten when the parent's turn comes).
template <class R, int k, class Scalar>
ARBOR_INLINE void tens_backward_body(Data<R, Scalar>& d, SecondOrderData<R, Scalar>& s,
                                     const SecondOrderTensors<R, Scalar>& t, int i,
                                     const Motion<Scalar>& Si) {
  if (tens_clear_if_unrelated<R, k>(s, i))
    return;
  s.Y[k] = t.Y[k];
  s.Yd[k] = t.Yd[k];
  s.h[k] = t.h[k];
  s.F[k] = t.F[k];
  s.dM[k] = tens_lambda_sums<R, k>(s, t, i, Si, Motion<Scalar>::from(d.J.col(k)));
  so_backward_body<R, k>(d, s);
}

/// True when every subtree is a contiguous range of joints (depth-first numbering).
template <class R>
constexpr bool tens_depth_first() {
  for (int k = 0; k < R::nb; ++k)
    if (!model::subtree_contiguous<R>(k))
      return false;
  return true;
}

/// tens_backward_body for depth-first numberings, writing slice i of the tensors directly: only
/// the lambda-dependent forces Kt, Ka, Wv of joint k are formed (Km, Wm, P stay from the
/// lambda = 0 sweep, the composites in so are not accumulated again), then the pair sweeps of the
/// contracted backward step over the columns [k, last] of k's subtree, each entry stored where
/// the tensors' convention puts it.
template <class R, int k, class Scalar>
ARBOR_INLINE void tens_fast_body(const Data<R, Scalar>& d, SecondOrderData<R, Scalar>& s,
                                 SecondOrderTensors<R, Scalar>& t, int i,
                                 const Motion<Scalar>& Si) {
  using B = spatial::BodyOps<R, k, Scalar>;
  constexpr int last = model::subtree_last<R>(k);
  constexpr int Lc = last - k + 1;
  if (tens_clear_if_unrelated<R, k>(s, i))
    return;
  const Motion<Scalar> Sc = Motion<Scalar>::from(d.J.col(k));
  const Motion<Scalar>& dS = s.dS[k];
  const Motion<Scalar>& ddS = s.ddS[k];
  const Inertia<Scalar>& Y = t.Y[k];
  const spatial::InertiaRate<Scalar>& Yd = t.Yd[k];
  const Force<Scalar>& h = t.h[k];
  const Motion<Scalar> dM = tens_lambda_sums<R, k>(s, t, i, Si, Sc);
  const Force<Scalar>& Lm = s.L[k];
  const Force<Scalar>& Nk = s.N[k];
  const spatial::InertiaRate<Scalar>& Ydm = s.Ydm[k];
  const Force<Scalar> SxL = cross_col_force<B>(Sc, Lm);
  const Force<Scalar> Kt = Yd * dM - spatial::cross(dM, h) - Ydm * dS + cross_col_force<B>(Sc, Nk) +
                           spatial::cross(dS, Lm);
  const Force<Scalar> Ka = Y * dM + SxL;
  const Force<Scalar> Wv = SxL - Ydm * Sc;
  so_store(s.Kt, k, Kt);
  so_store(s.Ka, k, Ka);
  so_store(s.Wv, k, Wv);

  auto& Tqq = t.d2tau_dqdq[i];
  auto& Tvv = t.d2tau_dvdv[i];
  auto& Tqv = t.d2tau_dqdv[i];
  auto& Taq = t.d2tau_dadq[i];
  Eigen::Matrix<Scalar, 1, Lc> qq = row_dot<Lc, Scalar>(s.Ka, k, ddS.v, ddS.w);
  if constexpr (B::parent >= 0) {  // dM = dS = 0 at a root
    qq += row_dot<Lc, Scalar>(s.Km, k, dM.v, dM.w) + row_dot<Lc, Scalar>(s.Kt, k, dS.v, dS.w);
    // d2/dq_k dv_m and d2/dq_k da_m, m in [k, last]
    Tqv.row(k).template segment<Lc>(k) =
        row_dot<Lc, Scalar>(s.Wm, k, dM.v, dM.w) + row_dot<Lc, Scalar>(s.Wv, k, dS.v, dS.w);
    Taq.col(k).template segment<Lc>(k) = row_dot<Lc, Scalar>(s.P, k, dM.v, dM.w).transpose();
  }
  Tqq.row(k).template segment<Lc>(k) = qq;
  Tqq.col(k).template segment<Lc>(k) = qq.transpose();
  const Eigen::Matrix<Scalar, 1, Lc> vv = row_dot<Lc, Scalar>(s.Wv, k, Sc.v, Sc.w);
  Tvv.row(k).template segment<Lc>(k) = vv;
  Tvv.col(k).template segment<Lc>(k) = vv.transpose();
  if constexpr (Lc > 1) {
    // d2/dv_k dq_m and d2/da_k dq_m, m in (k, last]
    Eigen::Matrix<Scalar, 1, Lc - 1> vq = row_dot<Lc - 1, Scalar>(s.Kt, k + 1, Sc.v, Sc.w);
    if constexpr (B::parent >= 0) {
      const Vec3<Scalar> dSv2 = dS.v * Scalar(2), dSw2 = dS.w * Scalar(2);
      vq += row_dot<Lc - 1, Scalar>(s.Ka, k + 1, dSv2, dSw2);
    }
    Tqv.col(k).template segment<Lc - 1>(k + 1) = vq.transpose();
    Taq.row(k).template segment<Lc - 1>(k + 1) = row_dot<Lc - 1, Scalar>(s.Ka, k + 1, Sc.v, Sc.w);
  }
}

/// Zeros the blocks of so.hessian that tens_store_slice reads (q-q, v-v, q-v, a-q): the
/// backward steps leave the entries of unrelated pairs untouched.
template <class R, class Scalar>
ARBOR_INLINE void tens_clear_blocks(SecondOrderData<R, Scalar>& s) {
  constexpr int n = R::nv;
  s.hessian.template block<2 * n, 2 * n>(0, 0).setZero();
  s.hessian.template block<n, n>(2 * n, 0).setZero();
}

/// Copies the Hessian of tau_i (so.hessian, z = (q, v, a)) into slice i of the tensors.
template <class R, class Scalar>
ARBOR_INLINE void tens_store_slice(const SecondOrderData<R, Scalar>& s,
                                   SecondOrderTensors<R, Scalar>& t, int i) {
  constexpr int n = R::nv;
  const auto& H = s.hessian;
  t.d2tau_dqdq[i] = H.template block<n, n>(0, 0);
  t.d2tau_dvdv[i] = H.template block<n, n>(n, n);
  t.d2tau_dqdv[i] = H.template block<n, n>(0, n);
  t.d2tau_dadq[i] = H.template block<n, n>(2 * n, 0);
}

}  // namespace detail

/// The four second-order tensors of inverse dynamics tau = ID(q, v, a) with gravity g (world
/// frame) into tensors (convention in SecondOrderTensors). Uses so as work space (its contents
/// on return are work values, not a contracted Hessian). Also leaves data.tau = ID(q, v, a),
/// data.oMi and data.J (world joint columns). O(n^2 d) at most; no allocation.
template <Robot R, class Scalar, class Q, class V, class A>
void rnea_second_order_tensors(Data<R, Scalar>& data, SecondOrderData<R, Scalar>& so,
                               SecondOrderTensors<R, Scalar>& tensors,
                               const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                               const Eigen::MatrixBase<A>& a,
                               const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, A>();
  detail::joint_states(data, q);
  const VecN<Scalar, R::nv> zero = VecN<Scalar, R::nv>::Zero();
  // the lambda-independent quantities, once: a contracted sweep with lambda = 0 (mu, dM, L, N,
  // Ydm vanish) leaves the composites Y, Yd, h, F, the columns Km, Wm, P, zero Kt, Ka, Wv, and
  // data.tau
  so.hessian.setZero();
  static_for<R::nb>([&](auto K) {
    detail::so_forward_body<R, decltype(K)::value, false>(data, so, v, a, zero, g);
  });
  if (data.payload.active)
    detail::so_forward_payload(data, so);
  static_for_reverse<R::nb>(
      [&](auto K) { detail::so_backward_body<R, decltype(K)::value>(data, so); });
  static_for<R::nb>([&](auto K) { detail::tens_cache_body<R, decltype(K)::value>(so, tensors); });
  for (int i = 0; i < R::nv; ++i) {
    const Motion<Scalar> Si = Motion<Scalar>::from(data.J.col(i));
    if constexpr (detail::tens_depth_first<R>()) {
      tensors.d2tau_dqdq[i].setZero();
      tensors.d2tau_dvdv[i].setZero();
      tensors.d2tau_dqdv[i].setZero();
      tensors.d2tau_dadq[i].setZero();
      static_for_reverse<R::nb>(
          [&](auto K) { detail::tens_fast_body<R, decltype(K)::value>(data, so, tensors, i, Si); });
    } else {
      detail::tens_clear_blocks(so);
      static_for_reverse<R::nb>([&](auto K) {
        detail::tens_backward_body<R, decltype(K)::value>(data, so, tensors, i, Si);
      });
      detail::tens_store_slice(so, tensors, i);
    }
  }
}

}  // namespace arbor
