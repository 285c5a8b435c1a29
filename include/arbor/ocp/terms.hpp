// arbor::ocp: the terms of an optimal control problem, each built from an inner expression in the
// stage symbols (x = Symbol<0, nx>, u = Symbol<1, nu>, p = Symbol<2, np>; terminal terms use x
// and p only):
//   cost(r, phi)               phi(r(x, u, p)), phi an outer convex function (outer.hpp)
//   least_squares(r, w)        sum_i w_i r_i^2 (w a number or an array of M weights)
//   constraint(g, lg, ug)      lg <= g(x, u, p) <= ug, M rows (bounds may be +-infinity)
//   convex_constraint(c, psi)  psi(c(x, u, p)) <= 0, one row (e.g. Ball: |c| <= rho)
//   soft(constraint, l1, l2)   the same with an exact-penalty slack s >= 0 per row:
//                              lg - s <= g <= ug + s (psi <= s), cost l1 s + l2 s^2 per slack.
//                              With l1 above the constraint's multiplier the slack stays zero
//                              whenever the hard problem is feasible (exact penalty); l2 > 0
//                              alone is a quadratic penalty (never exact).
// Sizes are compile-time: a constraint term knows its nonlinear rows (`rows`), its slacks
// (`slacks`: one per row when soft), the sides of a soft row (`sides`: 2 for a lower and an upper
// QP row, 1 for a kind without lower bound) and from these its QP rows (`qp_rows`). Nothing is
// evaluated here (linearize.hpp does that, and lays the rows out).
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <type_traits>

#include "arbor/ad/expr/values.hpp"
#include "arbor/ocp/outer.hpp"

namespace arbor::ocp {

namespace detail {
/// QP rows of a constraint term with `rows` nonlinear rows: one per row when hard; when soft,
/// `sides` per row (a lower and an upper row, or the upper alone), each with the row's slack.
constexpr int constraint_qp_rows(int rows, bool soft, int sides) {
  return soft ? sides * rows : rows;
}
}  // namespace detail

/// A cost term phi(r(x, u, p)).
template <ad::Expression E, class Phi>
struct Cost {
  static_assert(OuterFunction<Phi, E::rows>, "cost: phi must be an outer function of r");
  static constexpr int rows = E::rows;  ///< size of r
  E r;                                  ///< inner expression
  Phi phi;                              ///< outer convex function
};

/// A constraint lg <= g(x, u, p) <= ug (Soft: with one slack per row).
template <ad::Expression E, bool Soft>
struct Constraint {
  static constexpr int rows = E::rows;            ///< nonlinear rows
  static constexpr bool soft = Soft;              ///< has slacks
  static constexpr int slacks = Soft ? rows : 0;  ///< slack variables
  static constexpr int sides = 2;                 ///< QP rows per soft row (lower, upper)
  static constexpr int qp_rows = detail::constraint_qp_rows(rows, Soft, sides);  ///< in the QP
  E g;                                       ///< inner expression
  std::array<double, std::size_t(rows)> lg;  ///< lower bounds (may be -inf)
  std::array<double, std::size_t(rows)> ug;  ///< upper bounds (may be +inf)
  double l1 = 0;                             ///< slack cost l1 s (Soft only)
  double l2 = 0;                             ///< slack cost l2 s^2 (Soft only)
};

/// A convex-over-nonlinear constraint psi(c(x, u, p)) <= 0 (Soft: psi <= s, s >= 0).
template <ad::Expression E, class Psi, bool Soft>
struct ConvexConstraint {
  static_assert(OuterFunction<Psi, E::rows>, "convex_constraint: psi must be an outer function");
  static constexpr int rows = 1;               ///< nonlinear rows
  static constexpr bool soft = Soft;           ///< has a slack
  static constexpr int slacks = Soft ? 1 : 0;  ///< slack variables
  static constexpr int sides = 1;              ///< QP rows per soft row (upper: psi <= s)
  static constexpr int qp_rows = detail::constraint_qp_rows(rows, Soft, sides);  ///< in the QP
  E c;            ///< inner expression
  Psi psi;        ///< outer convex function
  double l1 = 0;  ///< slack cost l1 s (Soft only)
  double l2 = 0;  ///< slack cost l2 s^2 (Soft only)
};

/// phi(r): a convex-over-nonlinear cost.
template <ad::Expression E, class Phi>
Cost<E, Phi> cost(const E& r, const Phi& phi) {
  return {r, phi};
}

/// sum_i w_i r_i^2.
template <ad::Expression E>
Cost<E, WeightedSquares<E::rows>> least_squares(const E& r,
                                                const std::array<double, std::size_t(E::rows)>& w) {
  return {r, WeightedSquares<E::rows>{w}};
}
/// w |r|^2.
template <ad::Expression E>
Cost<E, WeightedSquares<E::rows>> least_squares(const E& r, double w) {
  WeightedSquares<E::rows> phi;
  phi.w.fill(w);
  return {r, phi};
}

/// lg <= g <= ug, row by row.
template <ad::Expression E>
Constraint<E, false> constraint(const E& g, const std::array<double, std::size_t(E::rows)>& lg,
                                const std::array<double, std::size_t(E::rows)>& ug) {
  return {g, lg, ug};
}
/// lg <= g_i <= ug for every row.
template <ad::Expression E>
Constraint<E, false> constraint(const E& g, double lg, double ug) {
  Constraint<E, false> c{g, {}, {}};
  c.lg.fill(lg);
  c.ug.fill(ug);
  return c;
}

/// psi(c) <= 0.
template <ad::Expression E, class Psi>
ConvexConstraint<E, Psi, false> convex_constraint(const E& c, const Psi& psi) {
  return {c, psi};
}

/// The soft version of a hard constraint: slacks costing l1 s + l2 s^2 (see the top of this file).
template <ad::Expression E>
Constraint<E, true> soft(const Constraint<E, false>& c, double l1, double l2 = 0) {
  return {c.g, c.lg, c.ug, l1, l2};
}
/// The soft version of a hard convex constraint: psi(c) <= s, cost l1 s + l2 s^2.
template <ad::Expression E, class Psi>
ConvexConstraint<E, Psi, true> soft(const ConvexConstraint<E, Psi, false>& c, double l1,
                                    double l2 = 0) {
  return {c.c, c.psi, l1, l2};
}

/// The infinity used for an absent bound.
inline constexpr double inf = std::numeric_limits<double>::infinity();

}  // namespace arbor::ocp
