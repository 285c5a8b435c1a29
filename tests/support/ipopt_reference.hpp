// Test support (host only, not part of the library): a dense NLP solved by IPOPT, as an
// independent reference for the NMPC tests (same discretised NLP, IPOPT's solution).
//
//   min f(w)  s.t.  g_l <= g(w) <= g_u,  w_l <= w <= w_u,     w in R^n, g(w) in R^m
//
// The derivatives are IPOPT's own business here, not arbor's: by default the gradient and the
// Jacobian are finite differences of f and g, and the Hessian of the Lagrangian is a finite
// difference of the gradient of the Lagrangian (or IPOPT's L-BFGS). The test may instead give
// its own exact gradient and Jacobian (grad_f, jac_g), written independently of the code under
// test.
//
// Finite differences (step for variable i: h_i = c * max(1, |w_i|), rounded so that w_i + h_i is
// exact):
//   - first derivatives: 4-point central stencil by default (c = eps^(1/5) ~ 7e-4, truncation
//     O(h^4), relative error ~ 1e-12), or the 2-point central one (fd_stencil = 2,
//     c = cbrt(eps) ~ 6e-6, relative error ~ 1e-10, enough for tol ~ 1e-8 only);
//   - Hessian of the Lagrangian sigma f + lambda^T g: for the parts given by finite differences,
//     the central difference of their 2-point central gradient, i.e. second differences of
//     their values (lower triangle only, h = eps^(1/4) ~ 1.2e-4, error ~ 1e-8 relative); for the
//     parts with exact derivatives, the central difference of the exact gradient / Jacobian
//     (h = cbrt(eps)), symmetrised. Its error only slows IPOPT's local convergence a little;
//     the solution is defined by the gradients.
// The functions are evaluated at w +- 2 h_i, possibly slightly outside [w_l, w_u]: they must be
// defined there.
//
// Cost per IPOPT iteration with finite differences: gradient + Jacobian 4n (2n) evaluations of
// f and g; Hessian 2n^2 + 1 evaluations of f and g (2n evaluations of grad_f and jac_g when exact
// ones are given). Measured (pendulum swing-up, RK4 in g, 4-point stencil, loaded 2-core host):
// N = 20 (n = 62, m = 42) 10 iterations, 80k evaluations, 0.2 s; N = 50 (n = 152) 11 iterations,
// 0.5M evaluations, 2.7 s. The 2-point stencil stops at "acceptable" there (noise). L-BFGS
// needs 3k evaluations (0.08 s) for the same objective to 2e-13 (relative). For n in the
// hundreds give exact derivatives or set exact_hessian_by_fd = false (L-BFGS).
//
// Multipliers are returned exactly as IPOPT defines them. The Lagrangian is
//   L(w, lambda, z_l, z_u) = f(w) + lambda^T g(w) - z_l^T (w - w_l) + z_u^T (w - w_u)
// and at a solution
//   grad f(w) + J_g(w)^T lambda - z_l + z_u = 0,   z_l >= 0, z_u >= 0,
//   lambda_i >= 0 when g_i is at its upper bound g_u,i; lambda_i <= 0 at its lower bound g_l,i;
//   lambda_i of either sign for an equality (g_l,i == g_u,i); 0 (to tolerance) when inactive.
// z_l, z_u are 0 (to tolerance) for inactive or absent bounds.
//
// Options set: sb = yes (no banner), print_level, tol, max_iter, hessian_approximation, and
// bound_relax_factor = 0 (IPOPT's default 1e-8 relaxes every bound and moves a solution at an
// active bound by ~1e-8; here the NLP is solved as stated). IpoptOptions' extra options come
// last and override these. An unknown option is reported by IPOPT on stdout, then thrown.
//
// IPOPT 3.11.9 (Debian 12, coinor-libipopt-dev) with MUMPS (sequential) as its only linear
// solver: linear_solver ma27/ma57/ma86/pardiso/wsmp return Invalid_Option (-12), and ma97 ends
// the process (exit 1, no libhsl.so). Treat it as not thread safe (sequential MUMPS); call from
// one thread at a time.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace arbor::test {

/// A dense NLP: min f(w) s.t. g_l <= g(w) <= g_u, w_l <= w <= w_u.
struct Nlp {
  int n = 0;                                 ///< number of variables
  int m = 0;                                 ///< number of constraints (0 allowed)
  std::function<double(const double* w)> f;  ///< objective
  /// m constraint values (may be empty if m == 0)
  std::function<void(const double* w, double* g)> g;
  /// Optional exact gradient of f (n values). Empty: finite differences of f.
  std::function<void(const double* w, double* grad)> grad_f;
  /// Optional exact Jacobian of g, dense m x n row-major. Empty: finite differences of g.
  std::function<void(const double* w, double* jac)> jac_g;
  /// Bounds (sizes n, n, m, m; empty means "none" for all) and the initial guess (size n; empty
  /// means zeros). A bound beyond +-1e19 (+-1e20 or +-inf) is none; g_l == g_u is an equality.
  std::vector<double> w_l, w_u, g_l, g_u, w0;
};

/// Solver settings. The extra options are passed to IPOPT after the ones set from the fields
/// (so they override them), e.g. {"mu_strategy", "adaptive"} or {"derivative_test", ...}.
struct IpoptOptions {
  double tol = 1e-10;               ///< IPOPT "tol" (scaled KKT error)
  int max_iter = 3000;              ///< IPOPT "max_iter"
  bool exact_hessian_by_fd = true;  ///< FD Hessian of the Lagrangian; false: L-BFGS
  int print_level = 0;              ///< IPOPT "print_level" (0: silent, 5: IPOPT's default)
  int fd_stencil = 4;               ///< 4- or 2-point central differences for f and g
  std::vector<std::pair<std::string, std::string>> string_options;
  std::vector<std::pair<std::string, double>> number_options;
  std::vector<std::pair<std::string, int>> int_options;
};

/// IPOPT's answer. status is IPOPT's ApplicationReturnStatus (0 Solve_Succeeded,
/// 1 Solved_To_Acceptable_Level, ...); success means status == 0. Multipliers: see above.
struct IpoptResult {
  int status = 0;
  bool success = false;
  std::vector<double> w;         ///< solution (n)
  std::vector<double> lambda_g;  ///< constraint multipliers (m)
  std::vector<double> z_l, z_u;  ///< bound multipliers (n each), >= 0
  double objective = 0;          ///< f(w)
  int iterations = 0;            ///< IPOPT iterations (last iter_count seen)
  std::vector<double> g;         ///< g(w) (m)
  long f_evaluations = 0;        ///< calls of nlp.f (including finite differences)
  long g_evaluations = 0;        ///< calls of nlp.g (including finite differences)
  double seconds = 0;            ///< wall-clock time of IpoptSolve
  std::string status_name;       ///< the enum's name, e.g. "Solve_Succeeded"
};

/// Solves the NLP with IPOPT. Throws std::invalid_argument for inconsistent sizes or missing
/// functions; IPOPT's failures come back in the status.
IpoptResult solve_with_ipopt(const Nlp& nlp, const IpoptOptions& options = {});

/// The name of an IPOPT ApplicationReturnStatus value.
std::string ipopt_status_name(int status);

}  // namespace arbor::test
