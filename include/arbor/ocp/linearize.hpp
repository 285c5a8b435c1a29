// arbor::ocp: one SQP linearisation of a stage, written straight into the QP's stage blocks (delta
// form: the QP variables are the steps dx_k, [du_k; ds_k]):
//   dynamics     A_k = dF/dx, B_k = [dF/du, 0] (slack columns zero),
//                b_k = F(x_k, u_k, p_k) - x_{k+1}
//   cost         q, r = gradient of the stage cost (slacks: l1 + 2 l2 s)
//   Hessian      Gauss-Newton (SCQP): sum J_r' grad^2 phi J_r + sum mu_i J_c' grad^2 psi_i J_c
//                (mu_i = max(0, multiplier) of convex constraint i), slacks 2 l2: positive
//                semidefinite by construction, no second derivative of any inner function;
//                exact: the Hessian of the stage Lagrangian in (x, u) from the expression layer
//                (nested duals); it may be indefinite (nmpc/ falls back to Gauss-Newton then)
//   constraints  rows in the order of the terms: a hard constraint g gives lg - g <= J d <= ug - g;
//                a soft one with slack s gives a lower row J d + ds >= lg - g - s and an upper row
//                J d - ds <= ug - g + s; a convex constraint gives grad psi' J_c d <= -psi(c)
//                (soft: grad psi' J_c d - ds <= -psi(c) + s)
// One routine serves both stage kinds: the terminal stage is a stage without input (nu = ns = 0,
// x seeded alone, no D block, no dynamics). Each constraint kind states its rows, Gauss-Newton
// term and violation once (detail::ConstraintKind); the QP-row layout of hard and soft rows, the
// slacks' costs and the rows' multipliers are detail::place_rows' alone.
// Variable bounds and the embedding of x_0 are the solver's (nmpc/): they change without
// relinearising. Multipliers follow the QP's sign convention (qp/problem.hpp): the stage
// Lagrangian is f + lam_dyn' (x_{k+1} - F) + mu' g.
// Cost per path stage: one evaluation of F and of each inner function at Dual<T, nx + nu> (in one
// environment: the arguments are seeded once), and the Gauss-Newton products: with the provided
// outer functions (diagonal Hessians) sum_i nnz_i^2 / 2 multiply-adds over the structurally
// nonzero entries of each row of J (known at compile time from the expression: a stacked
// residual's input and state rows have one; the lower triangle, mirrored once), else
// O(rows^2 n + rows n^2); the gradient J' grad phi over the same entries; exact
// Hessians add one evaluation of the Lagrangian at Dual<Dual<T, n>, n> and an n x n
// eigen-decomposition.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <tuple>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/blocks.hpp"
#include "arbor/ad/expr/elementwise.hpp"
#include "arbor/ad/expr/evaluate.hpp"
#include "arbor/ad/expr/reductions.hpp"
#include "arbor/ad/expr/structure.hpp"
#include "arbor/core/math.hpp"
#include "arbor/ocp/outer.hpp"
#include "arbor/ocp/problem.hpp"
#include "arbor/qp/problem.hpp"

namespace arbor::ocp {

/// Which Hessian a linearisation builds.
enum class HessianKind : unsigned char {
  gauss_newton,  ///< SCQP: from the outer functions' Hessians (PSD by construction)
  exact,         ///< exact Hessian of the Lagrangian (may be indefinite)
};

/// Name of a HessianKind value.
constexpr const char* to_string(HessianKind h) {
  switch (h) {
    case HessianKind::gauss_newton:
      return "gauss_newton";
    case HessianKind::exact:
      return "exact";
  }
  return "unknown";
}

/// QP rows of a stage: the constraints' rows, or one free row (C = 0, bounds +-inf) when there
/// are none (the QP solver is instantiated with at least one row per stage).
constexpr int qp_rows(int rows) {
  return rows > 0 ? rows : 1;
}

/// The QP a problem P linearises into, at scalar T.
template <class P, class T>
using QpOf = qp::OcpQp<T, P::horizon, P::nx, P::nu + P::ns, qp_rows(P::ng), qp_rows(P::ngn)>;

/// Cost and L1 infeasibility of a stage (merit function pieces; bounds excluded).
template <class T>
struct StageMerit {
  T cost = T(0);       ///< stage cost, slack costs included
  T violation = T(0);  ///< sum of |F - x_next| and of the constraints' violations
};

namespace detail {

template <class Tuple, class F>
void for_each_term(const Tuple& t, F&& f) {
  std::apply([&](const auto&... term) { (f(term), ...); }, t);
}

/// The lower triangle of hess += scale J' grad^2 phi(r) J (the Gauss-Newton term of an outer
/// function phi of an m-row inner function with Jacobian J, m x n); the strict upper triangle of
/// hess is not touched (symmetrize_lower() completes it once all terms are in). Pat (an
/// ad::detail::RowPattern) lists, per row of J, the columns that may be nonzero (the expression's
/// structure, known at compile time: a row of a stacked residual typically depends on a few
/// variables, an input, a state, the joints). With a diagonal Hessian (DiagonalHessian) the
/// product is a sum of rank-one updates h_i J_i' J_i over those columns of each row J_i:
/// O(sum_i nnz_i^2) instead of O(m^2 n + m n^2) (entries that are zero at the point are skipped
/// too, which changes nothing but the order of the sums); otherwise H J is formed first (lazy
/// products: no general matrix-product kernel for these fixed small sizes).
template <auto Pat, class Phi, class T, int m, int n>
void add_gauss_newton_lower(MatN<T, n>& hess, const Phi& phi, const VecN<T, m>& r,
                            const Eigen::Matrix<T, m, n>& J, T scale) {
  if constexpr (DiagonalHessian<Phi, T, m>) {
    const VecN<T, m> h = phi.template hessian_diagonal<T, m>(r);
    int idx[n];
    T val[n];
    for (int i = 0; i < m; ++i) {
      const T hi = scale * h[i];
      if (known_zero(hi))
        continue;
      // the row's entries in the pattern that are not zero at this point (a pattern may be a
      // superset: an unanalysed node's rows have every direction)
      int c = 0;
      for (int a = 0; a < Pat.count[std::size_t(i)]; ++a) {
        const int k = Pat.cols[std::size_t(i)][std::size_t(a)];
        const T v = J(i, k);
        if (!known_zero(v)) {
          idx[c] = k;
          val[c] = v;
          ++c;
        }
      }
      for (int a = 0; a < c; ++a) {
        const T va = hi * val[a];
        for (int b = 0; b <= a; ++b)
          hess(idx[a], idx[b]) += va * val[b];
      }
    }
  } else {
    const Eigen::Matrix<T, m, n> HJ = phi.template hessian<T, m>(r).lazyProduct(J);
    for (int b = 0; b < n; ++b)
      for (int a = b; a < n; ++a)
        hess(a, b) += scale * J.col(a).dot(HJ.col(b));
  }
}

/// grad += J' g over the columns of each row of J that Pat lists (see add_gauss_newton_lower).
template <auto Pat, class T, int m, int n>
void add_transposed_product(VecN<T, n>& grad, const Eigen::Matrix<T, m, n>& J,
                            const VecN<T, m>& g) {
  for (int i = 0; i < m; ++i) {
    const T gi = g[i];
    const int c = Pat.count[std::size_t(i)];
    const auto& idx = Pat.cols[std::size_t(i)];
    for (int a = 0; a < c; ++a)
      grad[idx[std::size_t(a)]] += J(i, idx[std::size_t(a)]) * gi;
  }
}

/// The row pattern (ad::detail::RowPattern) of expression E's Jacobian in environment Env.
template <class Env, class E>
inline constexpr auto jacobian_pattern =
    ad::detail::row_pattern<E::rows, Env::Scalar::directions>(ad::detail::row_deps<Env, E>());

/// Copies the lower triangle of hess to its upper triangle.
template <class T, int n>
void symmetrize_lower(MatN<T, n>& hess) {
  for (int b = 0; b < n; ++b)
    for (int a = b + 1; a < n; ++a)
      hess(b, a) = hess(a, b);
}

/// grad += J' grad phi(r) for every cost term at the point of env (n seeded variables) and, for
/// Gauss-Newton, the lower triangle of hess += J' grad^2 phi(r) J.
template <HessianKind H, class Costs, class Env, class T, int n>
void add_costs(const Costs& costs, const Env& env, VecN<T, n>& grad, MatN<T, n>& hess) {
  for_each_term(costs.terms, [&](const auto& c) {
    constexpr int m = std::remove_cvref_t<decltype(c)>::rows;
    constexpr auto pat = jacobian_pattern<Env, decltype(c.r)>;
    const auto [rv, J] = ad::detail::value_and_jacobian_in(env, c.r);
    add_transposed_product<pat>(grad, J, c.phi.template gradient<T, m>(rv));
    if constexpr (H == HessianKind::gauss_newton)
      add_gauss_newton_lower<pat>(hess, c.phi, VecN<T, m>(rv), J, T(1));
  });
}

/// How a constraint kind of terms.hpp enters a stage, one specialisation per kind (its QP rows
/// are laid out by place_rows, its sizes and soft sides declared by the term type):
///   linearize<H>(c, env, hess, place)  at the point of env (n seeded variables), passes the
///       Jacobian J (rows x n) of the kind's nonlinear rows and the bounds of J d relative to the
///       value (lo = lg - g, hi = ug - g; -inf or inf where absent) to place(J, lo, hi), which
///       writes the QP rows and returns the rows' multipliers mu; for Gauss-Newton it then adds
///       the kind's curvature term at mu to the lower triangle of hess
///   lagrangian_term<off>(c, mu)  the term's part mu' g of the stage Lagrangian, an expression in
///       the multiplier symbol mu, its rows' multipliers from entry off (the exact Hessian's)
///   add_violation(c, x, u, p, s, v)  v += how far each row lies outside [lg - s(i), ug + s(i)]
///       (s(i): row i's slack, 0 when hard)
template <class C>
struct ConstraintKind;

/// lg <= g <= ug: the rows of g. A constraint's curvature is not part of the Gauss-Newton
/// Hessian (it needs the inner function's second derivatives).
template <ad::Expression E, bool Soft>
struct ConstraintKind<Constraint<E, Soft>> {
  using C = Constraint<E, Soft>;
  template <HessianKind H, class Env, class T, int n, class Place>
  static void linearize(const C& c, const Env& env, MatN<T, n>&, Place&& place) {
    const auto [gv, J] = ad::detail::value_and_jacobian_in(env, c.g);
    VecN<T, C::rows> lo, hi;
    for (int i = 0; i < C::rows; ++i) {
      lo[i] = T(c.lg[std::size_t(i)]) - gv[i];
      hi[i] = T(c.ug[std::size_t(i)]) - gv[i];
    }
    place(J, lo, hi);
  }
  template <int off, class Mu>
  static auto lagrangian_term(const C& c, const Mu& mu) {
    return ad::dot(ad::segment<off, C::rows>(mu), c.g);
  }
  template <class X, class U, class Pv, class S, class T>
  static void add_violation(const C& c, const X& x, const U& u, const Pv& p, const S& s, T& v) {
    const auto g = ad::evaluate(c.g, x, u, p);
    for (int i = 0; i < C::rows; ++i) {
      const T lo = T(c.lg[std::size_t(i)]) - s(i) - g[i],
              hi = g[i] - s(i) - T(c.ug[std::size_t(i)]);
      v += positive_part(lo) + positive_part(hi);
    }
  }
};

/// psi(c) <= 0: one row grad psi' J_c d <= -psi(c), no lower bound; its Gauss-Newton term is
/// max(mu, 0) J_c' grad^2 psi J_c (convex psi: positive semidefinite; skipped at mu <= 0).
template <ad::Expression E, class Psi, bool Soft>
struct ConstraintKind<ConvexConstraint<E, Psi, Soft>> {
  using C = ConvexConstraint<E, Psi, Soft>;
  template <HessianKind H, class Env, class T, int n, class Place>
  static void linearize(const C& c, const Env& env, MatN<T, n>& hess, Place&& place) {
    constexpr int m = E::rows;
    const auto [cv, J] = ad::detail::value_and_jacobian_in(env, c.c);
    const Eigen::Matrix<T, 1, n> jrow = c.psi.template gradient<T, m>(cv).transpose() * J;
    const VecN<T, 1> lo = VecN<T, 1>::Constant(-std::numeric_limits<T>::infinity());
    const VecN<T, 1> hi = VecN<T, 1>::Constant(-c.psi.template value<T, m>(cv));
    const VecN<T, 1> mu = place(jrow, lo, hi);
    if constexpr (H == HessianKind::gauss_newton) {
      const T scale = positive_part(mu[0]);
      if (!known_zero(scale))
        add_gauss_newton_lower<jacobian_pattern<Env, E>>(hess, c.psi, VecN<T, m>(cv), J, scale);
    }
  }
  template <int off, class Mu>
  static auto lagrangian_term(const C& c, const Mu& mu) {
    return ad::element<off>(mu) * OuterExpr<Psi, E>{c.psi, c.c};
  }
  template <class X, class U, class Pv, class S, class T>
  static void add_violation(const C& c, const X& x, const U& u, const Pv& p, const S& s, T& v) {
    v += positive_part(c.psi.template value<T, E::rows>(ad::evaluate(c.c, x, u, p)) - s(0));
  }
};

/// The scalar stage Lagrangian as an expression in (x, u, p, lam_dyn = Symbol<3, nx>,
/// mu = Symbol<4, nm>): costs + mu' g (+ mu_i psi_i(c_i)) [- lam_dyn' F].
template <int NX, int NM, class Costs, class Cons, class Dyn>
auto lagrangian(const Costs& costs, const Cons& cons, const Dyn* dyn) {
  constexpr ad::Symbol<4, (NM > 0 ? NM : 1)> mu{};
  auto cost_part = std::apply(
      [](const auto&... c) {
        return (ad::constant(0.0) + ... + OuterExpr<decltype(c.phi), decltype(c.r)>{c.phi, c.r});
      },
      costs.terms);
  auto with_cons = [&]<std::size_t... I>(std::index_sequence<I...>) {
    constexpr auto offsets = [] {
      std::array<int, sizeof...(I) + 1> o{};
      [[maybe_unused]] int acc = 0, i = 0;
      ((o[std::size_t(i++)] = acc, acc += std::tuple_element_t<I, decltype(cons.terms)>::rows),
       ...);
      return o;
    }();
    [[maybe_unused]] auto term = [&]<std::size_t J>(std::integral_constant<std::size_t, J>) {
      const auto& c = std::get<J>(cons.terms);
      using C = std::remove_cvref_t<decltype(c)>;
      return ConstraintKind<C>::template lagrangian_term<offsets[J]>(c, mu);
    };
    return (cost_part + ... + term(std::integral_constant<std::size_t, I>{}));
  }
  (std::make_index_sequence<std::tuple_size_v<decltype(cons.terms)>>{});
  if constexpr (std::is_same_v<Dyn, void>)
    return with_cons;
  else
    return with_cons - ad::dot(ad::Symbol<3, NX>{}, *dyn);
}

/// The constraint rows of a stage as its terms write them (qp/problem.hpp's blocks): C over the
/// state and, on a path stage, D over the stage input [u; s] (the Jacobians' nu input columns,
/// then one column per slack), the slacks' costs into r and R. The terminal stage is the stage
/// with nu = ns = 0: C, lg and ug only.
template <int nx, int nu, int ns, class Out, class T>
struct StageRows {
  Out& out;    ///< the QP stage
  const T* w;  ///< the stage input [u; s] (read for the slacks only)

  /// The free row (C = 0, D = 0, bounds +-inf) of a stage without constraints.
  void free_row() {
    out.C.setZero();
    if constexpr (nu + ns > 0)
      out.D.setZero();
    out.lg.setConstant(-std::numeric_limits<T>::infinity());
    out.ug.setConstant(std::numeric_limits<T>::infinity());
  }
  /// Rows [row, row + m) of [C, D] = [J, 0] (J: m x (nx + nu); zero slack columns).
  template <int m, class J>
  void jacobian(int row, const J& j) {
    out.C.template middleRows<m>(row) = j.template leftCols<nx>();
    if constexpr (nu + ns > 0) {
      out.D.template middleRows<m>(row).template leftCols<nu>() = j.template rightCols<nu>();
      out.D.template middleRows<m>(row).template rightCols<ns>().setZero();
    }
  }
};

/// Writes the QP rows of constraint term c from QP row `row` (its slacks from slack `slack`), the
/// layout of every kind, and returns its nonlinear rows' multipliers mu from the QP rows' lam_g:
///   hard               row i: lo_i <= J_i d <= hi_i; mu_i = lam_i
///   soft, sides = 2    the m lower rows J_i d + ds_i >= lo_i - s_i, then the m upper rows
///                      J_i d - ds_i <= hi_i + s_i (s_i >= 0 row i's slack, ds_i its step);
///                      mu_i = the sum of its two rows' multipliers
///   soft, sides = 1    the upper rows alone (a kind without lower bound); mu_i = lam_i
/// A soft term's slack costs l1 s + l2 s^2 give r = l1 + 2 l2 s and the diagonal R = 2 l2.
template <class C, int nx, int nu, int ns, class Out, class T, class J, int m, class Lam>
VecN<T, m> place_rows(StageRows<nx, nu, ns, Out, T>& rows, const C& c, int row, int slack,
                      const J& jac, const VecN<T, m>& lo, const VecN<T, m>& hi, const Lam& lam_g) {
  auto& o = rows.out;
  VecN<T, m> mu;
  if constexpr (!C::soft) {
    rows.template jacobian<m>(row, jac);
    for (int i = 0; i < m; ++i) {
      o.lg[row + i] = lo[i];
      o.ug[row + i] = hi[i];
      mu[i] = lam_g[row + i];
    }
  } else {
    static_assert(C::sides == 1 || C::sides == 2, "a soft row has an upper and maybe a lower side");
    const T inf = std::numeric_limits<T>::infinity();
    constexpr int upper = C::sides == 2 ? m : 0;  // the upper rows' offset
    for (int i = 0; i < m; ++i) {
      const int k = nu + slack + i;  // the slack's column in D
      o.r[k] = T(c.l1) + T(2 * c.l2) * rows.w[k];
      o.R(k, k) = T(2 * c.l2);
    }
    if constexpr (C::sides == 2) {
      rows.template jacobian<m>(row, jac);
      for (int i = 0; i < m; ++i) {
        o.lg[row + i] = lo[i] - rows.w[nu + slack + i];
        o.ug[row + i] = inf;
        o.D(row + i, nu + slack + i) = T(1);
      }
    }
    rows.template jacobian<m>(row + upper, jac);
    for (int i = 0; i < m; ++i) {
      o.lg[row + upper + i] = -inf;
      o.ug[row + upper + i] = hi[i] + rows.w[nu + slack + i];
      o.D(row + upper + i, nu + slack + i) = T(-1);
      mu[i] = C::sides == 2 ? lam_g[row + i] + lam_g[row + upper + i] : lam_g[row + i];
    }
  }
  return mu;
}

/// cost += l1 s + l2 s^2 over soft term c's slacks s(0), s(1), ... (place_rows' slack costs).
template <class C, class S, class T>
void add_slack_cost(const C& c, const S& s, T& cost) {
  for (int j = 0; j < C::slacks; ++j)
    cost += T(c.l1) * s(j) + T(c.l2) * s(j) * s(j);
}

/// The costs' and constraints' part of a stage's linearisation at the point of env (x, and u on
/// a path stage, seeded: n variables): grad and, for Gauss-Newton, the lower triangle of hess;
/// the QP rows into `rows`; mu: the nonlinear rows' multipliers (the exact Hessian's).
template <HessianKind H, class Costs, class Cons, class Env, class Rows, class Lam, class T, int n,
          int nm>
void linearize_terms(const Costs& costs, const Cons& cons, const Env& env, Rows& rows,
                     const Lam& lam_g, VecN<T, n>& grad, MatN<T, n>& hess, VecN<T, nm>& mu) {
  add_costs<H>(costs, env, grad, hess);
  if constexpr (ListSizes<Cons>::qp_rows == 0)
    rows.free_row();
  int row = 0, slack = 0, nl = 0;
  for_each_term(cons.terms, [&](const auto& c) {
    using C = std::remove_cvref_t<decltype(c)>;
    ConstraintKind<C>::template linearize<H>(
        c, env, hess, [&]<int m>(const auto& J, const VecN<T, m>& lo, const VecN<T, m>& hi) {
          const VecN<T, m> mc = place_rows(rows, c, row, slack, J, lo, hi, lam_g);
          mu.template segment<m>(nl) = mc;
          return mc;
        });
    row += C::qp_rows;
    slack += C::slacks;
    nl += C::rows;
  });
}

/// m.cost and m.violation += the terms' cost and constraint violation at (x, u, p) with the
/// stage's slacks s (none at the terminal stage).
template <class Costs, class Cons, class X, class U, class Pv, class T>
void add_term_merit(const Costs& costs, const Cons& cons, const X& x, const U& u, const Pv& p,
                    const T* s, StageMerit<T>& m) {
  for_each_term(costs.terms, [&](const auto& c) {
    constexpr int r = std::remove_cvref_t<decltype(c)>::rows;
    m.cost += c.phi.template value<T, r>(ad::evaluate(c.r, x, u, p));
  });
  int slack = 0;
  for_each_term(cons.terms, [&](const auto& c) {
    using C = std::remove_cvref_t<decltype(c)>;
    const auto si = [&](int i) { return C::soft ? s[slack + i] : T(0); };  // (hard: none)
    ConstraintKind<C>::add_violation(c, x, u, p, si, m.violation);
    add_slack_cost(c, si, m.cost);
    slack += C::slacks;
  });
}

}  // namespace detail

/// Linearises path stage (x, w = [u; s], p; successor x_next) into the QP stage `st` (every
/// member but the variable bounds lbx, ubx, lbu, ubu). lam_dyn and lam_g are the multipliers of
/// the stage's dynamics and QP rows (used by the Gauss-Newton term of convex constraints and by
/// the exact Hessian).
template <HessianKind H, class P, class T, class Stage>
void linearize_path(const P& prob, const VecN<T, P::nx>& x, const VecN<T, P::nu + P::ns>& w,
                    const VecN<T, P::np>& p, const VecN<T, P::nx>& x_next,
                    const VecN<T, P::nx>& lam_dyn, const VecN<T, qp_rows(P::ng)>& lam_g,
                    Stage& st) {
  constexpr int nx = P::nx, nu = P::nu, ns = P::ns, n = nx + nu;
  const VecN<T, nu> u = w.template head<nu>();
  MatN<T, n> hess = MatN<T, n>::Zero();
  VecN<T, n> grad = VecN<T, n>::Zero();
  st.S.setZero();
  st.R.setZero();
  st.r.setZero();

  // one environment (x and u seeded at Dual<T, n>) for the dynamics and every term
  const auto env = ad::detail::jacobian_env<0, 1>(x, u, p);
  {  // dynamics, straight into A and B
    const auto r = prob.dynamics.eval(env);
    for (int i = 0; i < nx; ++i) {
      st.b[i] = r[i].v - x_next[i];
      for (int k = 0; k < nx; ++k)
        st.A(i, k) = r[i].d[k];
      for (int k = 0; k < nu; ++k)
        st.B(i, k) = r[i].d[nx + k];
      for (int k = nu; k < nu + ns; ++k)
        st.B(i, k) = T(0);
    }
  }
  detail::StageRows<nx, nu, ns, Stage, T> rows{st, w.data()};
  [[maybe_unused]] VecN<T, (P::nm > 0 ? P::nm : 1)> mu = decltype(mu)::Zero();
  detail::linearize_terms<H>(prob.path_costs, prob.path_constraints, env, rows, lam_g, grad, hess,
                             mu);
  if constexpr (H == HessianKind::exact) {
    const auto L =
        detail::lagrangian<nx, P::nm>(prob.path_costs, prob.path_constraints, &prob.dynamics);
    hess = ad::hessian<0, 1>(L, x, u, p, lam_dyn, mu);
  } else {
    detail::symmetrize_lower(hess);  // (the Gauss-Newton terms filled the lower triangle)
  }
  st.Q = hess.template topLeftCorner<nx, nx>();
  st.S.template topRows<nu>() = hess.template bottomLeftCorner<nu, nx>();
  st.R.template topLeftCorner<nu, nu>() = hess.template bottomRightCorner<nu, nu>();
  st.q = grad.template head<nx>();
  st.r.template head<nu>() = grad.template tail<nu>();
}

/// Linearises the terminal stage (x, p) into `t` (every member but lbx, ubx); lam_g: the
/// multipliers of its QP rows. The same terms' routine as a path stage's, without input.
template <HessianKind H, class P, class T, class Terminal>
void linearize_terminal(const P& prob, const VecN<T, P::nx>& x, const VecN<T, P::np>& p,
                        const VecN<T, qp_rows(P::ngn)>& lam_g, Terminal& t) {
  constexpr int nx = P::nx;
  const VecN<T, P::nu> u0 = VecN<T, P::nu>::Zero();  // terminal terms do not depend on u
  t.Q.setZero();
  t.q.setZero();
  const auto env = ad::detail::jacobian_env<0>(x, u0, p);  // x seeded at Dual<T, nx>
  detail::StageRows<nx, 0, 0, Terminal, T> rows{t, nullptr};
  [[maybe_unused]] VecN<T, (P::nmn > 0 ? P::nmn : 1)> mu = decltype(mu)::Zero();
  detail::linearize_terms<H>(prob.terminal_costs, prob.terminal_constraints, env, rows, lam_g, t.q,
                             t.Q, mu);
  if constexpr (H == HessianKind::exact) {
    const auto L = detail::lagrangian<nx, P::nmn>(prob.terminal_costs, prob.terminal_constraints,
                                                  static_cast<const void*>(nullptr));
    t.Q = ad::hessian<0>(L, x, u0, p, VecN<T, nx>::Zero().eval(), mu);
  } else {
    detail::symmetrize_lower(t.Q);  // (the Gauss-Newton terms filled the lower triangle)
  }
}

/// Cost and constraint violation of path stage (x, w = [u; s], p) with successor x_next.
template <class P, class T>
StageMerit<T> path_merit(const P& prob, const VecN<T, P::nx>& x, const VecN<T, P::nu + P::ns>& w,
                         const VecN<T, P::np>& p, const VecN<T, P::nx>& x_next) {
  constexpr int nu = P::nu;
  const VecN<T, nu> u = w.template head<nu>();
  StageMerit<T> m;
  m.violation = (ad::evaluate(prob.dynamics, x, u, p) - x_next).cwiseAbs().sum();
  detail::add_term_merit(prob.path_costs, prob.path_constraints, x, u, p, w.data() + nu, m);
  return m;
}

/// Cost and constraint violation of the terminal stage.
template <class P, class T>
StageMerit<T> terminal_merit(const P& prob, const VecN<T, P::nx>& x, const VecN<T, P::np>& p) {
  const VecN<T, P::nu> u0 = VecN<T, P::nu>::Zero();
  StageMerit<T> m;
  detail::add_term_merit(prob.terminal_costs, prob.terminal_constraints, x, u0, p,
                         static_cast<const T*>(nullptr), m);
  return m;
}

}  // namespace arbor::ocp
