// arbor: the actions of body i (BodyOps) written out scalar by scalar for joints about a
// coordinate axis (namespace detail::sx, next to the products of spatial/sx.hpp): its placement
// on motions and forces, its constant inertia times a motion, the joint's subspace. Structural
// zeros and +-1 of the constant placement and inertia are removed at compile time (cst::
// add_scaled), each coordinate is one chain of multiply-adds, and nothing goes through Eigen's
// vectorised 3-vector expressions, whose pairing of scalars cost as many shuffles as arithmetic
// (bench/RESULTS.md, issue 17). Other joints use BodyOps' own actions.
#pragma once

#include <bit>
#include <type_traits>

#include "arbor/core/config.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/spatial/body_ops.hpp"
#include "arbor/spatial/constant.hpp"
#include "arbor/spatial/sx.hpp"

namespace arbor::detail::sx {

/// acc + (row r of the constant K) . (x0, x1, x2), term by term (zeros skipped); T the scalar
/// S or a row vector of S (column blocks).
template <class S, class K, int r, class T>
ARBOR_INLINE T add_row(T acc, const T& x0, const T& x1, const T& x2) {
  namespace c = spatial::cst;
  c::add_scaled<S, c::Entry<K, r, 0>>(acc, x0);
  c::add_scaled<S, c::Entry<K, r, 1>>(acc, x1);
  c::add_scaled<S, c::Entry<K, r, 2>>(acc, x2);
  return acc;
}
/// acc - (row r of the constant K) . (x0, x1, x2).
template <class S, class K, int r, class T>
ARBOR_INLINE T sub_row(T acc, const T& x0, const T& x1, const T& x2) {
  namespace c = spatial::cst;
  c::add_scaled<S, c::Neg<c::Entry<K, r, 0>>>(acc, x0);
  c::add_scaled<S, c::Neg<c::Entry<K, r, 1>>>(acc, x1);
  c::add_scaled<S, c::Neg<c::Entry<K, r, 2>>>(acc, x2);
  return acc;
}
/// (row r of the constant K) . (x0, x1, x2).
template <class S, class K, int r, class T>
ARBOR_INLINE T krow(const T& x0, const T& x1, const T& x2) {
  if constexpr (std::is_same_v<T, S>)
    return spatial::cst::row<S, K, r>(x0, x1, x2, [] { return S(0); });
  else
    return spatial::cst::row<S, K, r>(x0, x1, x2, [] { return T(T::Zero()); });
}

/// A 3x3 matrix as nine scalars whose structurally zero entries are known at compile time: bit
/// 3 r + c of Nz clear means entry (r, c) is zero (never written, never read).
template <class S, unsigned Nz>
struct SMat {
  static constexpr unsigned nz = Nz;
  static constexpr bool at(int r, int c) { return (Nz >> (3 * r + c)) & 1u; }
  S e[3][3];
};
constexpr bool nz_bit(unsigned nz, int r, int c) {
  return (nz >> (3 * r + c)) & 1u;
}

/// Entry types for K M (left) and M K^T (right) over the nonzero entries of M only.
template <class K, unsigned Nz, int r, int c, int j>
struct LeftEntry {  // K(r, j) M(j, c)
  static constexpr double v = nz_bit(Nz, j, c) ? K::at(r, j) : 0.0;
};
template <class K, unsigned Nz, int r, int c, int j>
struct RightEntry {  // M(r, j) K(c, j)
  static constexpr double v = nz_bit(Nz, r, j) ? K::at(c, j) : 0.0;
};
template <class K>
constexpr unsigned left_nz(unsigned nz) {
  unsigned out = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j)
        if (K::at(r, j) != 0.0 && nz_bit(nz, j, c))
          out |= 1u << (3 * r + c);
  return out;
}
template <class K>
constexpr unsigned right_nz(unsigned nz) {
  unsigned out = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j)
        if (K::at(c, j) != 0.0 && nz_bit(nz, r, j))
          out |= 1u << (3 * r + c);
  return out;
}
/// The transpose of a mask, and a mask made symmetric.
constexpr unsigned transpose_nz(unsigned nz) {
  unsigned out = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (nz_bit(nz, c, r))
        out |= 1u << (3 * r + c);
  return out;
}

/// K M for a constant K; Sym: the result is known symmetric, entries r > c copied.
template <class K, bool Sym = false, class S, unsigned Nz>
ARBOR_INLINE SMat<S, left_nz<K>(Nz)> kl(const SMat<S, Nz>& M) {
  namespace c_ = spatial::cst;
  SMat<S, left_nz<K>(Nz)> out;
  static_for<9>([&](auto RC) {
    constexpr int r = decltype(RC)::value / 3, c = decltype(RC)::value % 3;
    if constexpr (nz_bit(left_nz<K>(Nz), r, c) && (!Sym || r <= c))
      out.e[r][c] =
          c_::dot3<S, LeftEntry<K, Nz, r, c, 0>, LeftEntry<K, Nz, r, c, 1>,
                   LeftEntry<K, Nz, r, c, 2>>(M.e[0][c], M.e[1][c], M.e[2][c], [] { return S(0); });
  });
  if constexpr (Sym)
    static_for<9>([&](auto RC) {
      constexpr int r = decltype(RC)::value / 3, c = decltype(RC)::value % 3;
      if constexpr (nz_bit(left_nz<K>(Nz), r, c) && r > c)
        out.e[r][c] = out.e[c][r];
    });
  return out;
}
/// M K^T for a constant K.
template <class K, class S, unsigned Nz>
ARBOR_INLINE SMat<S, right_nz<K>(Nz)> kr(const SMat<S, Nz>& M) {
  namespace c_ = spatial::cst;
  SMat<S, right_nz<K>(Nz)> out;
  static_for<9>([&](auto RC) {
    constexpr int r = decltype(RC)::value / 3, c = decltype(RC)::value % 3;
    if constexpr (nz_bit(right_nz<K>(Nz), r, c))
      out.e[r][c] = c_::dot3<S, RightEntry<K, Nz, r, c, 0>, RightEntry<K, Nz, r, c, 1>,
                             RightEntry<K, Nz, r, c, 2>>(M.e[r][0], M.e[r][1], M.e[r][2],
                                                         [] { return S(0); });
  });
  return out;
}

/// The entries of BP::art_inertia() (BodyOps of a parent) as compile-time constants (0 when
/// !Init): A = m 1, B = -[h], C = Io.
template <class BP, bool Init, int r, int c>
struct ConstA {
  static constexpr double value = [] {
    if constexpr (Init)
      return r == c ? BP::Y.m : 0.0;
    else
      return 0.0;
  }();
};
template <class BP, bool Init, int r, int c>
struct ConstB {
  static constexpr double value = [] {
    if constexpr (Init)
      return -spatial::cst::Skew<typename BP::HV>::at(r, c);
    else
      return 0.0;
  }();
};
template <class BP, bool Init, int r, int c>
struct ConstC {
  static constexpr double value = [] {
    if constexpr (Init)
      return BP::Y.Io[r][c];
    else
      return 0.0;
  }();
};

/// The child of body p that comes last in the tree's numbering (the first one the backward
/// passes visit), -1 for a leaf.
template <class R>
constexpr int last_child(int p) {
  int c = -1;
  for (int j = 0; j < R::nb; ++j)
    if (R::parent[j] == p)
      c = j;
  return c;
}

/// Scalar actions of body B = BodyOps<R, i, S>.
template <class B, class S>
struct Body {
  using KR = typename B::KR;
  using KRT = typename B::KRT;
  using Kp = spatial::cst::Skew<typename B::Vp>;  // [p] of the joint placement
  using Kh = spatial::cst::Skew<typename B::HV>;  // [h] of the body inertia
  using KI = typename B::IoK;
  static constexpr bool scalar = B::aligned;  // else BodyOps' actions
  static constexpr int k = B::k, ia = B::ia, ib = B::ib;
  static constexpr bool revolute = B::revolute;

  /// Rj^T (x0, x1, x2) (revolute) into y; the identity for prismatic joints.
  ARBOR_INLINE static Vec3<S> jrotT(const spatial::JointState<S>& js, const S& x0, const S& x1,
                                    const S& x2) {
    const S x[3] = {x0, x1, x2};
    Vec3<S> y;
    y[k] = x[k];
    if constexpr (revolute) {
      y[ia] = js.c * x[ia] + js.s * x[ib];
      y[ib] = js.c * x[ib] - js.s * x[ia];
    } else {
      y[ia] = x[ia];
      y[ib] = x[ib];
    }
    return y;
  }

  /// Motion in the parent frame -> body frame (BodyOps::motion_to_child).
  ARBOR_INLINE static spatial::Motion<S> to_child(const spatial::JointState<S>& js,
                                                  const spatial::Motion<S>& m) {
    if constexpr (!scalar) {
      return B::motion_to_child(js, m);
    } else {
      const S w0 = m.w[0], w1 = m.w[1], w2 = m.w[2];
      S t0 = m.v[0], t1 = m.v[1], t2 = m.v[2];
      if constexpr (!B::p_zero) {  // t = v - p x w
        t0 = sub_row<S, Kp, 0>(t0, w0, w1, w2);
        t1 = sub_row<S, Kp, 1>(t1, w0, w1, w2);
        t2 = sub_row<S, Kp, 2>(t2, w0, w1, w2);
      }
      const S wa = krow<S, KRT, 0>(w0, w1, w2), wb = krow<S, KRT, 1>(w0, w1, w2),
              wc = krow<S, KRT, 2>(w0, w1, w2);
      const S va = krow<S, KRT, 0>(t0, t1, t2), vb = krow<S, KRT, 1>(t0, t1, t2),
              vc = krow<S, KRT, 2>(t0, t1, t2);
      spatial::Motion<S> out;
      out.w = jrotT(js, wa, wb, wc);
      out.v = jrotT(js, va, vb, vc);
      if constexpr (!revolute) {  // v - d x w, d = js.d e_k
        out.v[ia] += js.d * out.w[ib];
        out.v[ib] -= js.d * out.w[ia];
      }
      return out;
    }
  }
  /// Pure linear motion in the parent frame -> body frame.
  ARBOR_INLINE static Vec3<S> linear_to_child(const spatial::JointState<S>& js, const Vec3<S>& v) {
    if constexpr (!scalar) {
      return B::linear_to_child(js, v);
    } else {
      const S v0 = v[0], v1 = v[1], v2 = v[2];
      return jrotT(js, krow<S, KRT, 0>(v0, v1, v2), krow<S, KRT, 1>(v0, v1, v2),
                   krow<S, KRT, 2>(v0, v1, v2));
    }
  }

  /// fp += (force f of the body carried to the parent frame) (BodyOps::force_to_parent).
  ARBOR_INLINE static void add_to_parent(const spatial::JointState<S>& js,
                                         const spatial::Force<S>& f, spatial::Force<S>& fp) {
    if constexpr (!scalar) {
      fp += B::force_to_parent(js, f);
    } else {
      S f1[3], n1[3];
      f1[k] = f.f[k];
      n1[k] = f.n[k];
      if constexpr (revolute) {
        const S c = js.c, s = js.s;
        f1[ia] = c * f.f[ia] - s * f.f[ib];
        f1[ib] = s * f.f[ia] + c * f.f[ib];
        n1[ia] = c * f.n[ia] - s * f.n[ib];
        n1[ib] = s * f.n[ia] + c * f.n[ib];
      } else {  // n + d x f
        f1[ia] = f.f[ia];
        f1[ib] = f.f[ib];
        n1[ia] = f.n[ia] - js.d * f.f[ib];
        n1[ib] = f.n[ib] + js.d * f.f[ia];
      }
      const S f2[3] = {krow<S, KR, 0>(f1[0], f1[1], f1[2]), krow<S, KR, 1>(f1[0], f1[1], f1[2]),
                       krow<S, KR, 2>(f1[0], f1[1], f1[2])};
      for (int r = 0; r < 3; ++r)
        fp.f[r] += f2[r];
      S n2[3] = {krow<S, KR, 0>(n1[0], n1[1], n1[2]), krow<S, KR, 1>(n1[0], n1[1], n1[2]),
                 krow<S, KR, 2>(n1[0], n1[1], n1[2])};
      if constexpr (!B::p_zero) {
        n2[0] = add_row<S, Kp, 0>(n2[0], f2[0], f2[1], f2[2]);
        n2[1] = add_row<S, Kp, 1>(n2[1], f2[0], f2[1], f2[2]);
        n2[2] = add_row<S, Kp, 2>(n2[2], f2[0], f2[1], f2[2]);
      }
      for (int r = 0; r < 3; ++r)
        fp.n[r] += n2[r];
    }
  }

  /// The constant body inertia times a motion (BodyOps::inertia_times).
  ARBOR_INLINE static spatial::Force<S> inertia_times(const spatial::Motion<S>& x) {
    if constexpr (B::massless) {
      return spatial::Force<S>::Zero();
    } else {
      const S m = S(B::Y.m);
      const S v0 = x.v[0], v1 = x.v[1], v2 = x.v[2], w0 = x.w[0], w1 = x.w[1], w2 = x.w[2];
      spatial::Force<S> F;
      F.f[0] = sub_row<S, Kh, 0>(S(v0 * m), w0, w1, w2);  // m v - h x w
      F.f[1] = sub_row<S, Kh, 1>(S(v1 * m), w0, w1, w2);
      F.f[2] = sub_row<S, Kh, 2>(S(v2 * m), w0, w1, w2);
      F.n[0] = add_row<S, Kh, 0>(krow<S, KI, 0>(w0, w1, w2), v0, v1, v2);  // Io w + h x v
      F.n[1] = add_row<S, Kh, 1>(krow<S, KI, 1>(w0, w1, w2), v0, v1, v2);
      F.n[2] = add_row<S, Kh, 2>(krow<S, KI, 2>(w0, w1, w2), v0, v1, v2);
      return F;
    }
  }

  /// Which of the six entries (v then w) of the velocity-product acceleration c = v x S qd can
  /// be nonzero (bit j: entry j): m x e_k has no k component; a prismatic joint's has no w.
  static constexpr unsigned c_nz = !scalar    ? 0x3fu
                                   : revolute ? (0x3fu & ~((1u << k) | (1u << (3 + k))))
                                              : (0x7u & ~(1u << k));

  /// Ya x for an articulated inertia and a motion x whose entries outside Mask are zero.
  template <unsigned Mask = 0x3fu>
  ARBOR_INLINE static spatial::Force<S> art_times(const spatial::ArticulatedInertia<S>& Y,
                                                  const spatial::Motion<S>& x) {
    constexpr int j0 = std::countr_zero(Mask);
    spatial::Force<S> F;
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
  template <unsigned Mask = 0x3fu>
  ARBOR_INLINE static S dot_masked(const spatial::Force<S>& U, const spatial::Motion<S>& x) {
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

  /// U = Ya S as (uf, un) (BodyOps::art_S).
  ARBOR_INLINE static void art_S(const spatial::ArticulatedInertia<S>& Y, spatial::Force<S>& U) {
    if constexpr (!scalar) {
      B::art_S(Y, U.f, U.n);
    } else {
      for (int r = 0; r < 3; ++r) {
        if constexpr (revolute) {
          U.f[r] = signed_(Y.B(r, k));
          U.n[r] = signed_(Y.C(r, k));
        } else {
          U.f[r] = signed_(Y.A(r, k));
          U.n[r] = signed_(Y.B(k, r));
        }
      }
    }
  }

  /// Yp += (Yi - U Dinv U^T) carried to the parent frame (BodyOps::art_project_to_parent). For a
  /// revolute joint about a coordinate axis: the projection's zero row and column k (C) and
  /// column k (B) known at compile time through the joint rotation, the constant rotation and
  /// translation of the placement applied to the nonzero entries only, A and C as their upper
  /// triangles.
  /// Init = BP (the parent's BodyOps, not void): Yp is set to the parent's constant body inertia
  /// plus the projection (the first child of the parent to project) instead of added to.
  template <class BP = void>
  ARBOR_INLINE static void add_art_projection(const spatial::JointState<S>& js,
                                              const spatial::ArticulatedInertia<S>& Yi,
                                              const spatial::Force<S>& U, const S& Dinv,
                                              spatial::ArticulatedInertia<S>& Yp) {
    constexpr bool init = !std::is_void_v<BP>;
    if constexpr (!(scalar && revolute)) {
      if constexpr (init)
        Yp = BP::art_inertia();
      Yp += B::art_project_to_parent(js, Yi, U, Dinv);
    } else {
      // the entries of Yp before the sum: Yp itself, or the parent's constant art_inertia()
      // (-0.0 for its zeros: -0.0 + x is x, folded at compile time)
      auto start = [&](const S& y, auto Kc) -> S {
        if constexpr (!init) {
          return y;
        } else {
          constexpr double kc = decltype(Kc)::value;
          if constexpr (kc == 0.0)
            return S(-0.0);
          else
            return S(kc);
        }
      };
      constexpr int a = ia, b = ib;
      constexpr unsigned full = 0x1ffu;
      constexpr unsigned no_col_k = full & ~((1u << k) | (1u << (3 + k)) | (1u << (6 + k)));
      constexpr unsigned ab_block =
          (1u << (3 * a + a)) | (1u << (3 * a + b)) | (1u << (3 * b + a)) | (1u << (3 * b + b));
      using KpT = spatial::cst::Transpose<Kp>;
      // Block by block (A, then B, then C), so that few values live at once: the rank-one
      // projection, the joint rotation Rj (.) Rj^T (a and b mixed), the constant rotation, the
      // translation p (B - A [p], C + [p] B + ([p] B)^T - [p] A [p]), the sum into Yp.
      const S c = js.c, sn = js.s;
      const S cc = c * c, ss = sn * sn, cs = c * sn;
      const S gf[3] = {U.f[0] * Dinv, U.f[1] * Dinv, U.f[2] * Dinv};
      SMat<S, full> Am;
      {
        S A[3][3];
        for (int r = 0; r < 3; ++r)
          for (int q = r; q < 3; ++q) {
            A[r][q] = Yi.A(r, q) - gf[r] * U.f[q];
            A[q][r] = A[r][q];
          }
        const S ta = S(2) * cs * A[a][b];
        Am.e[k][k] = A[k][k];
        Am.e[a][k] = Am.e[k][a] = c * A[a][k] - sn * A[b][k];
        Am.e[b][k] = Am.e[k][b] = sn * A[a][k] + c * A[b][k];
        Am.e[a][a] = cc * A[a][a] + ss * A[b][b] - ta;
        Am.e[b][b] = ss * A[a][a] + cc * A[b][b] + ta;
        Am.e[a][b] = Am.e[b][a] = cs * (A[a][a] - A[b][b]) + (cc - ss) * A[a][b];
      }
      const auto A2 = kl<KR, true>(kr<KR>(Am));
      using MA = std::remove_cvref_t<decltype(A2)>;
      static_for<9>([&](auto RC) {
        constexpr int r = decltype(RC)::value / 3, q = decltype(RC)::value % 3;
        if constexpr (r <= q) {
          S t = start(Yp.A(r, q), ConstA<BP, init, r, q>{});
          if constexpr (MA::at(r, q))
            t += A2.e[r][q];
          Yp.A(r, q) = t;
          if constexpr (r != q)
            Yp.A(q, r) = t;
        }
      });
      const auto AP = [&] {  // A [p]
        if constexpr (B::p_zero)
          return SMat<S, 0u>{};
        else
          return kr<KpT>(A2);
      }();
      const auto PAP = [&] {  // [p] A [p]
        if constexpr (B::p_zero)
          return SMat<S, 0u>{};
        else
          return kl<Kp, true>(AP);
      }();
      SMat<S, no_col_k> Bm;
      {
        S Ta[3], Tb[3];
        for (int r = 0; r < 3; ++r) {
          const S Ba = Yi.B(r, a) - gf[r] * U.n[a];
          const S Bb = Yi.B(r, b) - gf[r] * U.n[b];
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
      const auto B2 = kl<KR>(kr<KR>(Bm));
      using MB = std::remove_cvref_t<decltype(B2)>;
      using MAP = std::remove_cvref_t<decltype(AP)>;
      static_for<9>([&](auto RC) {
        constexpr int r = decltype(RC)::value / 3, q = decltype(RC)::value % 3;
        S t = start(Yp.B(r, q), ConstB<BP, init, r, q>{});
        if constexpr (MB::at(r, q))
          t += B2.e[r][q];
        if constexpr (MAP::at(r, q))
          t -= AP.e[r][q];
        Yp.B(r, q) = t;
      });
      const auto PB = [&] {  // [p] B
        if constexpr (B::p_zero)
          return SMat<S, 0u>{};
        else
          return kl<Kp>(B2);
      }();
      SMat<S, ab_block> Cm;
      {
        const S gna = U.n[a] * Dinv, gnb = U.n[b] * Dinv;
        const S Caa = Yi.C(a, a) - gna * U.n[a];
        const S Cab = Yi.C(a, b) - gna * U.n[b];
        const S Cbb = Yi.C(b, b) - gnb * U.n[b];
        const S tc = S(2) * cs * Cab;
        Cm.e[a][a] = cc * Caa + ss * Cbb - tc;
        Cm.e[b][b] = ss * Caa + cc * Cbb + tc;
        Cm.e[a][b] = Cm.e[b][a] = cs * (Caa - Cbb) + (cc - ss) * Cab;
      }
      const auto C2 = kl<KR, true>(kr<KR>(Cm));
      using MC = std::remove_cvref_t<decltype(C2)>;
      using MPB = std::remove_cvref_t<decltype(PB)>;
      using MPAP = std::remove_cvref_t<decltype(PAP)>;
      static_for<9>([&](auto RC) {
        constexpr int r = decltype(RC)::value / 3, q = decltype(RC)::value % 3;
        if constexpr (r <= q) {
          S t = start(Yp.C(r, q), ConstC<BP, init, r, q>{});
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

  // ---- the same on blocks of columns (minverse): T a row vector of S, one per coordinate ----
  /// (v, w) = the columns of the 6-row block P (parent frame) carried to the body frame
  /// (BodyOps::motion_to_child_t).
  template <class T, class P>
  ARBOR_INLINE static void rows_to_child(const spatial::JointState<S>& js, const P& pb, T (&v)[3],
                                         T (&w)[3]) {
    if constexpr (!scalar) {
      typename B::template Tri<T> tv{pb.row(0), pb.row(1), pb.row(2)};
      typename B::template Tri<T> tw{pb.row(3), pb.row(4), pb.row(5)};
      B::motion_to_child_t(js, tv, tw);
      for (int j = 0; j < 3; ++j) {
        v[j] = tv[j];
        w[j] = tw[j];
      }
    } else {
      const T w0 = pb.row(3), w1 = pb.row(4), w2 = pb.row(5);
      T t0 = pb.row(0), t1 = pb.row(1), t2 = pb.row(2);
      if constexpr (!B::p_zero) {  // t = v - p x w
        t0 = sub_row<S, Kp, 0>(t0, w0, w1, w2);
        t1 = sub_row<S, Kp, 1>(t1, w0, w1, w2);
        t2 = sub_row<S, Kp, 2>(t2, w0, w1, w2);
      }
      rot_rows_T(js, krow<S, KRT, 0>(w0, w1, w2), krow<S, KRT, 1>(w0, w1, w2),
                 krow<S, KRT, 2>(w0, w1, w2), w);
      rot_rows_T(js, krow<S, KRT, 0>(t0, t1, t2), krow<S, KRT, 1>(t0, t1, t2),
                 krow<S, KRT, 2>(t0, t1, t2), v);
      if constexpr (!revolute) {  // v - d x w
        v[ia] += w[ib] * js.d;
        v[ib] -= w[ia] * js.d;
      }
    }
  }
  /// y = Rj^T x on rows (the identity for prismatic joints).
  template <class T>
  ARBOR_INLINE static void rot_rows_T(const spatial::JointState<S>& js, const T& x0, const T& x1,
                                      const T& x2, T (&y)[3]) {
    const T* x[3] = {&x0, &x1, &x2};
    y[k] = *x[k];
    if constexpr (revolute) {
      y[ia] = *x[ia] * js.c + *x[ib] * js.s;
      y[ib] = *x[ib] * js.c - *x[ia] * js.s;
    } else {
      y[ia] = *x[ia];
      y[ib] = *x[ib];
    }
  }
  /// The rows of P (parent frame) += the force columns (f, n) of the body carried to the parent
  /// (BodyOps::force_to_parent_t).
  template <class T, class P>
  ARBOR_INLINE static void add_rows_to_parent(const spatial::JointState<S>& js, const T (&f)[3],
                                              const T (&n)[3], P&& pb) {
    if constexpr (!scalar) {
      typename B::template Tri<T> tf{f[0], f[1], f[2]};
      typename B::template Tri<T> tn{n[0], n[1], n[2]};
      B::force_to_parent_t(js, tf, tn);
      for (int j = 0; j < 3; ++j) {
        pb.row(j) += tf[j];
        pb.row(3 + j) += tn[j];
      }
    } else {
      T f1[3], n1[3];
      f1[k] = f[k];
      n1[k] = n[k];
      if constexpr (revolute) {
        const S c = js.c, s = js.s;
        f1[ia] = f[ia] * c - f[ib] * s;
        f1[ib] = f[ia] * s + f[ib] * c;
        n1[ia] = n[ia] * c - n[ib] * s;
        n1[ib] = n[ia] * s + n[ib] * c;
      } else {  // n + d x f
        f1[ia] = f[ia];
        f1[ib] = f[ib];
        n1[ia] = n[ia] - f[ib] * js.d;
        n1[ib] = n[ib] + f[ia] * js.d;
      }
      const T f2[3] = {krow<S, KR, 0>(f1[0], f1[1], f1[2]), krow<S, KR, 1>(f1[0], f1[1], f1[2]),
                       krow<S, KR, 2>(f1[0], f1[1], f1[2])};
      for (int r = 0; r < 3; ++r)
        pb.row(r) += f2[r];
      T n2[3] = {krow<S, KR, 0>(n1[0], n1[1], n1[2]), krow<S, KR, 1>(n1[0], n1[1], n1[2]),
                 krow<S, KR, 2>(n1[0], n1[1], n1[2])};
      if constexpr (!B::p_zero) {
        n2[0] = add_row<S, Kp, 0>(n2[0], f2[0], f2[1], f2[2]);
        n2[1] = add_row<S, Kp, 1>(n2[1], f2[0], f2[1], f2[2]);
        n2[2] = add_row<S, Kp, 2>(n2[2], f2[0], f2[1], f2[2]);
      }
      for (int r = 0; r < 3; ++r)
        pb.row(3 + r) += n2[r];
    }
  }

  /// S^T on the rows of a 6-row block of force columns.
  template <class P>
  ARBOR_INLINE static auto ST_rows(const P& blk) {
    using T = Eigen::Matrix<S, 1, P::ColsAtCompileTime>;
    if constexpr (!scalar) {
      typename B::template Tri<T> f{blk.row(0), blk.row(1), blk.row(2)};
      typename B::template Tri<T> t{blk.row(3), blk.row(4), blk.row(5)};
      return T(B::ST_t(f, t));
    } else if constexpr (B::sign > 0) {
      return T(blk.row(revolute ? 3 + k : k));
    } else {
      return T(-blk.row(revolute ? 3 + k : k));
    }
  }
  /// (v, w) += S x on rows.
  template <class T>
  ARBOR_INLINE static void add_S_rows(T (&v)[3], T (&w)[3], const T& x) {
    if constexpr (!scalar) {
      typename B::template Tri<T> tv{v[0], v[1], v[2]}, tw{w[0], w[1], w[2]};
      B::add_S_t(tv, tw, x);
      for (int j = 0; j < 3; ++j) {
        v[j] = tv[j];
        w[j] = tw[j];
      }
    } else {
      T& y = revolute ? w[k] : v[k];
      if constexpr (B::sign > 0)
        y += x;
      else
        y -= x;
    }
  }

  /// The joint's sign applied to x.
  ARBOR_INLINE static S signed_(const S& x) {
    if constexpr (B::sign > 0)
      return x;
    else
      return S(-x);
  }
  /// m += S x.
  ARBOR_INLINE static void add_S(spatial::Motion<S>& m, const S& x) {
    if constexpr (!scalar)
      B::add_S(m, x);
    else if constexpr (revolute)
      m.w[k] += signed_(x);
    else
      m.v[k] += signed_(x);
  }
  /// a += m x (S x) (BodyOps::cross_S).
  ARBOR_INLINE static void add_cross_S(spatial::Motion<S>& a, const spatial::Motion<S>& m,
                                       const S& x) {
    if constexpr (!scalar) {
      a += B::cross_S(m, x);
    } else {
      const S sx = signed_(x);
      if constexpr (revolute) {  // y x e_k = y_b e_a - y_a e_b
        a.v[ia] += m.v[ib] * sx;
        a.v[ib] -= m.v[ia] * sx;
        a.w[ia] += m.w[ib] * sx;
        a.w[ib] -= m.w[ia] * sx;
      } else {
        a.v[ia] += m.w[ib] * sx;
        a.v[ib] -= m.w[ia] * sx;
      }
    }
  }
  /// S^T f.
  ARBOR_INLINE static S ST(const spatial::Force<S>& f) {
    if constexpr (!scalar)
      return B::ST(f);
    else if constexpr (revolute)
      return signed_(f.n[k]);
    else
      return signed_(f.f[k]);
  }
};

}  // namespace arbor::detail::sx
