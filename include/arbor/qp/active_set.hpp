// arbor::qp::detail: the primal-dual active-set logic shared by the dense and the OCP solvers.
//
// Problem (flat form; the OCP solver flattens its stages into it):
//   min 1/2 x'Hx + g'x   s.t.  lbx <= x <= ubx,  lba <= A x <= uba,   x in R^NV, A x in R^NA.
// Stack z = [x; A x] (NZ = NV + NA) with one multiplier lam = [lam_x; lam_a]; stationarity reads
// H x + g + lam_x + A' lam_a = 0; lam_i > 0 means "upper bound active", lam_i < 0 "lower active".
//
// Method (in the style of CasADi's QRQP primal-dual active-set solver; our own implementation):
// - An explicit int8 working set ws (ConstraintState in backend.hpp: inactive, lower, upper,
//   equality) is built from the multipliers' signs at the start of every solve (warm start =
//   keep x and lam), and kept consistent afterwards: an inactive constraint has lam_i == 0
//   exactly.
// - Each iteration evaluates the residuals and makes at most ONE working-set change: a pending
//   change from the last ratio test, else, if the (scaled) primal error dominates, the most
//   violated constraint is added on its violated side, else the active constraint whose
//   multiplier has the most wrong sign is dropped. Violations and multipliers are compared per
//   constraint: row i's violation is divided by |a_i|, its multiplier multiplied by |a_i| (the
//   same quantities for any scaling of the row), against the thresholds of the termination test.
//   The first iteration of a warm start (the multipliers name at least one inequality) adds
//   nothing: it steps on the working set they name, and a constraint violated only at the start
//   point (the NMPC's extrapolated terminal state beyond a velocity bound) is added only if that
//   step leaves it violated (adding it first would add and then drop it: two iterations).
// - The step goes to the solution of the equality-constrained QP of the working set, with a
//   proximal regularisation centred at the current iterate (delta = reg_primal on x,
//   epsilon = reg_dual on the active multipliers):
//     (H + delta I + A_W' E A_W) dx = -(H x + g + A' lam) - A_W' E (A_W x - t_W)
//     dlam_W = E (A_W (x + dx) - t_W),   dlam_i = 0 off the working set,
//   with E = diag(h / (eps |a_i|^2)) (rows normalised; |a_i| = 1 for bounds; h = 1, or with
//   QpSettings::relative_regularisation the largest |H_ii| (1 when H = 0): the weights then
//   dominate the curvature by 1 / eps at every scale of the cost, and a cost multiplied by s
//   gives the same steps, multipliers multiplied by s).
//   A backend that solves some rows exactly (ExactRowBackend in backend.hpp: the OCP's dynamics
//   rows, by a Riccati recursion) leaves them out of E: they hold exactly, D (x + dx) = t_D,
//   and their multiplier steps dlam_D come from its solve (compute_step(); the rows are
//   equalities, so the working-set logic never adds or drops them). Such a backend may hold
//   some bounds exactly too (exact_bound(i): the OCP's inputs and x_0, whose variable it fixes):
//   while in the working set they take no weight, the step puts the variable on its bound
//   (dx_i = t_i - x_i) and their multiplier steps come from the solve as well.
//   A full step that nothing blocks misses the weighted constraints by eps |dlam_i| |a_i|; when
//   that would fail the primal test, refine_step() adds one more proximal step on the same
//   factorization (centred at the new multipliers), so that a warm start on the right working
//   set ends after one iteration instead of two.
//   The matrix is positive definite for any convex H, whatever the working set: redundant or
//   linearly dependent active constraints and directions of zero curvature (states without
//   cost, LPs) never make it singular. Along a zero-curvature direction the step is long
//   (~ gradient / delta) and the ratio test stops it at the first blocking constraint: this is
//   QRQP's null-space step, obtained without predicting the singularity. Because the proximal
//   terms are centred at the iterate, a fixed point is an exact KKT point; repeated iterations
//   on an unchanged working set reuse the factorization and act as iterative refinement.
// - When the primal error stalls on an unchanged working set (a nearly inconsistent one), the
//   multipliers are moved along their step to the first active one that reaches zero, which is
//   dropped (QRQP's singular step in multiplier space). Anti-cycling: the last kDropMemory
//   constraints dropped this way are remembered; a constraint that comes back and would be
//   dropped again is kept (the error stalls at round-off, not on an inconsistent set), and the
//   refusal is counted in SolveInfo::cycling_refusals (without the rule, round-off can drop and
//   re-add the same bounds until the iteration cap: the float Kinova-sized problem of bench/qp).
// - Ratio test on tau in [0, 1]: inactive constraints may not cross their bound by more than
//   |a_i| max(tol_primal * scale, current max per-constraint violation) (primal blocking ->
//   pending add), active multipliers of the right sign may not cross zero (dual break point ->
//   pending drop).
// - Termination by an explicit check on the original data, judged per constraint:
//     primal     max_i violation_i / |a_i|                 <= tol_primal * pscale,
//     dual       max_j |(H x + g + lam_x + A' lam)_j|     <= tol_dual * dscale,
//     compl.     max_i min(|lam_i| |a_i|, dist_i / |a_i|)  <= tol_comp * pscale,
//   with pscale = 1 + max(1, |x|_inf, max_i |z_i| / |a_i|) and dscale = 1 + the largest term of
//   the stationarity sum, dist_i the distance of z_i to the bound lam_i's sign selects. Scaling
//   a row changes none of these (stationarity contains a_i lam_i only), so `solved` is never
//   returned at a point that violates a row relative to its own size. SolveInfo reports the
//   residuals as the data state them (unnormalised).
// - Infeasibility: every step's multiplier change y = dlam is tested as a Farkas certificate
//   (after the next evaluate(), unless that one ends the loop as `solved`, or at the iteration
//   cap with no certificate before it, where one more could not change the status:
//   settle_farkas()):
//   with y normalised (sum |y_i| |a_i| = 1), entries on a side with an infinite bound left out,
//   e = y_x + A' y_a and sigma = sum_{y_i>0} ub_i y_i + sum_{y_i<0} lb_i y_i, every x has
//   y'z = e'x and every feasible x has y'z <= sigma; with bscale the largest |bound_i| / |a_i|
//   involved, sigma < -10 tol_primal (1 + bscale) and |e|_1 (1 + bscale) <= tol_certificate
//   |sigma| prove that no point within (1 + bscale) / tol_certificate is feasible (scales of the
//   data, not of the iterate, which a long step along a free direction may have inflated). On an
//   inconsistent working set dlam settles on such a direction within a few iterations whatever the
//   size of H or of the rows (the multipliers themselves turn slowly when the cost is large).
//   Two consecutive certificates give `infeasible`.
// - A full step along a zero-curvature descent direction that no constraint blocks gives
//   `unbounded`. kStallIterations iterations without a working-set change in which the merit
//   (largest residual / tolerance) does not fall by 10 % give `stalled`: the rule has nothing
//   left to change although the test fails (tolerances below the round-off floor, or mutually
//   inconsistent ones). `stalled` and the iteration cap return the best iterate seen, with its
//   residuals (the cap: the last one with QpSettings::last_iterate_at_cap).
// Memory of this part: about 14 NV + 9 NA scalars and 2 (NV + NA) bytes. Cost per iteration: O(NV +
// NA) here plus one backend solve (and one product with A' while the iterate is infeasible, for
// the certificate), and a (partial) refactorization after a working-set change.
// Products: evaluate() needs A x, H x and H x + g + lam_x + A' lam. After a step that a
// constraint blocked (the iteration goes on: the blocking constraint enters or leaves next) they
// are updated instead of recomputed, A x += tau A dx with the step's A dx, H x += tau H dx and
// A' times the multipliers' change: one product with A fewer per such iteration (a product with H
// and one with A' are left). They are computed from scratch at the start (A x and H x are zero
// at x = 0: not formed), after a full unblocked step (the next evaluate() may end the loop), every
// kExactEvery steps, at the iteration cap, and whenever the loop would end on updated ones (the
// test is repeated on products from scratch): every status and every residual reported belongs
// to the returned point as computed from the data.
// Prepared start (ActiveSetCore::prepare_start(), solve_from(): the NMPC's feedback, whose QP
// differs from the prepared one only in the targets of x_0's bounds): active_set_prepared.hpp.
// The linear algebra lives in a backend satisfying ActiveSetBackend (backend.hpp). solve() runs
// the steps below in this order (iterate()), each a member function: begin() once, then per
// iteration evaluate() (solve_from()'s first: scan_moved(); the pass a ResidualScan),
// settle_farkas() (the previous step's farkas_step()), a second evaluate() from scratch when the
// loop may end on updated products,
// converged_or_stopped(), change_working_set(), refactorize(), compute_step() (solve_from()'s
// first, when nothing changed: move_presolved_step()), ratio_test(), refine_step(),
// singular_dual_step(), take_step(); finish() once.
// Files: active_set_core.hpp (the class and the order of the steps), active_set_evaluate.hpp,
// active_set_step.hpp, active_set_termination.hpp (the steps), residual_scan.hpp (the pass over
// the constraints), prepared_start.hpp and active_set_prepared.hpp (the prepared start).
#pragma once

#include "arbor/qp/active_set_core.hpp"
#include "arbor/qp/active_set_evaluate.hpp"
#include "arbor/qp/active_set_prepared.hpp"
#include "arbor/qp/active_set_step.hpp"
#include "arbor/qp/active_set_termination.hpp"
