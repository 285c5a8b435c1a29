// Test support for the IPOPT comparisons: a multiple-shooting OCP written in plain double code
// (no arbor), its transcription to the dense NLP of support/ipopt_reference.hpp, finite-difference
// derivatives of the plain functions, the NLP's KKT residuals at a given primal-dual point, and
// the extraction of an Nmpc controller's solution into the NLP's layout.
//
// The NLP (the same one the controller solves):
//   variables    w = [x_0, u_0, x_1, u_1, ..., x_{N-1}, u_{N-1}, x_N]
//   objective    sum_{k<N} l(x_k, u_k) + l_N(x_N)
//   constraints  g = [x_0 - x0;  for k < N: x_{k+1} - F(x_k, u_k) (nx rows), c(x_k, u_k) (nc rows)]
//                with x_0 - x0 = 0, x_{k+1} - F = 0, lc <= c <= uc
//   bounds       lbu <= u_k <= ubu (k < N), lbx <= x_k <= ubx (k >= 1; x_0 is fixed by its row)
// Multipliers in IPOPT's convention (ipopt_reference.hpp): grad f + J' lambda + z = 0 with z = z_u
// - z_l (> 0 at an upper bound), lambda_i > 0 at an upper bound of g_i. The controller uses the
// same one (its Lagrangian is f + lam_dyn'(x_{k+1} - F) + mu' c, bound multipliers > 0 at the
// upper bound), so its multipliers map one to one: state_bound_multiplier(0) is lambda of x_0 -
// x0, dynamics_multiplier(k) of x_{k+1} - F, constraint_multiplier(k) of c(x_k, u_k) (hard
// constraints: one QP row per row of c), and the other bound multipliers are z.
//
// Derivatives (IPOPT's, not arbor's): the stage map z = (x, u) -> [F(x, u); c(x, u)] is
// differentiated by 4-point central differences (h_i = 7e-4 max(1, |z_i|), truncation O(h^4),
// relative error ~ 1e-12) stage by stage, and each stage's block is cached against its input, so
// that IPOPT's finite-difference Hessian (2 n Jacobian evaluations, each perturbing one stage)
// recomputes one stage per evaluation. The gradient of the objective is computed (and cached) the
// same way, stage by stage.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "alloc_guard.hpp"
#include "arbor/nmpc/controller.hpp"
#include "ipopt_reference.hpp"

namespace nmpc_test {

using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

/// A multiple-shooting OCP in plain code (see the top of this file).
struct PlainOcp {
  int nx = 0, nu = 0, N = 0;
  int nc = 0;  ///< path constraint rows per stage k < N (on x_k, u_k)
  /// x_{k+1} = F(x_k, u_k) (plain RK4)
  std::function<VecX(const VecX& x, const VecX& u)> F;
  /// stage cost l(x_k, u_k), k < N
  std::function<double(const VecX& x, const VecX& u)> stage_cost;
  /// terminal cost l_N(x_N)
  std::function<double(const VecX& x)> terminal_cost;
  /// path constraint c(x_k, u_k) (nc rows), lc <= c <= uc
  std::function<VecX(const VecX& x, const VecX& u)> path_constraint;
  VecX lc, uc;    ///< path constraint bounds (nc)
  VecX lbx, ubx;  ///< state bounds, stages k >= 1 (nx)
  VecX lbu, ubu;  ///< input bounds (nu)
  VecX x0;        ///< initial state

  int stage_size() const { return nx + nu; }
  int n() const { return N * (nx + nu) + nx; }  ///< NLP variables
  int m() const { return nx + N * (nx + nc); }  ///< NLP constraints
  int x_index(int k) const { return k * (nx + nu); }
  int u_index(int k) const { return k * (nx + nu) + nx; }
  int dyn_row(int k) const { return nx + k * (nx + nc); }  ///< first row of x_{k+1} - F
  int con_row(int k) const { return dyn_row(k) + nx; }     ///< first row of c(x_k, u_k)

  VecX x_of(const VecX& w, int k) const { return w.segment(x_index(k), nx); }
  VecX u_of(const VecX& w, int k) const { return w.segment(u_index(k), nu); }

  /// [F(x, u); c(x, u)] for stage input z = [x; u].
  VecX stage_map(const VecX& z) const {
    VecX out(nx + nc);
    const VecX x = z.head(nx), u = z.tail(nu);
    out.head(nx) = F(x, u);
    if (nc > 0)
      out.tail(nc) = path_constraint(x, u);
    return out;
  }

  double objective(const VecX& w) const {
    double f = 0;
    for (int k = 0; k < N; ++k)
      f += stage_cost(x_of(w, k), u_of(w, k));
    return f + terminal_cost(x_of(w, N));
  }

  VecX constraints(const VecX& w) const {
    VecX g(m());
    g.head(nx) = x_of(w, 0) - x0;
    for (int k = 0; k < N; ++k) {
      const VecX s = stage_map(w.segment(x_index(k), nx + nu));
      g.segment(dyn_row(k), nx) = x_of(w, k + 1) - s.head(nx);
      if (nc > 0)
        g.segment(con_row(k), nc) = s.tail(nc);
    }
    return g;
  }
};

/// The solvers' common initial guess: every state x0, every input zero.
inline VecX constant_guess(const PlainOcp& o) {
  VecX w = VecX::Zero(o.n());
  for (int k = 0; k <= o.N; ++k)
    w.segment(o.x_index(k), o.nx) = o.x0;
  return w;
}

/// 4-point central difference step for a value v (exactly representable v +- h).
inline double fd_step(double v) {
  const double h = 7e-4 * std::max(1.0, std::abs(v));
  volatile double t = v + h;
  return t - v;
}

/// d fn / d z by 4-point central differences (fn: R^n -> R^m).
template <class Fn>
MatX fd_jacobian(const Fn& fn, const VecX& z, int rows) {
  MatX J(rows, z.size());
  for (int i = 0; i < z.size(); ++i) {
    const double h = fd_step(z[i]);
    VecX zp1 = z, zm1 = z, zp2 = z, zm2 = z;
    zp1[i] += h;
    zm1[i] -= h;
    zp2[i] += 2 * h;
    zm2[i] -= 2 * h;
    const VecX fp1 = fn(zp1), fm1 = fn(zm1), fp2 = fn(zp2), fm2 = fn(zm2);
    J.col(i) = (8 * (fp1 - fm1) - (fp2 - fm2)) / (12 * h);
  }
  return J;
}

/// Gradient of a scalar function by 4-point central differences.
template <class Fn>
VecX fd_gradient(const Fn& fn, const VecX& z) {
  auto vec_fn = [&](const VecX& y) { return VecX::Constant(1, fn(y)); };
  return fd_jacobian(vec_fn, z, 1).transpose();
}

/// Jacobian of g (dense m x n) from per-stage finite differences of the plain functions.
inline MatX nlp_jacobian(const PlainOcp& ocp, const VecX& w) {
  MatX J = MatX::Zero(ocp.m(), ocp.n());
  J.topLeftCorner(ocp.nx, ocp.nx).setIdentity();
  for (int k = 0; k < ocp.N; ++k) {
    const VecX z = w.segment(ocp.x_index(k), ocp.stage_size());
    const MatX Js =
        fd_jacobian([&](const VecX& y) { return ocp.stage_map(y); }, z, ocp.nx + ocp.nc);
    J.block(ocp.dyn_row(k), ocp.x_index(k), ocp.nx, ocp.stage_size()) = -Js.topRows(ocp.nx);
    J.block(ocp.dyn_row(k), ocp.x_index(k + 1), ocp.nx, ocp.nx).setIdentity();
    if (ocp.nc > 0)
      J.block(ocp.con_row(k), ocp.x_index(k), ocp.nc, ocp.stage_size()) = Js.bottomRows(ocp.nc);
  }
  return J;
}

/// Gradient of the objective, stage by stage by finite differences.
inline VecX nlp_gradient(const PlainOcp& ocp, const VecX& w) {
  VecX g = VecX::Zero(ocp.n());
  for (int k = 0; k < ocp.N; ++k) {
    const VecX z = w.segment(ocp.x_index(k), ocp.stage_size());
    g.segment(ocp.x_index(k), ocp.stage_size()) = fd_gradient(
        [&](const VecX& y) { return ocp.stage_cost(y.head(ocp.nx), y.tail(ocp.nu)); }, z);
  }
  g.tail(ocp.nx) =
      fd_gradient([&](const VecX& y) { return ocp.terminal_cost(y); }, ocp.x_of(w, ocp.N));
  return g;
}

/// The dense NLP of the OCP for IPOPT: f and g plain, grad_f and jac_g by cached per-stage finite
/// differences (the Hessian: IPOPT's finite differences of those).
inline arbor::test::Nlp make_nlp(const PlainOcp& ocp, const VecX& w0) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  arbor::test::Nlp nlp;
  nlp.n = ocp.n();
  nlp.m = ocp.m();
  const auto p = std::make_shared<PlainOcp>(ocp);
  nlp.f = [p](const double* w) { return p->objective(Eigen::Map<const VecX>(w, p->n())); };
  nlp.g = [p](const double* w, double* g) {
    Eigen::Map<VecX>(g, p->m()) = p->constraints(Eigen::Map<const VecX>(w, p->n()));
  };
  struct Cache {
    std::vector<VecX> z;  // stage inputs of the cached blocks
    std::vector<MatX> J;  // d [F; c] / d z
  };
  const auto cache = std::make_shared<Cache>();
  cache->z.assign(std::size_t(ocp.N), VecX());
  cache->J.assign(std::size_t(ocp.N), MatX());
  nlp.jac_g = [p, cache](const double* wp, double* jac) {
    const PlainOcp& o = *p;
    const Eigen::Map<const VecX> w(wp, o.n());
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(jac, o.m(),
                                                                                         o.n());
    J.setZero();
    J.topLeftCorner(o.nx, o.nx).setIdentity();
    for (int k = 0; k < o.N; ++k) {
      const VecX z = w.segment(o.x_index(k), o.stage_size());
      auto& cz = cache->z[std::size_t(k)];
      auto& cj = cache->J[std::size_t(k)];
      if (cz.size() != z.size() || cz != z) {
        cj = fd_jacobian([&](const VecX& y) { return o.stage_map(y); }, z, o.nx + o.nc);
        cz = z;
      }
      J.block(o.dyn_row(k), o.x_index(k), o.nx, o.stage_size()) = -cj.topRows(o.nx);
      J.block(o.dyn_row(k), o.x_index(k + 1), o.nx, o.nx).setIdentity();
      if (o.nc > 0)
        J.block(o.con_row(k), o.x_index(k), o.nc, o.stage_size()) = cj.bottomRows(o.nc);
    }
  };
  struct GradCache {
    std::vector<VecX> z;  // stage inputs of the cached gradients (N + 1: the terminal one)
    std::vector<VecX> g;  // d l / d z
  };
  const auto gcache = std::make_shared<GradCache>();
  gcache->z.assign(std::size_t(ocp.N + 1), VecX());
  gcache->g.assign(std::size_t(ocp.N + 1), VecX());
  nlp.grad_f = [p, gcache](const double* wp, double* grad) {
    const PlainOcp& o = *p;
    const Eigen::Map<const VecX> w(wp, o.n());
    Eigen::Map<VecX> gr(grad, o.n());
    for (int k = 0; k <= o.N; ++k) {
      const int size = k < o.N ? o.stage_size() : o.nx;
      const VecX z = w.segment(o.x_index(k), size);
      auto& cz = gcache->z[std::size_t(k)];
      auto& cg = gcache->g[std::size_t(k)];
      if (cz.size() != z.size() || cz != z) {
        if (k < o.N)
          cg = fd_gradient([&](const VecX& y) { return o.stage_cost(y.head(o.nx), y.tail(o.nu)); },
                           z);
        else
          cg = fd_gradient([&](const VecX& y) { return o.terminal_cost(y); }, z);
        cz = z;
      }
      gr.segment(o.x_index(k), size) = cg;
    }
  };
  nlp.w_l.assign(std::size_t(nlp.n), -inf);
  nlp.w_u.assign(std::size_t(nlp.n), inf);
  for (int k = 0; k <= ocp.N; ++k) {
    for (int i = 0; i < ocp.nx && k > 0; ++i) {
      nlp.w_l[std::size_t(ocp.x_index(k) + i)] = ocp.lbx[i];
      nlp.w_u[std::size_t(ocp.x_index(k) + i)] = ocp.ubx[i];
    }
    for (int i = 0; i < ocp.nu && k < ocp.N; ++i) {
      nlp.w_l[std::size_t(ocp.u_index(k) + i)] = ocp.lbu[i];
      nlp.w_u[std::size_t(ocp.u_index(k) + i)] = ocp.ubu[i];
    }
  }
  nlp.g_l.assign(std::size_t(nlp.m), 0.0);
  nlp.g_u.assign(std::size_t(nlp.m), 0.0);
  for (int k = 0; k < ocp.N; ++k)
    for (int i = 0; i < ocp.nc; ++i) {
      nlp.g_l[std::size_t(ocp.con_row(k) + i)] = ocp.lc[i];
      nlp.g_u[std::size_t(ocp.con_row(k) + i)] = ocp.uc[i];
    }
  nlp.w0.assign(w0.data(), w0.data() + w0.size());
  return nlp;
}

/// A primal-dual point of the NLP in IPOPT's layout and convention.
struct NlpPoint {
  VecX w;       ///< primal (n)
  VecX lambda;  ///< constraint multipliers (m)
  VecX z;       ///< bound multipliers z_u - z_l (n)
};

/// IPOPT's answer as an NlpPoint.
inline NlpPoint point_of(const arbor::test::IpoptResult& r) {
  NlpPoint p;
  p.w = Eigen::Map<const VecX>(r.w.data(), Eigen::Index(r.w.size()));
  p.lambda = Eigen::Map<const VecX>(r.lambda_g.data(), Eigen::Index(r.lambda_g.size()));
  p.z = Eigen::Map<const VecX>(r.z_u.data(), Eigen::Index(r.z_u.size())) -
        Eigen::Map<const VecX>(r.z_l.data(), Eigen::Index(r.z_l.size()));
  return p;
}

/// The controller's plan and multipliers in the NLP's layout (see the top of this file). The
/// controller's path constraints must be hard (one QP row per row of c, in order). Every call
/// into arbor runs inside a NoAllocScope (the vectors are allocated before).
template <class Ctrl>
NlpPoint point_of(const PlainOcp& ocp, const Ctrl& ctrl) {
  static_assert(Ctrl::ns == 0, "point_of: hard constraints only");
  NlpPoint p;
  p.w = VecX::Zero(ocp.n());
  p.lambda = VecX::Zero(ocp.m());
  p.z = VecX::Zero(ocp.n());
  arbor::test::NoAllocScope guard;
  for (int k = 0; k <= ocp.N; ++k) {
    p.w.segment(ocp.x_index(k), ocp.nx) = ctrl.state(k);
    if (k > 0)
      p.z.segment(ocp.x_index(k), ocp.nx) = ctrl.state_bound_multiplier(k);
    if (k < ocp.N) {
      p.w.segment(ocp.u_index(k), ocp.nu) = ctrl.input(k);
      p.z.segment(ocp.u_index(k), ocp.nu) = ctrl.input_bound_multiplier(k);
      p.lambda.segment(ocp.dyn_row(k), ocp.nx) = ctrl.dynamics_multiplier(k);
      if (ocp.nc > 0)
        p.lambda.segment(ocp.con_row(k), ocp.nc) = ctrl.constraint_multiplier(k).head(ocp.nc);
    }
  }
  p.lambda.head(ocp.nx) = ctrl.state_bound_multiplier(0);
  return p;
}

/// The NLP's KKT residuals (infinity norms), recomputed from the plain functions.
struct Kkt {
  double stationarity = 0;     ///< |grad f + J' lambda + z|_inf
  double primal = 0;           ///< max violation of g's rows and of the bounds
  double complementarity = 0;  ///< max |multiplier * distance to the bound its sign names|
  double dual_sign = 0;        ///< max size of a multiplier of the wrong sign (or of no bound)
};

namespace detail {
inline void bound_residual(double v, double lo, double hi, double lam, Kkt& r) {
  r.primal = std::max({r.primal, lo - v, v - hi});
  if (lam > 0) {
    if (std::isfinite(hi))
      r.complementarity = std::max(r.complementarity, lam * std::abs(hi - v));
    else
      r.dual_sign = std::max(r.dual_sign, lam);
  } else if (lam < 0) {
    if (std::isfinite(lo))
      r.complementarity = std::max(r.complementarity, -lam * std::abs(v - lo));
    else
      r.dual_sign = std::max(r.dual_sign, -lam);
  }
}
}  // namespace detail

/// KKT residuals of the NLP at p, derivatives by finite differences of the plain functions.
inline Kkt kkt_residuals(const PlainOcp& ocp, const NlpPoint& p) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Kkt r;
  const MatX J = nlp_jacobian(ocp, p.w);
  const VecX grad = nlp_gradient(ocp, p.w);
  r.stationarity = (grad + J.transpose() * p.lambda + p.z).cwiseAbs().maxCoeff();
  const VecX g = ocp.constraints(p.w);
  for (int i = 0; i < ocp.m(); ++i) {
    double lo = 0, hi = 0;
    for (int k = 0; k < ocp.N; ++k)
      if (i >= ocp.con_row(k) && i < ocp.con_row(k) + ocp.nc) {
        lo = ocp.lc[i - ocp.con_row(k)];
        hi = ocp.uc[i - ocp.con_row(k)];
      }
    if (lo == hi)
      r.primal = std::max(r.primal, std::abs(g[i] - lo));
    else
      detail::bound_residual(g[i], lo, hi, p.lambda[i], r);
  }
  for (int k = 0; k <= ocp.N; ++k) {
    for (int i = 0; i < ocp.nx; ++i) {
      const int j = ocp.x_index(k) + i;
      detail::bound_residual(p.w[j], k > 0 ? ocp.lbx[i] : -inf, k > 0 ? ocp.ubx[i] : inf, p.z[j],
                             r);
    }
    for (int i = 0; i < ocp.nu && k < ocp.N; ++i) {
      const int j = ocp.u_index(k) + i;
      detail::bound_residual(p.w[j], ocp.lbu[i], ocp.ubu[i], p.z[j], r);
    }
  }
  return r;
}

/// The number of bounds and constraint rows with a multiplier above `threshold` in magnitude (the
/// active inequalities).
inline int active_count(const PlainOcp& ocp, const NlpPoint& p, double threshold) {
  int count = 0;
  for (int i = 0; i < ocp.n(); ++i)
    count += std::abs(p.z[i]) > threshold;
  for (int k = 0; k < ocp.N; ++k)
    for (int i = 0; i < ocp.nc; ++i)
      count += std::abs(p.lambda[ocp.con_row(k) + i]) > threshold;
  return count;
}

/// Max |a - b| over the states and over the inputs.
struct TrajectoryGap {
  double x = 0, u = 0;
};
inline TrajectoryGap trajectory_gap(const PlainOcp& ocp, const VecX& a, const VecX& b) {
  TrajectoryGap d;
  for (int k = 0; k <= ocp.N; ++k) {
    d.x = std::max(d.x, (ocp.x_of(a, k) - ocp.x_of(b, k)).cwiseAbs().maxCoeff());
    if (k < ocp.N)
      d.u = std::max(d.u, (ocp.u_of(a, k) - ocp.u_of(b, k)).cwiseAbs().maxCoeff());
  }
  return d;
}

/// Max |a - b| of the dynamics multipliers (rows x_{k+1} - F and x_0 - x0).
inline double dynamics_multiplier_gap(const PlainOcp& ocp, const VecX& a, const VecX& b) {
  double d = (a.head(ocp.nx) - b.head(ocp.nx)).cwiseAbs().maxCoeff();
  for (int k = 0; k < ocp.N; ++k)
    d = std::max(d, (a.segment(ocp.dyn_row(k), ocp.nx) - b.segment(ocp.dyn_row(k), ocp.nx))
                        .cwiseAbs()
                        .maxCoeff());
  return d;
}

// ---- the comparison -------------------------------------------------------------------------

/// IPOPT on the plain NLP from w0 (tol 1e-10; IPOPT's FD Hessian of the Lagrangian).
inline arbor::test::IpoptResult solve_ipopt(const std::string& name, const PlainOcp& ocp,
                                            const VecX& w0, double tol = 1e-10) {
  arbor::test::IpoptOptions opt;
  opt.tol = tol;
  opt.max_iter = 500;
  const arbor::test::IpoptResult r = arbor::test::solve_with_ipopt(make_nlp(ocp, w0), opt);
  std::printf(
      "[ipopt] %-28s %s: %d iterations, objective %.15g, %ld f / %ld g evaluations, "
      "%.2f s\n",
      name.c_str(), r.status_name.c_str(), r.iterations, r.objective, r.f_evaluations,
      r.g_evaluations, r.seconds);
  return r;
}

/// One controller run: status, figures, time, and its solution in the NLP's layout.
template <class Ctrl>
struct NmpcRun {
  arbor::nmpc::NmpcStatus status{};
  typename Ctrl::Info info{};
  double seconds = 0;
  NlpPoint point;
};

/// Sets the guess w0 (states and inputs per stage; multipliers zero) and solves from ocp.x0 with
/// max_iter SQP iterations, the relative stationarity tolerance tol_stationarity (tighter than the
/// default 1e-8, for solutions to compare at 1e-6) and the QP tolerances tol_qp (tighter than the
/// SQP's: the QP's inexactness is the floor of the SQP's accuracy), every controller call inside
/// a NoAllocScope.
template <class Ctrl>
NmpcRun<Ctrl> solve_nmpc(Ctrl& ctrl, const PlainOcp& ocp, const VecX& w0, int max_iter,
                         double tol_stationarity = 1e-10, double tol_qp = 1e-11) {
  using Vx = typename Ctrl::Vx;
  using Vu = typename Ctrl::Vu;
  NmpcRun<Ctrl> run;
  const Vx x0 = ocp.x0;
  std::vector<Vx> xs;
  std::vector<Vu> us;
  for (int k = 0; k <= ocp.N; ++k)
    xs.push_back(ocp.x_of(w0, k));
  for (int k = 0; k < ocp.N; ++k)
    us.push_back(ocp.u_of(w0, k));
  bool guess_ok = true;
  {
    arbor::test::NoAllocScope guard;
    ctrl.settings().max_iter = max_iter;
    ctrl.settings().tol_stationarity = tol_stationarity;
    ctrl.settings().qp.tol_primal = tol_qp;
    ctrl.settings().qp.tol_dual = tol_qp;
    ctrl.settings().qp.tol_comp = tol_qp;
    guess_ok &= ctrl.set_initial_guess(xs[0], us[0]) == arbor::nmpc::NmpcStatus::accepted;
    for (int k = 0; k <= ocp.N; ++k)
      guess_ok &= ctrl.set_state_guess(k, xs[std::size_t(k)]) == arbor::nmpc::NmpcStatus::accepted;
    for (int k = 0; k < ocp.N; ++k)
      guess_ok &= ctrl.set_input_guess(k, us[std::size_t(k)]) == arbor::nmpc::NmpcStatus::accepted;
    const auto t0 = std::chrono::steady_clock::now();
    run.status = ctrl.solve(x0);
    run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    run.info = ctrl.info();
  }
  EXPECT_TRUE(guess_ok);
  run.point = point_of(ocp, ctrl);
  return run;
}

/// Tolerances of a comparison with IPOPT.
struct Tolerances {
  double objective = 1e-8;  ///< relative
  double x = 1e-6;          ///< max |x_ours - x_ipopt|
  double u = 1e-6;          ///< max |u_ours - u_ipopt|
  double lambda = 1e-6;     ///< max |lambda_ours - lambda_ipopt| / (1 + max |lambda_ipopt|)
  double kkt = 1e-6;        ///< stationarity (FD), primal, complementarity of our solution
};

/// Compares a converged controller run with IPOPT's solution of the same NLP and checks the KKT
/// residuals of the controller's solution, recomputed from the plain functions.
template <class Run>
void expect_matches_ipopt(const std::string& name, const PlainOcp& ocp, const Run& run,
                          const arbor::test::IpoptResult& ip, const Tolerances& tol) {
  ASSERT_EQ(ip.status, 0) << ip.status_name;
  EXPECT_EQ(run.status, arbor::nmpc::NmpcStatus::converged);
  const NlpPoint ref = point_of(ip);
  const double f_ours = ocp.objective(run.point.w), f_ref = ocp.objective(ref.w);
  const double f_rel = std::abs(f_ours - f_ref) / std::max(1.0, std::abs(f_ref));
  const TrajectoryGap gap = trajectory_gap(ocp, run.point.w, ref.w);
  const double lam_scale = 1 + ref.lambda.cwiseAbs().maxCoeff();
  const double lam_dyn = dynamics_multiplier_gap(ocp, run.point.lambda, ref.lambda) / lam_scale;
  const double lam_all = std::max((run.point.lambda - ref.lambda).cwiseAbs().maxCoeff(),
                                  (run.point.z - ref.z).cwiseAbs().maxCoeff()) /
                         lam_scale;
  const Kkt kkt = kkt_residuals(ocp, run.point);
  const Kkt kkt_ref = kkt_residuals(ocp, ref);
  std::printf(
      "[nmpc-ipopt] %s: %s, %d SQP iterations (%d QP iterations), %.4f s | IPOPT %d iterations, "
      "%.2f s\n"
      "[nmpc-ipopt] %s: objective %.15g vs IPOPT %.15g (rel %.2e); max |dx| %.2e, |du| %.2e; "
      "multipliers: dynamics %.2e, all %.2e (rel. to 1 + %.3g); active bounds/rows %d vs %d\n"
      "[nmpc-ipopt] %s: KKT (FD of the plain functions) ours: stat %.2e primal %.2e compl %.2e "
      "sign %.2e; IPOPT's: stat %.2e primal %.2e compl %.2e sign %.2e\n",
      name.c_str(), to_string(run.status), run.info.iterations, run.info.qp_iterations, run.seconds,
      ip.iterations, ip.seconds, name.c_str(), f_ours, f_ref, f_rel, gap.x, gap.u, lam_dyn, lam_all,
      lam_scale - 1, active_count(ocp, run.point, 1e-6), active_count(ocp, ref, 1e-6), name.c_str(),
      kkt.stationarity, kkt.primal, kkt.complementarity, kkt.dual_sign, kkt_ref.stationarity,
      kkt_ref.primal, kkt_ref.complementarity, kkt_ref.dual_sign);
  EXPECT_LE(f_rel, tol.objective);
  EXPECT_LE(gap.x, tol.x);
  EXPECT_LE(gap.u, tol.u);
  EXPECT_LE(lam_dyn, tol.lambda);
  EXPECT_LE(lam_all, tol.lambda);
  EXPECT_LE(kkt.stationarity, tol.kkt);
  EXPECT_LE(kkt.primal, tol.kkt);
  EXPECT_LE(kkt.complementarity, tol.kkt);
  EXPECT_LE(kkt.dual_sign, tol.kkt);
}

}  // namespace nmpc_test
