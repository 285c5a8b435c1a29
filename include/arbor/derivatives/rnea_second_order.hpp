// arbor: contracted second-order derivatives of inverse dynamics: the Hessian of
// phi = lambda' ID(q, v, a) with respect to z = (q, v, a) (3n x 3n, symmetric), and its gradient,
// without forming the n x n x n tensors. Cost O(n d) (d: tree depth), like rnea_derivatives: one
// forward and one backward world-frame sweep, then ten 6-vector dot products per pair of joints
// on one branch. Derivation in docs/second_order.md; summary:
//
// phi = sum_k mu_k . f_k, with mu_k = sum_{i <= k} lambda_i S_i the velocity of body k for joint
// rates lambda and f_k = I_k a_k + v_k x* I_k v_k (world frame, a_0 = -g). The subtree of joint
// j depends on q_j only through its rotation relative to the parent body p, so d phi / d q_j, and
// d phi / d v_j, are invariant functions psi_j, omega_j of the parent's motion B = (mu_p, v_p,
// a_p) and of the subtree. An ancestor i of j changes B by, beyond the common rotation that the
// invariance removes,
//   q_i: (dM_i, dS_i, a_p(i) x S_i + dS_i x (v_p(j) - v_p(i))),  v_i: (0, S_i, dS_i + S_i x
//   (v_p(j) - v_i)),  a_i: (0, 0, S_i),
// with dS_i = v_p(i) x S_i, dM_i = mu_p(i) x S_i. So each Hessian entry of a pair i <= j is the
// dot product of B-gradients of psi_j, omega_j (forces Km, Kv, Ka, Wm, Wv, P of joint j, built
// from the subtree sums Y, Yd, Ydm, h, L, N, F) with motions of joint i (dM, dS, ddS, S):
//   d2phi/dq_i dq_j = Km_j . dM_i + Kt_j . dS_i + Ka_j . ddS_i    (i <= j)
//   d2phi/dq_i dv_j = Wm_j . dM_i + Wv_j . dS_i                    (i <= j)
//   d2phi/dq_i da_j = P_j . dM_i                                   (i <= j)
//   d2phi/dv_i dq_j = Kt_j . S_i + 2 Ka_j . dS_i                   (i < j)
//   d2phi/dv_i dv_j = Wv_j . S_i                                   (i <= j)
//   d2phi/da_i dq_j = Ka_j . S_i                                   (i < j)
// and zero for a-a, a-v, and pairs on different branches.
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/derivatives/second_order_data.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/jacobian.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"

namespace arbor {

namespace detail {

/// Forward pass for body i: placement and world column (unless Placed: data.oMi and data.J
/// already hold them), velocities for v and lambda, acceleration, the joint motions dS, dM,
/// ddS, and the body's own terms of the subtree sums.
template <class R, int i, bool Placed, class Scalar, class V, class A, class L>
ARBOR_INLINE void so_forward_body(Data<R, Scalar>& d, SecondOrderData<R, Scalar>& s,
                                  const Eigen::MatrixBase<V>& v, const Eigen::MatrixBase<A>& a,
                                  const Eigen::MatrixBase<L>& lambda, const Vec3<Scalar>& g) {
  using B = spatial::BodyOps<R, i, Scalar>;
  using W = WorldInertia<R, i, Scalar>;
  Motion<Scalar> Sc;
  if constexpr (Placed) {
    Sc = Motion<Scalar>::from(d.J.col(i));
  } else {
    body_placement<R, i, Scalar>(d);
    Sc = world_column<R, i, Scalar>(d);
    d.J.col(i) << Sc.v, Sc.w;
  }
  const Scalar vi = Scalar(v[i]), ai = Scalar(a[i]), li = Scalar(lambda[i]);
  if constexpr (B::parent < 0) {
    s.dS[i] = Motion<Scalar>::Zero();
    s.dM[i] = Motion<Scalar>::Zero();
    // a_p = (-g, 0): a_p x S = [-g x S.w; 0] = [S.w x g; 0]
    if constexpr (B::revolute)
      s.ddS[i] = {Sc.w.cross(g), Vec3<Scalar>::Zero()};
    else
      s.ddS[i] = Motion<Scalar>::Zero();
    s.ov[i] = Sc * vi;
    s.omu[i] = Sc * li;
    s.oa[i] = {Sc.v * ai - g, Sc.w * ai};
  } else {
    constexpr int p = B::parent;
    const Motion<Scalar>& vp = s.ov[p];
    s.dS[i] = cross_col<B>(vp, Sc);
    s.dM[i] = cross_col<B>(s.omu[p], Sc);
    s.ddS[i] = cross_col<B>(s.oa[p], Sc) + spatial::cross(vp, s.dS[i]);
    s.ov[i] = vp + Sc * vi;
    s.omu[i] = s.omu[p] + Sc * li;
    s.oa[i] = s.oa[p] + s.dS[i] * vi + Sc * ai;
  }
  if constexpr (W::massless) {
    s.Y[i] = Inertia<Scalar>::Zero();
    s.Yd[i] = spatial::InertiaRate<Scalar>::Zero();
    s.Ydm[i] = spatial::InertiaRate<Scalar>::Zero();
    s.h[i] = Force<Scalar>::Zero();
    s.L[i] = Force<Scalar>::Zero();
    s.N[i] = Force<Scalar>::Zero();
    s.F[i] = Force<Scalar>::Zero();
  } else {
    const Inertia<Scalar> I = W::of(d.oMi[i]);
    const Motion<Scalar>& vk = s.ov[i];
    const Motion<Scalar>& mk = s.omu[i];
    s.Y[i] = I;
    s.h[i] = I * vk;
    s.L[i] = I * mk;
    s.F[i] = I * s.oa[i] + spatial::cross(vk, s.h[i]);
    s.Yd[i] = W::rate(I, vk);
    s.Ydm[i] = W::rate(I, mk);
    s.N[i] = spatial::cross(vk, s.L[i]) - spatial::cross(mk, s.h[i]) - I * spatial::cross(vk, mk);
  }
}

/// A payload's terms of the subtree sums, added to its body's after the forward pass (the same
/// expressions as so_forward_body's with the payload's world inertia). Out of line.
template <class R, class Scalar>
ARBOR_NOINLINE void so_forward_payload(Data<R, Scalar>& d, SecondOrderData<R, Scalar>& s) {
  const int b = d.payload.body;
  const Inertia<Scalar> I = payload_world(d);
  const Motion<Scalar>& vk = s.ov[b];
  const Motion<Scalar>& mk = s.omu[b];
  const Force<Scalar> h = I * vk, L = I * mk;
  s.Y[b] += I;
  s.h[b] += h;
  s.L[b] += L;
  s.F[b] += I * s.oa[b] + spatial::cross(vk, h);
  s.Yd[b] += sx::rate(I, vk);
  s.Ydm[b] += sx::rate(I, mk);
  s.N[b] += spatial::cross(vk, L) - spatial::cross(mk, h) - I * spatial::cross(vk, mk);
}

/// Writes the 6-vector x into column j of a RowBlock.
template <class Blk, class Scalar>
ARBOR_INLINE void so_store(Blk& blk, int j, const Force<Scalar>& x) {
  for (int c = 0; c < 3; ++c) {
    blk(c, j) = x.f[c];
    blk(3 + c, j) = x.n[c];
  }
}

/// The entries of the pair (i, j) for one j of the subtree of i (j >= i), the general path.
template <class R, int i, int j, class Scalar>
ARBOR_INLINE void so_pair(SecondOrderData<R, Scalar>& s, const Motion<Scalar>& Sc) {
  constexpr int n = R::nv;
  auto& H = s.hessian;
  const Motion<Scalar>& dM = s.dM[i];
  const Motion<Scalar>& dS = s.dS[i];
  const Motion<Scalar>& E = s.ddS[i];
  const Scalar qq = row_dot<1, Scalar>(s.Km, j, dM.v, dM.w)[0] +
                    row_dot<1, Scalar>(s.Kt, j, dS.v, dS.w)[0] +
                    row_dot<1, Scalar>(s.Ka, j, E.v, E.w)[0];
  const Scalar qv =
      row_dot<1, Scalar>(s.Wm, j, dM.v, dM.w)[0] + row_dot<1, Scalar>(s.Wv, j, dS.v, dS.w)[0];
  const Scalar qa = row_dot<1, Scalar>(s.P, j, dM.v, dM.w)[0];
  const Scalar vv = row_dot<1, Scalar>(s.Wv, j, Sc.v, Sc.w)[0];
  H(i, j) = qq;
  H(j, i) = qq;
  H(i, n + j) = qv;
  H(n + j, i) = qv;
  H(i, 2 * n + j) = qa;
  H(2 * n + j, i) = qa;
  H(n + i, n + j) = vv;
  H(n + j, n + i) = vv;
  if constexpr (j > i) {
    const Vec3<Scalar> dSv2 = dS.v * Scalar(2), dSw2 = dS.w * Scalar(2);
    const Scalar vq =
        row_dot<1, Scalar>(s.Kt, j, Sc.v, Sc.w)[0] + row_dot<1, Scalar>(s.Ka, j, dSv2, dSw2)[0];
    const Scalar aq = row_dot<1, Scalar>(s.Ka, j, Sc.v, Sc.w)[0];
    H(n + i, j) = vq;
    H(j, n + i) = vq;
    H(2 * n + i, j) = aq;
    H(j, 2 * n + i) = aq;
  }
}

/// Backward pass for body j: the B-gradient forces of joint j, the gradient entries, the Hessian
/// entries of every pair (j, k) with k in the subtree of j, and the sums handed to the parent.
template <class R, int j, class Scalar>
ARBOR_INLINE void so_backward_body(Data<R, Scalar>& d, SecondOrderData<R, Scalar>& s) {
  using B = spatial::BodyOps<R, j, Scalar>;
  constexpr int n = R::nv;
  constexpr int last = model::subtree_last<R>(j);
  constexpr int Lc = last - j + 1;
  const Motion<Scalar> Sc = Motion<Scalar>::from(d.J.col(j));
  const Motion<Scalar>& dS = s.dS[j];
  const Motion<Scalar>& dM = s.dM[j];
  const Inertia<Scalar>& Y = s.Y[j];
  const spatial::InertiaRate<Scalar>& Yd = s.Yd[j];
  const spatial::InertiaRate<Scalar>& Ydm = s.Ydm[j];
  const Force<Scalar>& h = s.h[j];
  const Force<Scalar>& Lm = s.L[j];
  const Force<Scalar>& Nj = s.N[j];
  const Force<Scalar>& F = s.F[j];

  // value and gradient
  d.tau[j] = spatial::dot(F, Sc);
  const Force<Scalar> SxL = cross_col_force<B>(Sc, Lm);
  s.gradient[j] = spatial::dot(F, dM) + spatial::dot(Nj, dS) + spatial::dot(Lm, s.ddS[j]);
  s.gradient[n + j] = Scalar(2) * spatial::dot(Lm, dS) + spatial::dot(Nj, Sc);
  s.gradient[2 * n + j] = spatial::dot(Lm, Sc);

  // B-gradients of psi_j, omega_j, chi_j
  const Force<Scalar> YdM = Y * dM;
  const Force<Scalar> Km =
      cross_col_force<B>(Sc, F) + Yd * dS + spatial::cross(dS, h) + Y * s.ddS[j];
  const Force<Scalar> Kt = Yd * dM - spatial::cross(dM, h) - Ydm * dS + cross_col_force<B>(Sc, Nj) +
                           spatial::cross(dS, Lm);
  const Force<Scalar> Ka = YdM + SxL;
  const Force<Scalar> Wm = Y * dS * Scalar(2) + Yd * Sc + cross_col_force<B>(Sc, h);
  const Force<Scalar> Wv = SxL - Ydm * Sc;
  const Force<Scalar> P = Y * Sc;
  so_store(s.Km, j, Km);
  so_store(s.Kt, j, Kt);
  so_store(s.Ka, j, Ka);
  so_store(s.Wm, j, Wm);
  so_store(s.Wv, j, Wv);
  so_store(s.P, j, P);

  // pairs (j, k), k in the subtree of j
  if constexpr (model::subtree_contiguous<R>(j)) {
    // the subtree's columns [j, last] at once, as row vectors (k = j included)
    auto& H = s.hessian;
    const Motion<Scalar>& ddS = s.ddS[j];
    Eigen::Matrix<Scalar, 1, Lc> qq = row_dot<Lc, Scalar>(s.Ka, j, ddS.v, ddS.w);
    if constexpr (B::parent >= 0) {  // dM = dS = 0 at the root
      qq += row_dot<Lc, Scalar>(s.Km, j, dM.v, dM.w) + row_dot<Lc, Scalar>(s.Kt, j, dS.v, dS.w);
      const Eigen::Matrix<Scalar, 1, Lc> qv =
          row_dot<Lc, Scalar>(s.Wm, j, dM.v, dM.w) + row_dot<Lc, Scalar>(s.Wv, j, dS.v, dS.w);
      const Eigen::Matrix<Scalar, 1, Lc> qa = row_dot<Lc, Scalar>(s.P, j, dM.v, dM.w);
      H.row(j).template segment<Lc>(n + j) = qv;
      H.col(j).template segment<Lc>(n + j) = qv.transpose();
      H.row(j).template segment<Lc>(2 * n + j) = qa;
      H.col(j).template segment<Lc>(2 * n + j) = qa.transpose();
    }
    H.row(j).template segment<Lc>(j) = qq;
    H.col(j).template segment<Lc>(j) = qq.transpose();
    const Eigen::Matrix<Scalar, 1, Lc> vv = row_dot<Lc, Scalar>(s.Wv, j, Sc.v, Sc.w);
    H.row(n + j).template segment<Lc>(n + j) = vv;
    H.col(n + j).template segment<Lc>(n + j) = vv.transpose();
    if constexpr (Lc > 1) {
      const Vec3<Scalar> dSv2 = dS.v * Scalar(2), dSw2 = dS.w * Scalar(2);
      Eigen::Matrix<Scalar, 1, Lc - 1> vq = row_dot<Lc - 1, Scalar>(s.Kt, j + 1, Sc.v, Sc.w);
      if constexpr (B::parent >= 0)
        vq += row_dot<Lc - 1, Scalar>(s.Ka, j + 1, dSv2, dSw2);
      const Eigen::Matrix<Scalar, 1, Lc - 1> aq = row_dot<Lc - 1, Scalar>(s.Ka, j + 1, Sc.v, Sc.w);
      H.row(n + j).template segment<Lc - 1>(j + 1) = vq;
      H.col(n + j).template segment<Lc - 1>(j + 1) = vq.transpose();
      H.row(2 * n + j).template segment<Lc - 1>(j + 1) = aq;
      H.col(2 * n + j).template segment<Lc - 1>(j + 1) = aq.transpose();
    }
  } else {
    // a numbering that is topological but not depth-first: each member of the subtree alone
    static_for<Lc>([&](auto K) {
      constexpr int k = j + decltype(K)::value;
      if constexpr (model::support<R>[k][j])
        so_pair<R, j, k>(s, Sc);
    });
  }

  if constexpr (B::parent >= 0) {
    constexpr int p = B::parent;
    s.Y[p] += Y;
    s.Yd[p] += Yd;
    s.Ydm[p] += Ydm;
    s.h[p] += h;
    s.L[p] += Lm;
    s.N[p] += Nj;
    s.F[p] += F;
  }
}

/// The whole second-order sweep at (q, v, a) with multipliers lambda.
template <class R, bool Placed, class Scalar, class Q, class V, class A, class L>
ARBOR_INLINE void rnea_second_order_impl(Data<R, Scalar>& d, SecondOrderData<R, Scalar>& s,
                                         const Eigen::MatrixBase<Q>& q,
                                         const Eigen::MatrixBase<V>& v,
                                         const Eigen::MatrixBase<A>& a,
                                         const Eigen::MatrixBase<L>& lambda,
                                         const Vec3<Scalar>& g) {
  if constexpr (!Placed)
    joint_states(d, q);
  else
    (void)q;
  s.hessian.setZero();
  static_for<R::nb>(
      [&](auto I) { so_forward_body<R, decltype(I)::value, Placed>(d, s, v, a, lambda, g); });
  if (d.payload.active)
    so_forward_payload(d, s);
  static_for_reverse<R::nb>([&](auto I) { so_backward_body<R, decltype(I)::value>(d, s); });
}

}  // namespace detail

/// Contracted second-order derivatives of inverse dynamics tau = ID(q, v, a) with gravity g
/// (world frame), for multipliers lambda: so.hessian = d^2 (lambda' ID) / dz^2 with z = (q, v, a)
/// (3n x 3n, full symmetric; the a-a and a-v blocks are zero), so.gradient = d (lambda' ID) / dz
/// and data.tau = ID(q, v, a). Also leaves data.oMi and data.J (world joint columns). O(n d); no
/// allocation.
template <Robot R, class Scalar, class Q, class V, class A, class L>
void rnea_second_order_derivatives(Data<R, Scalar>& data, SecondOrderData<R, Scalar>& so,
                                   const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                                   const Eigen::MatrixBase<A>& a,
                                   const Eigen::MatrixBase<L>& lambda,
                                   const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, A>();
  static_assert(L::RowsAtCompileTime == R::nv && L::ColsAtCompileTime == 1,
                "lambda must be a column vector of R::nv entries");
  detail::rnea_second_order_impl<R, false>(data, so, q, v, a, lambda, g);
}

}  // namespace arbor
