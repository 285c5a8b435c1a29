// Random OCP QPs in static memory (no heap, no files: every target), shared by the QP size
// matrix (qp_matrix.hpp) and the odd-size benchmark rows (bench/qp/qp_bench.cpp): splitmix64 for
// the same numbers everywhere, problems strictly convex and feasible by construction.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace qp_matrix {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// splitmix64: a small deterministic generator (the same numbers on every target).
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }  // [0, 1)
  double symmetric() { return 2 * uniform() - 1; }                                // [-1, 1)
};

/// Fills qp (double) with a random strictly convex problem around a simulated trajectory:
/// dynamics A = I + 0.3 R / sqrt(nx) (stable enough for long horizons), stage Hessians
/// L L' / nw + 0.1 I, bounds and path rows placed around the trajectory, a linear cost that
/// pushes against them; ~20 % of the bound sides infinite. x_0 is fixed (lbx_0 = ubx_0).
template <class Qp>
void random_problem(Qp& qp, std::uint64_t seed) {
  constexpr int N = Qp::horizon, NX = Qp::nx, NU = Qp::nu, NG = Qp::ng, NGN = Qp::ngn;
  constexpr int NW = NX + NU;
  Rng g{seed};
  auto lo = [&](double v) { return g.uniform() < 0.2 ? -kInf : v - 0.05 - g.uniform(); };
  auto hi = [&](double v) { return g.uniform() < 0.2 ? kInf : v + 0.05 + g.uniform(); };
  Eigen::Matrix<double, NX, 1> x;
  for (int i = 0; i < NX; ++i)
    x[i] = g.symmetric();
  for (int k = 0; k < N; ++k) {
    auto& s = qp.stage[std::size_t(k)];
    Eigen::Matrix<double, NW, NW> L, H;
    for (int i = 0; i < NW; ++i)
      for (int j = 0; j < NW; ++j)
        L(i, j) = g.symmetric();
    H = L * L.transpose() / NW;
    H.diagonal().array() += 0.1;
    s.Q = H.template topLeftCorner<NX, NX>();
    s.S = H.template bottomLeftCorner<NU, NX>();
    s.R = H.template bottomRightCorner<NU, NU>();
    for (int i = 0; i < NX; ++i)
      s.q[i] = 3 * g.symmetric();
    for (int i = 0; i < NU; ++i)
      s.r[i] = 3 * g.symmetric();
    for (int i = 0; i < NX; ++i) {
      for (int j = 0; j < NX; ++j)
        s.A(i, j) = (i == j ? 1.0 : 0.0) + 0.3 * g.symmetric() / std::sqrt(double(NX));
      for (int j = 0; j < NU; ++j)
        s.B(i, j) = g.symmetric();
      s.b[i] = 0.1 * g.symmetric();
    }
    Eigen::Matrix<double, NU, 1> u;
    for (int i = 0; i < NU; ++i)
      u[i] = 0.5 * g.symmetric();
    for (int i = 0; i < NG; ++i) {
      for (int j = 0; j < NX; ++j)
        s.C(i, j) = g.symmetric();
      for (int j = 0; j < NU; ++j)
        s.D(i, j) = g.symmetric();
      double z = 0;
      for (int j = 0; j < NX; ++j)
        z += s.C(i, j) * x[j];
      for (int j = 0; j < NU; ++j)
        z += s.D(i, j) * u[j];
      s.lg[i] = lo(z);
      s.ug[i] = hi(z);
    }
    for (int i = 0; i < NX; ++i) {
      s.lbx[i] = k == 0 ? x[i] : lo(x[i]);
      s.ubx[i] = k == 0 ? x[i] : hi(x[i]);
    }
    for (int i = 0; i < NU; ++i) {
      s.lbu[i] = lo(u[i]);
      s.ubu[i] = hi(u[i]);
    }
    Eigen::Matrix<double, NX, 1> xn = s.A * x + s.b;
    if constexpr (NU > 0)
      xn += s.B * u;
    x = xn;
  }
  auto& t = qp.terminal;
  Eigen::Matrix<double, NX, NX> L;
  for (int i = 0; i < NX; ++i)
    for (int j = 0; j < NX; ++j)
      L(i, j) = g.symmetric();
  t.Q = L * L.transpose() / NX;
  t.Q.diagonal().array() += 0.1;
  for (int i = 0; i < NX; ++i) {
    t.q[i] = 3 * g.symmetric();
    t.lbx[i] = lo(x[i]);
    t.ubx[i] = hi(x[i]);
  }
  for (int i = 0; i < NGN; ++i) {
    for (int j = 0; j < NX; ++j)
      t.C(i, j) = g.symmetric();
    double z = 0;
    for (int j = 0; j < NX; ++j)
      z += t.C(i, j) * x[j];
    t.lg[i] = lo(z);
    t.ug[i] = hi(z);
  }
}

/// The OcpQp cast to scalar S (data only).
template <class S, class Qd, class Qs>
void cast_problem(const Qd& d, Qs& s) {
  for (std::size_t k = 0; k < d.stage.size(); ++k) {
    const auto& a = d.stage[k];
    auto& b = s.stage[k];
    b.Q = a.Q.template cast<S>(), b.S = a.S.template cast<S>(), b.R = a.R.template cast<S>();
    b.q = a.q.template cast<S>(), b.r = a.r.template cast<S>();
    b.A = a.A.template cast<S>(), b.B = a.B.template cast<S>(), b.b = a.b.template cast<S>();
    b.C = a.C.template cast<S>(), b.D = a.D.template cast<S>();
    b.lg = a.lg.template cast<S>(), b.ug = a.ug.template cast<S>();
    b.lbx = a.lbx.template cast<S>(), b.ubx = a.ubx.template cast<S>();
    b.lbu = a.lbu.template cast<S>(), b.ubu = a.ubu.template cast<S>();
  }
  s.terminal.Q = d.terminal.Q.template cast<S>(), s.terminal.q = d.terminal.q.template cast<S>();
  s.terminal.C = d.terminal.C.template cast<S>();
  s.terminal.lg = d.terminal.lg.template cast<S>(),
  s.terminal.ug = d.terminal.ug.template cast<S>();
  s.terminal.lbx = d.terminal.lbx.template cast<S>();
  s.terminal.ubx = d.terminal.ubx.template cast<S>();
}

}  // namespace qp_matrix
