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

template <class C>
inline constexpr bool is_convex_constraint_v = false;
template <class E, class Psi, bool Soft>
inline constexpr bool is_convex_constraint_v<ConvexConstraint<E, Psi, Soft>> = true;

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
      constexpr int off = offsets[J];
      if constexpr (is_convex_constraint_v<C>)
        return ad::element<off>(mu) * OuterExpr<decltype(c.psi), decltype(c.c)>{c.psi, c.c};
      else
        return ad::dot(ad::segment<off, C::rows>(mu), c.g);
    };
    return (cost_part + ... + term(std::integral_constant<std::size_t, I>{}));
  }
  (std::make_index_sequence<std::tuple_size_v<decltype(cons.terms)>>{});
  if constexpr (std::is_same_v<Dyn, void>)
    return with_cons;
  else
    return with_cons - ad::dot(ad::Symbol<3, NX>{}, *dyn);
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
  const T inf = std::numeric_limits<T>::infinity();
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

  using Env = std::remove_cvref_t<decltype(env)>;
  detail::for_each_term(prob.path_costs.terms, [&](const auto& c) {
    constexpr int m = std::remove_cvref_t<decltype(c)>::rows;
    constexpr auto pat = detail::jacobian_pattern<Env, decltype(c.r)>;
    const auto [rv, J] = ad::detail::value_and_jacobian_in(env, c.r);
    detail::add_transposed_product<pat>(grad, J, c.phi.template gradient<T, m>(rv));
    if constexpr (H == HessianKind::gauss_newton)
      detail::add_gauss_newton_lower<pat>(hess, c.phi, VecN<T, m>(rv), J, T(1));
  });

  if constexpr (P::ng == 0) {  // the free row
    st.C.setZero();
    st.D.setZero();
    st.lg.setConstant(-inf);
    st.ug.setConstant(inf);
  }
  int row = 0, slack = 0, nl = 0;
  [[maybe_unused]] VecN<T, (P::nm > 0 ? P::nm : 1)> mu = decltype(mu)::Zero();
  detail::for_each_term(prob.path_constraints.terms, [&](const auto& c) {
    using C = std::remove_cvref_t<decltype(c)>;
    for (int j = 0; j < C::slacks; ++j) {  // slack costs l1 s + l2 s^2
      const int i = nu + slack + j;
      st.r[i] = T(c.l1) + T(2 * c.l2) * w[i];
      st.R(i, i) = T(2 * c.l2);
    }
    if constexpr (detail::is_convex_constraint_v<C>) {
      constexpr int m = decltype(c.c)::rows;
      const auto [cv, J] = ad::detail::value_and_jacobian_in(env, c.c);
      const Eigen::Matrix<T, 1, n> jrow = c.psi.template gradient<T, m>(cv).transpose() * J;
      st.C.row(row) = jrow.template head<nx>();
      st.D.row(row).template head<nu>() = jrow.template tail<nu>();
      st.D.row(row).template tail<ns>().setZero();
      st.lg[row] = -inf;
      st.ug[row] = -c.psi.template value<T, m>(cv);
      const T mui = lam_g[row];
      mu[nl] = mui;
      if constexpr (H == HessianKind::gauss_newton) {
        const T scale = positive_part(mui);  // (skipped at a zero or negative multiplier)
        if (!known_zero(scale))
          detail::add_gauss_newton_lower<detail::jacobian_pattern<Env, decltype(c.c)>>(
              hess, c.psi, VecN<T, m>(cv), J, scale);
      }
      if constexpr (C::soft) {
        st.D(row, nu + slack) = T(-1);
        st.ug[row] += w[nu + slack];  // psi + grad psi' J d - (s + ds) <= 0
        ++slack;
      }
      ++row;
      ++nl;
    } else {
      constexpr int m = C::rows;
      const auto [gv, J] = ad::detail::value_and_jacobian_in(env, c.g);
      const int copies = C::soft ? 2 : 1;
      for (int side = 0; side < copies; ++side) {
        st.C.template middleRows<m>(row + side * m) = J.template leftCols<nx>();
        st.D.template middleRows<m>(row + side * m).template leftCols<nu>() =
            J.template rightCols<nu>();
        st.D.template middleRows<m>(row + side * m).template rightCols<ns>().setZero();
      }
      for (int i = 0; i < m; ++i) {
        const T lo = T(c.lg[std::size_t(i)]) - gv[i], hi = T(c.ug[std::size_t(i)]) - gv[i];
        if constexpr (C::soft) {
          const T si = w[nu + slack + i];  // the current slack
          st.lg[row + i] = lo - si;        // lower row: J d + ds >= lg - g - s
          st.ug[row + i] = inf;
          st.D(row + i, nu + slack + i) = T(1);
          st.lg[row + m + i] = -inf;  // upper row: J d - ds <= ug - g + s
          st.ug[row + m + i] = hi + si;
          st.D(row + m + i, nu + slack + i) = T(-1);
          mu[nl + i] = lam_g[row + i] + lam_g[row + m + i];
        } else {
          st.lg[row + i] = lo;
          st.ug[row + i] = hi;
          mu[nl + i] = lam_g[row + i];
        }
      }
      row += C::qp_rows;
      slack += C::slacks;
      nl += m;
    }
  });

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
/// multipliers of its QP rows.
template <HessianKind H, class P, class T, class Terminal>
void linearize_terminal(const P& prob, const VecN<T, P::nx>& x, const VecN<T, P::np>& p,
                        const VecN<T, qp_rows(P::ngn)>& lam_g, Terminal& t) {
  constexpr int nx = P::nx;
  const T inf = std::numeric_limits<T>::infinity();
  const VecN<T, P::nu> u0 = VecN<T, P::nu>::Zero();  // terminal terms do not depend on u
  t.Q.setZero();
  t.q.setZero();
  const auto env = ad::detail::jacobian_env<0>(x, u0, p);  // x seeded at Dual<T, nx>
  using Env = std::remove_cvref_t<decltype(env)>;
  detail::for_each_term(prob.terminal_costs.terms, [&](const auto& c) {
    constexpr int m = std::remove_cvref_t<decltype(c)>::rows;
    constexpr auto pat = detail::jacobian_pattern<Env, decltype(c.r)>;
    const auto [rv, J] = ad::detail::value_and_jacobian_in(env, c.r);
    detail::add_transposed_product<pat>(t.q, J, c.phi.template gradient<T, m>(rv));
    if constexpr (H == HessianKind::gauss_newton)
      detail::add_gauss_newton_lower<pat>(t.Q, c.phi, VecN<T, m>(rv), J, T(1));
  });
  if constexpr (P::ngn == 0) {  // the free row
    t.C.setZero();
    t.lg.setConstant(-inf);
    t.ug.setConstant(inf);
  }
  int row = 0;
  [[maybe_unused]] VecN<T, (P::nmn > 0 ? P::nmn : 1)> mu = decltype(mu)::Zero();
  detail::for_each_term(prob.terminal_constraints.terms, [&](const auto& c) {
    using C = std::remove_cvref_t<decltype(c)>;
    if constexpr (detail::is_convex_constraint_v<C>) {
      constexpr int m = decltype(c.c)::rows;
      const auto [cv, J] = ad::detail::value_and_jacobian_in(env, c.c);
      t.C.row(row) = c.psi.template gradient<T, m>(cv).transpose() * J;
      t.lg[row] = -inf;
      t.ug[row] = -c.psi.template value<T, m>(cv);
      mu[row] = lam_g[row];
      if constexpr (H == HessianKind::gauss_newton) {
        const T scale = positive_part(lam_g[row]);
        if (!known_zero(scale))
          detail::add_gauss_newton_lower<detail::jacobian_pattern<Env, decltype(c.c)>>(
              t.Q, c.psi, VecN<T, m>(cv), J, scale);
      }
      ++row;
    } else {
      constexpr int m = C::rows;
      const auto [gv, J] = ad::detail::value_and_jacobian_in(env, c.g);
      t.C.template middleRows<m>(row) = J;
      for (int i = 0; i < m; ++i) {
        t.lg[row + i] = T(c.lg[std::size_t(i)]) - gv[i];
        t.ug[row + i] = T(c.ug[std::size_t(i)]) - gv[i];
        mu[row + i] = lam_g[row + i];
      }
      row += m;
    }
  });
  if constexpr (H == HessianKind::exact) {
    const auto L = detail::lagrangian<nx, P::nmn>(prob.terminal_costs, prob.terminal_constraints,
                                                  static_cast<const void*>(nullptr));
    t.Q = ad::hessian<0>(L, x, u0, p, VecN<T, nx>::Zero().eval(), mu);
  } else {
    detail::symmetrize_lower(t.Q);  // (the Gauss-Newton terms filled the lower triangle)
  }
}

/// Cost and L1 infeasibility of a path stage (merit function pieces; bounds excluded).
template <class T>
struct StageMerit {
  T cost = T(0);       ///< stage cost, slack costs included
  T violation = T(0);  ///< sum of |F - x_next| and of the constraints' violations
};

/// Cost and constraint violation of path stage (x, w = [u; s], p) with successor x_next.
template <class P, class T>
StageMerit<T> path_merit(const P& prob, const VecN<T, P::nx>& x, const VecN<T, P::nu + P::ns>& w,
                         const VecN<T, P::np>& p, const VecN<T, P::nx>& x_next) {
  constexpr int nu = P::nu;
  const VecN<T, nu> u = w.template head<nu>();
  StageMerit<T> m;
  m.violation = (ad::evaluate(prob.dynamics, x, u, p) - x_next).cwiseAbs().sum();
  detail::for_each_term(prob.path_costs.terms, [&](const auto& c) {
    constexpr int r = std::remove_cvref_t<decltype(c)>::rows;
    m.cost += c.phi.template value<T, r>(ad::evaluate(c.r, x, u, p));
  });
  int slack = nu;
  detail::for_each_term(prob.path_constraints.terms, [&](const auto& c) {
    using C = std::remove_cvref_t<decltype(c)>;
    if constexpr (detail::is_convex_constraint_v<C>) {
      constexpr int r = decltype(c.c)::rows;
      T v = c.psi.template value<T, r>(ad::evaluate(c.c, x, u, p));
      if constexpr (C::soft)
        v -= w[slack];
      m.violation += v > T(0) ? v : T(0);
    } else {
      const auto g = ad::evaluate(c.g, x, u, p);
      for (int i = 0; i < C::rows; ++i) {
        const T s = C::soft ? w[slack + i] : T(0);
        const T lo = T(c.lg[std::size_t(i)]) - s - g[i], hi = g[i] - s - T(c.ug[std::size_t(i)]);
        m.violation += (lo > T(0) ? lo : T(0)) + (hi > T(0) ? hi : T(0));
      }
    }
    for (int j = 0; j < C::slacks; ++j)
      m.cost += T(c.l1) * w[slack + j] + T(c.l2) * w[slack + j] * w[slack + j];
    slack += C::slacks;
  });
  return m;
}

/// Cost and constraint violation of the terminal stage.
template <class P, class T>
StageMerit<T> terminal_merit(const P& prob, const VecN<T, P::nx>& x, const VecN<T, P::np>& p) {
  const VecN<T, P::nu> u0 = VecN<T, P::nu>::Zero();
  StageMerit<T> m;
  detail::for_each_term(prob.terminal_costs.terms, [&](const auto& c) {
    constexpr int r = std::remove_cvref_t<decltype(c)>::rows;
    m.cost += c.phi.template value<T, r>(ad::evaluate(c.r, x, u0, p));
  });
  detail::for_each_term(prob.terminal_constraints.terms, [&](const auto& c) {
    using C = std::remove_cvref_t<decltype(c)>;
    if constexpr (detail::is_convex_constraint_v<C>) {
      constexpr int r = decltype(c.c)::rows;
      const T v = c.psi.template value<T, r>(ad::evaluate(c.c, x, u0, p));
      m.violation += v > T(0) ? v : T(0);
    } else {
      const auto g = ad::evaluate(c.g, x, u0, p);
      for (int i = 0; i < C::rows; ++i) {
        const T lo = T(c.lg[std::size_t(i)]) - g[i], hi = g[i] - T(c.ug[std::size_t(i)]);
        m.violation += (lo > T(0) ? lo : T(0)) + (hi > T(0) ? hi : T(0));
      }
    }
  });
  return m;
}

}  // namespace arbor::ocp
