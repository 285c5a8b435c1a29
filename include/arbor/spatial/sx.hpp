// arbor: scalar-level spatial products (namespace arbor::detail::sx): cross products, inertia and
// inertia-rate times a motion, motion and force cross products, sums, written out component by
// component and force-inlined, for the per-body passes of the dynamics and derivative kernels.
#pragma once

#include "arbor/core/config.hpp"
#include "arbor/spatial/fwd.hpp"
#include "arbor/spatial/inertia.hpp"
#include "arbor/spatial/motion.hpp"

namespace arbor::detail {

/// Scalar-level spatial products for the per-body passes, written out component by
/// component and force-inlined: with Eigen's vectorised 3-vector cross products and the
/// out-of-line Inertia * Motion, GCC's inlining of the flattened passes depended on the size of
/// everything else (one extra inline product doubled the count); plain scalar code keeps every
/// operand in registers. Same arithmetic as spatial::cross, Inertia::operator*, InertiaRate.
namespace sx {

template <class S>
ARBOR_INLINE Vec3<S> cross(const Vec3<S>& a, const Vec3<S>& b) {
  return Vec3<S>(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}

/// a x b + c x d
template <class S>
ARBOR_INLINE Vec3<S> cross2(const Vec3<S>& a, const Vec3<S>& b, const Vec3<S>& c,
                            const Vec3<S>& e) {
  return Vec3<S>(a[1] * b[2] - a[2] * b[1] + c[1] * e[2] - c[2] * e[1],
                 a[2] * b[0] - a[0] * b[2] + c[2] * e[0] - c[0] * e[2],
                 a[0] * b[1] - a[1] * b[0] + c[0] * e[1] - c[1] * e[0]);
}

template <class S>
ARBOR_INLINE S dot3(const Vec3<S>& a, const Vec3<S>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// M x for a 3x3 matrix.
template <class S>
ARBOR_INLINE Vec3<S> mul3(const Mat3<S>& M, const Vec3<S>& x) {
  return Vec3<S>(M(0, 0) * x[0] + M(0, 1) * x[1] + M(0, 2) * x[2],
                 M(1, 0) * x[0] + M(1, 1) * x[1] + M(1, 2) * x[2],
                 M(2, 0) * x[0] + M(2, 1) * x[1] + M(2, 2) * x[2]);
}

/// <f, m>
template <class S>
ARBOR_INLINE S dot(const spatial::Force<S>& f, const spatial::Motion<S>& m) {
  return dot3(f.f, m.v) + dot3(f.n, m.w);
}

/// m1 x m2 (motions)
template <class S>
ARBOR_INLINE spatial::Motion<S> mcross(const spatial::Motion<S>& a, const spatial::Motion<S>& b) {
  return {cross2(a.w, b.v, a.v, b.w), cross(a.w, b.w)};
}

/// m x* f
template <class S>
ARBOR_INLINE spatial::Force<S> fcross(const spatial::Motion<S>& m, const spatial::Force<S>& f) {
  return {cross(m.w, f.f), cross2(m.w, f.n, m.v, f.f)};
}

/// Y x = [m xv - h x xw; Io xw + h x xv]
template <class S>
ARBOR_INLINE spatial::Force<S> imul(const spatial::Inertia<S>& Y, const spatial::Motion<S>& x) {
  const Vec3<S>& h = Y.h;
  const Mat3<S>& I = Y.Io;
  const Vec3<S>& v = x.v;
  const Vec3<S>& w = x.w;
  return {Vec3<S>(Y.m * v[0] - h[1] * w[2] + h[2] * w[1], Y.m * v[1] - h[2] * w[0] + h[0] * w[2],
                  Y.m * v[2] - h[0] * w[1] + h[1] * w[0]),
          Vec3<S>(I(0, 0) * w[0] + I(0, 1) * w[1] + I(0, 2) * w[2] + h[1] * v[2] - h[2] * v[1],
                  I(1, 0) * w[0] + I(1, 1) * w[1] + I(1, 2) * w[2] + h[2] * v[0] - h[0] * v[2],
                  I(2, 0) * w[0] + I(2, 1) * w[1] + I(2, 2) * w[2] + h[0] * v[1] - h[1] * v[0])};
}

/// Yd x = [-hd x xw; Iod xw + hd x xv]
template <class S>
ARBOR_INLINE spatial::Force<S> rmul(const spatial::InertiaRate<S>& Y, const spatial::Motion<S>& x) {
  const Vec3<S>& h = Y.hd;
  const Mat3<S>& I = Y.Iod;
  const Vec3<S>& v = x.v;
  const Vec3<S>& w = x.w;
  return {Vec3<S>(h[2] * w[1] - h[1] * w[2], h[0] * w[2] - h[2] * w[0], h[1] * w[0] - h[0] * w[1]),
          Vec3<S>(I(0, 0) * w[0] + I(0, 1) * w[1] + I(0, 2) * w[2] + h[1] * v[2] - h[2] * v[1],
                  I(1, 0) * w[0] + I(1, 1) * w[1] + I(1, 2) * w[2] + h[2] * v[0] - h[0] * v[2],
                  I(2, 0) * w[0] + I(2, 1) * w[1] + I(2, 2) * w[2] + h[0] * v[1] - h[1] * v[0])};
}

/// Column i of a 6 x n matrix as a motion.
template <class S, class J>
ARBOR_INLINE spatial::Motion<S> jcol(const J& Jm, int i) {
  return {Vec3<S>(Jm(0, i), Jm(1, i), Jm(2, i)), Vec3<S>(Jm(3, i), Jm(4, i), Jm(5, i))};
}

/// a += b, entry by entry.
template <class S>
ARBOR_INLINE void add_to(spatial::Force<S>& a, const spatial::Force<S>& b) {
  for (int c = 0; c < 3; ++c) {
    a.f[c] += b.f[c];
    a.n[c] += b.n[c];
  }
}
template <class S>
ARBOR_INLINE void add_to(spatial::Inertia<S>& a, const spatial::Inertia<S>& b) {
  a.m += b.m;
  for (int c = 0; c < 3; ++c)
    a.h[c] += b.h[c];
  for (int c = 0; c < 9; ++c)
    a.Io.data()[c] += b.Io.data()[c];
}
template <class S>
ARBOR_INLINE void add_to(spatial::InertiaRate<S>& a, const spatial::InertiaRate<S>& b) {
  for (int c = 0; c < 3; ++c)
    a.hd[c] += b.hd[c];
  for (int c = 0; c < 9; ++c)
    a.Iod.data()[c] += b.Iod.data()[c];
}

/// m x S for the world column S of body B's joint (no angular part for prismatic joints).
template <class B, class S>
ARBOR_INLINE spatial::Motion<S> cross_col(const spatial::Motion<S>& m,
                                          const spatial::Motion<S>& Sc) {
  if constexpr (B::revolute)
    return mcross(m, Sc);
  else
    return {cross(m.w, Sc.v), Vec3<S>::Zero()};
}

/// S x* f for the world column S of body B's joint.
template <class B, class S>
ARBOR_INLINE spatial::Force<S> cross_col_force(const spatial::Motion<S>& Sc,
                                               const spatial::Force<S>& f) {
  if constexpr (B::revolute)
    return fcross(Sc, f);
  else
    return {Vec3<S>::Zero(), cross(Sc.v, f.f)};
}

/// Rate v x* Y - Y v x of the rigid inertia Y moving with velocity v (WorldInertia::rate).
template <class S>
ARBOR_INLINE spatial::InertiaRate<S> rate(const spatial::Inertia<S>& Y,
                                          const spatial::Motion<S>& v) {
  spatial::InertiaRate<S> D;
  const Vec3<S>& w = v.w;
  const Vec3<S>& h = Y.h;
  D.hd = Vec3<S>(v.v[0] * Y.m + w[1] * h[2] - w[2] * h[1], v.v[1] * Y.m + w[2] * h[0] - w[0] * h[2],
                 v.v[2] * Y.m + w[0] * h[1] - w[1] * h[0]);
  // Iod = A + A^T - (h v^T + v h^T) + 2 (v . h) 1, A = [w] Io
  const Mat3<S>& I = Y.Io;
  S A[3][3];
  for (int k = 0; k < 3; ++k) {
    A[0][k] = w[1] * I(2, k) - w[2] * I(1, k);
    A[1][k] = w[2] * I(0, k) - w[0] * I(2, k);
    A[2][k] = w[0] * I(1, k) - w[1] * I(0, k);
  }
  const S vh2 = S(2) * dot3(v.v, h);
  for (int r = 0; r < 3; ++r)
    for (int k = r; k < 3; ++k) {
      S e = A[r][k] + A[k][r] - h[r] * v.v[k] - v.v[r] * h[k];
      if (r == k)
        e += vh2;
      D.Iod(r, k) = e;
      D.Iod(k, r) = e;
    }
  return D;
}

}  // namespace sx

}  // namespace arbor::detail
