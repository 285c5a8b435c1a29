// arbor: first-order analytical derivatives of forward dynamics ddq = FD(q, v, tau), reusing
// M^-1 and the inverse-dynamics derivatives as Carpentier & Mansard (RSS 2018) do: at
// ddq = FD(q, v, tau), ID(q, v, ddq) = tau holds identically, so
//   d ddq / d q = -M^-1 d tau / d q,   d ddq / d v = -M^-1 d tau / d v,   d ddq / d tau = M^-1,
// with the ID derivatives evaluated at (q, v, ddq). The forward dynamics themselves come out of
// the same sweep: with the velocity part of the world-frame pass done, the composite forces at
// zero joint acceleration give the nonlinear effects nle, ddq = M^-1 (tau - nle) uses the M^-1
// that the derivatives need anyway, and a forward fix-up adds the accelerations of ddq before
// the derivative pass runs (no separate aba).
// M^-1 shares the sweep: for depth-first trees the nle pass also accumulates the world composite
// inertias and forms M (the columns P = Ycrb S that the derivative pass needs anyway), and M^-1
// comes from M's tree-structured L'DL factorisation (minverse_from_mass_matrix: no fill-in,
// O(n d^2)), cheaper than a separate articulated-body minverse with its own placements (about a
// fifth of the call's instructions on the Kinova, bench/derivatives/RESULTS.md). Other numberings
// use minverse.
#pragma once

#include <array>

#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/dynamics/minverse.hpp"

namespace arbor {

namespace detail {

/// Whether aba_derivatives forms M in its nle pass and M^-1 from it (minverse_from_mass_matrix)
/// instead of running minverse's articulated-body recursion: for trees numbered depth-first
/// (every subtree's columns contiguous, as the M rows are written).
template <class R>
constexpr bool fuse_minverse() {
  for (int i = 0; i < R::nb; ++i)
    if (!model::subtree_contiguous<R>(i))
      return false;
  return true;
}

/// [first, last] joint of the tree of each joint's root joint (M^-1 and the derivative matrices
/// are zero between the trees of different root joints, e.g. the YuMi's two arms); the whole
/// range when the numbering is not depth-first.
template <class R>
inline constexpr std::array<std::array<int, 2>, R::nv> root_tree = [] {
  std::array<std::array<int, 2>, R::nv> t{};
  for (int j = 0; j < R::nv; ++j) {
    int r = j;
    while (R::parent[r] >= 0)
      r = R::parent[r];
    t[j] = {fuse_minverse<R>() ? r : 0, fuse_minverse<R>() ? model::subtree_last<R>(r) : R::nv - 1};
  }
  return t;
}();

/// data.ddq_dq = -Minv dtau_dq and data.ddq_dv = -Minv dtau_dv, skipping the structural zeros
/// of the derivative matrices (pairs of joints on different branches).
template <class R, class Scalar>
ARBOR_INLINE void minus_minv_times_derivatives(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd) {
  constexpr int n = R::nv;
  if constexpr (n < 4) {
    // tiny: dense coefficient-based products
    dd.ddq_dq.noalias() = -d.Minv.lazyProduct(dd.dtau_dq);
    dd.ddq_dv.noalias() = -d.Minv.lazyProduct(dd.dtau_dv);
    return;
  } else if constexpr (n < 12) {
    // small: both dense products in one sweep over the columns of M^-1 (each loaded once for the
    // two; fewer instructions than two lazy products or the skipping loop)
    using Col = Eigen::Matrix<Scalar, n, 1>;
    for (int j = 0; j < n; ++j) {
      Col oq = d.Minv.col(0) * (-dd.dtau_dq(0, j));
      Col ov = d.Minv.col(0) * (-dd.dtau_dv(0, j));
      for (int k = 1; k < n; ++k) {
        oq -= d.Minv.col(k) * dd.dtau_dq(k, j);
        ov -= d.Minv.col(k) * dd.dtau_dv(k, j);
      }
      dd.ddq_dq.col(j) = oq;
      dd.ddq_dv.col(j) = ov;
    }
    return;
  }
  if constexpr (fuse_minverse<R>()) {
    // Depth-first forest: M^-1 and the derivative matrices are block diagonal over the trees of
    // the root joints. A tree of fewer than 12 joints (the YuMi's arms, the Atlas's legs) gets a
    // dense product on its block with compile-time bounds (plain loops, which GCC unrolls and
    // vectorises: Eigen's unaligned fixed-size segments went through its generic assignment loops
    // out of line); a larger tree visits only the joints on a branch with column j.
    const Scalar* Mi = d.Minv.data();  // column-major: column k at Mi + k n
    static_for<n>([&](auto Root) {
      constexpr int r0 = decltype(Root)::value;
      if constexpr (R::parent[r0] < 0) {
        constexpr int r1 = model::subtree_last<R>(r0);
        constexpr int m = r1 - r0 + 1;
        for (int j = r0; j <= r1; ++j) {
          Scalar aq[m], av[m];
          for (int r = 0; r < m; ++r) {
            aq[r] = Scalar(0);
            av[r] = Scalar(0);
          }
          for (int k = r0; k <= r1; ++k) {
            if constexpr (m >= 12) {
              if (!model::on_branch<R>[k][j])
                continue;
            }
            const Scalar cq = dd.dtau_dq(k, j), cv = dd.dtau_dv(k, j);
            const Scalar* mk = Mi + k * n + r0;
            for (int r = 0; r < m; ++r) {
              aq[r] -= mk[r] * cq;
              av[r] -= mk[r] * cv;
            }
          }
          Scalar* oq = dd.ddq_dq.data() + j * n;
          Scalar* ov = dd.ddq_dv.data() + j * n;
          for (int r = 0; r < r0; ++r) {
            oq[r] = Scalar(0);
            ov[r] = Scalar(0);
          }
          for (int r = 0; r < m; ++r) {
            oq[r0 + r] = aq[r];
            ov[r0 + r] = av[r];
          }
          for (int r = r1 + 1; r < n; ++r) {
            oq[r] = Scalar(0);
            ov[r] = Scalar(0);
          }
        }
      }
    });
    return;
  }
  // Other numberings: rows limited to the tree of j's root joint (root_tree).
  constexpr auto& tree = root_tree<R>;
  const Scalar* Mi = d.Minv.data();  // column-major: column k at Mi + k n
  for (int j = 0; j < n; ++j) {
    Scalar* oq = dd.ddq_dq.data() + j * n;
    Scalar* ov = dd.ddq_dv.data() + j * n;
    for (int r = 0; r < n; ++r) {
      oq[r] = Scalar(0);
      ov[r] = Scalar(0);
    }
    const int r0 = tree[j][0], r1 = tree[j][1];
    for (int k = 0; k < n; ++k) {
      if (!model::on_branch<R>[k][j])
        continue;
      const Scalar cq = dd.dtau_dq(k, j), cv = dd.dtau_dv(k, j);
      const Scalar* mk = Mi + k * n;
      for (int r = r0; r <= r1; ++r) {
        oq[r] -= mk[r] * cq;
        ov[r] -= mk[r] * cv;
      }
    }
  }
}

/// The payload's terms of aba_derivatives' first pass (at ddq = 0) on its body, with their copies
/// in data.f and (Fused) data.Ycrb. Out of line (called only with a payload).
template <bool Fused, class R, class Scalar>
ARBOR_NOINLINE void aba_deriv_payload(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd) {
  const int b = d.payload.body;
  deriv_forward_payload(d, dd);
  d.f[b] = dd.of[b];
  if constexpr (Fused)
    d.Ycrb[b] = dd.oYcrb[b];
}

/// The fix-up's inertial force of the payload on a body without mass of its own (whose term the
/// fix-up skips at compile time; its oYcrb holds the payload alone). Out of line.
template <class R, class Scalar>
ARBOR_NOINLINE void aba_deriv_payload_fixup(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd) {
  const int b = d.payload.body;
  if (body_massless<R>(b))
    dd.of[b] += dd.oYcrb[b] * d.a[b];
}

/// aba_derivatives at (q, v, tau): see the file comment.
template <class R, bool HasFext, class Scalar, class Q, class V, class T>
ARBOR_INLINE void aba_derivatives_impl(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd,
                                       const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                                       const Eigen::MatrixBase<T>& tau, const Vec3<Scalar>& g,
                                       const typename Data<R, Scalar>::ForceArray* fext) {
  // Per-body passes flattened for floating-point scalars (static_for_flat).
  constexpr bool flat = std::is_floating_point_v<Scalar>;
  constexpr bool fused = fuse_minverse<R>();
  if constexpr (fused)
    joint_states(d, q);
  else
    minverse<R>(d, q);  // also the joint states
  // Velocity part and the accelerations at ddq = 0; composite forces at ddq = 0 in data.f.
  static_for_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    deriv_forward_velocity<R, i, HasFext>(d, dd, v, fext);
    deriv_forward_acceleration<R, i>(d, dd, v, Data<R, Scalar>::Vector::Zero(), g);
    d.f[i] = dd.of[i];
    if constexpr (fused)
      d.Ycrb[i] = dd.oYcrb[i];
  });
  if (d.payload.active)  // the payload's terms at ddq = 0 on its body
    aba_deriv_payload<fused>(d, dd);
  // nle from the composite forces; fused: also the world composite inertias (data.Ycrb), their
  // joint columns P = Ycrb S (deriv.dP, reused by the derivative pass) and M.
  static_for_reverse_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    const Motion<Scalar> Sc = Motion<Scalar>::from(d.J.col(i));
    d.tau[i] = spatial::dot(d.f[i], Sc);  // nle_i
    if constexpr (B::parent >= 0)
      d.f[B::parent] += d.f[i];
    if constexpr (fused) {
      constexpr int n = R::nv;
      constexpr int last = model::subtree_last<R>(i);
      constexpr int L = last - i + 1;
      const Force<Scalar> P = d.Ycrb[i] * Sc;
      for (int c = 0; c < 3; ++c) {
        dd.dP(c, i) = P.f[c];
        dd.dP(3 + c, i) = P.n[c];
      }
      const auto mrow = row_dot<L, Scalar>(dd.dP, i, Sc.v, Sc.w);
      d.M.row(i).template segment<L>(i) = mrow;
      d.M.col(i).template segment<L>(i) = mrow.transpose();
      if constexpr (last + 1 < n) {
        d.M.row(i).template tail<n - last - 1>().setZero();
        d.M.col(i).template tail<n - last - 1>().setZero();
      }
      if constexpr (B::parent >= 0)
        d.Ycrb[B::parent] += d.Ycrb[i];
    }
  });
  if constexpr (fused)  // deriv.ddq_dq as scratch (written last)
    minverse_from_mass_matrix<R>(d.M, dd.ddq_dq, d.Minv);
  d.ddq.noalias() = d.Minv * (tau.template cast<Scalar>() - d.tau);
  // Fix-up: world accelerations of ddq (data.a holds their increments), ddS and forces.
  static_for_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    const Motion<Scalar> Sc = Motion<Scalar>::from(d.J.col(i));
    if constexpr (B::parent < 0) {
      d.a[i] = Sc * d.ddq[i];
    } else {
      const Motion<Scalar>& dap = d.a[B::parent];
      d.a[i] = dap + Sc * d.ddq[i];
      dd.ddS[i] += cross_col<B>(dap, Sc);
    }
    dd.oa[i] += d.a[i];
    if constexpr (!WorldInertia<R, i, Scalar>::massless)
      dd.of[i] += dd.oYcrb[i] * d.a[i];
  });
  // a payload on a body without mass of its own (skipped above): oYcrb holds the payload alone
  if (d.payload.active)
    aba_deriv_payload_fixup(d, dd);
  static_for_reverse_flat<R::nb, flat>(
      [&](auto I) { deriv_backward_body<R, decltype(I)::value, false, Scalar, fused>(d, dd); });
  minus_minv_times_derivatives(d, dd);
}

}  // namespace detail

/// Derivatives of forward dynamics with gravity g (world frame): data.ddq = FD(q, v, tau),
/// deriv.ddq_dq = d ddq / d q, deriv.ddq_dv = d ddq / d v, data.Minv = d ddq / d tau (full
/// symmetric). Also leaves deriv.dtau_dq and deriv.dtau_dv at (q, v, ddq) and (depth-first
/// trees) data.M, and uses data.a, data.f and data.Ycrb (world frame) as scratch. O(n d) sweeps,
/// M^-1 from M in O(n d^2) + O(sum of subtree sizes squared), and two n x n products.
template <Robot R, class Scalar, class Q, class V, class T>
void aba_derivatives(Data<R, Scalar>& data, DerivativeData<R, Scalar>& deriv,
                     const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                     const Eigen::MatrixBase<T>& tau,
                     const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, T>();
  detail::aba_derivatives_impl<R, false>(data, deriv, q, v, tau, g, nullptr);
}

/// aba_derivatives with external forces fext (one per body, body frame, held fixed in the body
/// frames).
template <Robot R, class Scalar, class Q, class V, class T>
void aba_derivatives(Data<R, Scalar>& data, DerivativeData<R, Scalar>& deriv,
                     const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                     const Eigen::MatrixBase<T>& tau, const Vec3<Scalar>& g,
                     const ForceArray<R, Scalar>& fext) {
  detail::check_sizes<R, Q, V, T>();
  detail::aba_derivatives_impl<R, true>(data, deriv, q, v, tau, g, &fext);
}

}  // namespace arbor
