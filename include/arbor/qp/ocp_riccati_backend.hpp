// arbor::qp::detail: exact-dynamics linear algebra of the OCP solver: a backward square-root
// Riccati recursion on the stage blocks, with the dynamics rows solved exactly (no proximal
// weight) and their multipliers (the costates) returned by the solve; an ExactRowBackend
// (backend.hpp).
//
// Each iteration of the active-set method (active_set.hpp) solves, for the working set W,
//   G dx + D' dnu = f,   D dx = e
// with D the dynamics rows dyn_k = x_{k+1} - A_k x_k - B_k u_k (exact), G block diagonal: the
// stage Hessian [Q S'; S R] plus delta I, the weight w of the active bounds and e_j c_j c_j' of the
// active path rows (the proximal terms of active_set.hpp, unchanged). Per stage, with the stage
// variables ordered (u_k, x_k) and F_k = [B_k A_k]:
//   P_N = G_N = L_N L_N'
//   M_k = G_k + F_k' P_{k+1} F_k = L_k L_k'    (Cholesky, NW = NU + NX; (u, x) order)
//   P_k = Lxx_k Lxx_k'                         (the Schur complement of u_k in M_k: the trailing
//                                               NX x NX block of L_k, no extra work)
// F_k' P_{k+1} F_k is formed as T' T with T = Lxx_{k+1}' F_k (triangular times dense). Per stage
// in multiply-adds: NX^2 NW / 2 (T) + NW (NW+1) NX / 2 (T' T) + NW^3 / 6 (Cholesky):
// 3.1 k + 4.8 k + 2.3 k = 10.2 k for NX = 16, NU = 8; the dynamics hold exactly, so no 1/eps
// weight enters the matrix.
// solve_exact(): backward, h_k = f_k + F_k' Lxx_{k+1} (y_{x,k+1} - Lxx_{k+1}' e_k), y_k =
// L_k^-1 h_k; forward, from dx_0 = L_0^-T y_0: du_k = Luu^-T (y_u - Lxu' dx_k), the costate
// dnu_{k-1} = Lxx_k (y_{x,k} - Lxx_k' dx_k), dx_{k+1} = F_k dw_k + e_k. ~NW^2 / 2 + NU NW + 4 NX NW
// + 2 NX^2 multiply-adds per stage (1.8 k for the Kinova size).
// Two variants skip what a known-zero right-hand side makes zero: ZeroRhs (e and the fixed steps
// zero: refine_step()) and InitialOnly (only x_0's fixed steps nonzero: the presolved feedback's
// response, active_set.hpp; the backward sweep of stages N..1 is skipped).
// Instruction counts per factorization and solve are in bench/qp/RESULTS.md (bench/qp/qp_count).
// The [A B] products per stage are written per column where Eigen vectorises them
// (ocp_products.hpp, lazy_products). This is the default backend of OcpQpSolver
// (ocp_qp_solver.hpp).
// Exact bounds (exact_bound()): a working bound of an input u_k or of x_0 fixes its variable
// instead of adding the weight w: its row and column of M_k become the unit vector (the
// recursion runs on the other variables; P_k is the Schur complement of the free inputs only).
// solve_exact() moves G_k c and F_k c (c: the fixed variables' steps) to the right-hand sides,
// and returns their multipliers dlam_j = f_j - (G_k dw)_j + (F_k' dnu_k)_j. (A bound on x_k,
// k >= 1, would be an equality on stage k-1's variables through the dynamics: those bounds keep
// the weight.) Fixing a variable deletes its column of L_k (the part below the diagonal is
// rotated into the later columns: an update, always safe), freeing one inserts the column again
// (row j left of the diagonal by a triangular solve, then a downdate of the later columns); both
// carry P_k's change down like a rank-one update.
// Working-set changes: a bound or path row of stage k changes M_k by +-v v'; the rank-one update
// (downdate) of L_k leaves, after its u columns, the vector v^ with P_k +-= v^ v^', so M_{k-1}
// changes by +-(F_{k-1}' v^)(F_{k-1}' v^)': one sweep from stage k down to stage 0,
// O(NW^2 + NX NW) per stage. An unsafe downdate (r^2 < sqrt(eps) L_jj^2) refactorizes stages
// k..0 instead (k + 1 stage factorizations); after max_updates updates the next factorization
// is a full one.
// Memory (scalars): N NW (NW+1)/2 + NX (NX+1)/2 for the factor (no off-diagonal blocks), plus
// NV + NA bytes. Stack: an NW x NW scratch, [B A]', T' and an unpacked Lxx during a stage's
// factorization (the transposed copies by kernels::transpose, T' assigned by the product, M_k's
// upper part not filled where the kernels do not read it).
// Files: ocp_riccati_factor.hpp (the state and the factorization), ocp_riccati_solve.hpp (the
// solve), ocp_riccati_update.hpp (the rank-one updates).
#pragma once

#include "arbor/qp/ocp_riccati_factor.hpp"
#include "arbor/qp/ocp_riccati_solve.hpp"
#include "arbor/qp/ocp_riccati_update.hpp"
