// arbor::ocp: a multiple-shooting optimal control problem with compile-time sizes:
//
//   min  sum_{k<N} sum_j phi_j(r_j(x_k, u_k, p_k)) + sum_j phi_Nj(r_Nj(x_N, p_N))  (+ slack costs)
//   s.t. x_0 = measured state,  x_{k+1} = F(x_k, u_k, p_k)                  k = 0..N-1
//        lbx <= x_k <= ubx,  lbu <= u_k <= ubu                              (per stage, editable)
//        path constraints on (x_k, u_k, p_k), k = 0..N-1; terminal ones on (x_N, p_N)
//
// Built once from expressions in the stage symbols of Dims (x = Symbol<0, nx>, u = Symbol<1, nu>,
// p = Symbol<2, np>; a generic callable over the scalar becomes one with ad::fn<rows>(f, x, u, p)):
//
//   using D = ocp::Dims<2, 1, 1, 40>;                  // nx, nu, np (>= 1), N
//   auto ode = ad::cat(ad::element<1>(D::x), ...);
//   auto problem = ocp::make_problem<D>(ocp::rk4<4>(ode, 0.05),
//       ocp::path_costs(ocp::least_squares(D::x, 1.0), ocp::least_squares(D::u, 0.1)),
//       ocp::terminal_costs(ocp::least_squares(D::x, 10.0)),
//       ocp::path_constraints(ocp::soft(ocp::constraint(ad::element<0>(D::x), -1, 1), 100)));
//   problem.lbu.fill(-2); problem.ubu.fill(2);       // default bounds of every stage
//
// Soft constraints are allowed on path stages only: their slacks are extra QP inputs (the QP's
// input at stage k is [u_k; s_k], nu + ns entries), and the terminal stage has no input. A
// terminal constraint must therefore be hard (or moved to the last path stage).
// The problem holds expressions by value (RBD calls hold handles to caller-owned workspaces) and
// the default bounds; it evaluates nothing (linearize.hpp does).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <tuple>

#include "arbor/ad/expr/leaves.hpp"
#include "arbor/ocp/terms.hpp"

namespace arbor::ocp {

/// Compile-time sizes of an OCP and its stage symbols.
template <int NX, int NU, int NP, int N>
struct Dims {
  static_assert(NX >= 1 && NU >= 1 && N >= 1, "Dims: nx, nu, N >= 1");
  static_assert(NP >= 1, "Dims: np >= 1 (use np = 1 and leave it unused when there is none)");
  static constexpr int nx = NX;            ///< states
  static constexpr int nu = NU;            ///< inputs
  static constexpr int np = NP;            ///< parameters per stage
  static constexpr int horizon = N;        ///< number of shooting intervals
  static constexpr ad::Symbol<0, NX> x{};  ///< the stage state
  static constexpr ad::Symbol<1, NU> u{};  ///< the stage input
  static constexpr ad::Symbol<2, NP> p{};  ///< the stage parameters
};

/// A list of terms of one kind (cost or constraint, path or terminal).
template <int Kind, class... T>
struct TermList {
  std::tuple<T...> terms;                          ///< the terms
  static constexpr int count = int(sizeof...(T));  ///< number of terms
};
template <class... T>
using PathCosts = TermList<0, T...>;  ///< costs of the path stages
template <class... T>
using TerminalCosts = TermList<1, T...>;  ///< costs of the terminal stage
template <class... T>
using PathConstraints = TermList<2, T...>;  ///< constraints of the path stages
template <class... T>
using TerminalConstraints = TermList<3, T...>;  ///< constraints of the terminal stage

/// Costs of every path stage k < N.
template <class... T>
PathCosts<T...> path_costs(const T&... t) {
  return {{t...}};
}
/// Costs of the terminal stage (expressions in x and p).
template <class... T>
TerminalCosts<T...> terminal_costs(const T&... t) {
  return {{t...}};
}
/// Constraints of every path stage k < N (stage 0 included: x_0 is fixed there, so a hard
/// state-only constraint the measured state violates makes the QP infeasible; make it soft).
template <class... T>
PathConstraints<T...> path_constraints(const T&... t) {
  return {{t...}};
}
/// Constraints of the terminal stage (hard; expressions in x and p).
template <class... T>
TerminalConstraints<T...> terminal_constraints(const T&... t) {
  return {{t...}};
}

namespace detail {
template <class L>
struct ListSizes;
template <int K, class... T>
struct ListSizes<TermList<K, T...>> {
  static constexpr int rows = (0 + ... + T::rows);        ///< nonlinear rows (constraints)
  static constexpr int qp_rows = (0 + ... + T::qp_rows);  ///< QP rows (constraints)
  static constexpr int slacks = (0 + ... + T::slacks);    ///< slacks (constraints)
};
template <int K>
struct ListSizes<TermList<K>> {
  static constexpr int rows = 0, qp_rows = 0, slacks = 0;
};
}  // namespace detail

/// An OCP (see the top of this file). Make one with make_problem<Dims>(...).
template <class D, class Dyn, class PCost, class TCost, class PCon, class TCon>
struct Problem {
  using Dims = D;                                               ///< sizes and symbols
  static constexpr int nx = D::nx;                              ///< states
  static constexpr int nu = D::nu;                              ///< inputs
  static constexpr int np = D::np;                              ///< parameters per stage
  static constexpr int horizon = D::horizon;                    ///< shooting intervals N
  static constexpr int ns = detail::ListSizes<PCon>::slacks;    ///< slacks per path stage
  static constexpr int ng = detail::ListSizes<PCon>::qp_rows;   ///< QP rows per path stage
  static constexpr int ngn = detail::ListSizes<TCon>::qp_rows;  ///< QP rows, terminal stage
  static constexpr int nm = detail::ListSizes<PCon>::rows;      ///< nonlinear rows, path
  static constexpr int nmn = detail::ListSizes<TCon>::rows;     ///< nonlinear rows, terminal
  static_assert(Dyn::rows == nx, "make_problem: the dynamics must return nx rows (x_{k+1})");
  static_assert(detail::ListSizes<TCon>::slacks == 0,
                "terminal constraints must be hard (slacks live in the path stages' inputs)");

  Dyn dynamics;                                             ///< x_{k+1} = F(x_k, u_k, p_k)
  PCost path_costs;                                         ///< costs of the path stages
  TCost terminal_costs;                                     ///< costs of the terminal stage
  PCon path_constraints;                                    ///< constraints of the path stages
  TCon terminal_constraints;                                ///< constraints of the terminal stage
  VecN<double, nx> lbx = VecN<double, nx>::Constant(-inf);  ///< default state lower bounds
  VecN<double, nx> ubx = VecN<double, nx>::Constant(inf);   ///< default state upper bounds
  VecN<double, nu> lbu = VecN<double, nu>::Constant(-inf);  ///< default input lower bounds
  VecN<double, nu> ubu = VecN<double, nu>::Constant(inf);   ///< default input upper bounds
};

/// Builds a Problem from the dynamics and the term lists (constraint lists may be omitted).
template <class D, ad::Expression Dyn, class PCost, class TCost, class PCon = PathConstraints<>,
          class TCon = TerminalConstraints<>>
Problem<D, Dyn, PCost, TCost, PCon, TCon> make_problem(const Dyn& dynamics, const PCost& pc,
                                                       const TCost& tc, const PCon& pcon = {},
                                                       const TCon& tcon = {}) {
  return {dynamics, pc, tc, pcon, tcon};
}

}  // namespace arbor::ocp
