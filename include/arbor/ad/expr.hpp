// arbor: expression templates for OCP functions, with custom-derivative RBD nodes.
//
// An expression is a small value type built from symbols and operators:
//
//   constexpr ad::Symbol<0, 7> q;          // argument 0: a 7-vector
//   constexpr ad::Symbol<1, 1> s;          // argument 1: a scalar
//   auto e = ad::call<ad::Analytical>(ad::FramePosition<Arm, 8>{}, q) - p_ref(s);
//   auto cost = ad::squared_norm(e);
//   auto g = ad::gradient(cost, q_value, s_value);   // d cost / d (q, s), an 8-vector
//   auto H = ad::hessian(cost, q_value, s_value);    // 8 x 8
//
// Argument i of evaluate/jacobian/gradient/hessian is the value of Symbol<i, N> (an Eigen
// fixed-size column vector of N rows, or a plain scalar when N == 1). Derivatives are taken with
// respect to all arguments stacked in Id order, or with respect to the listed Ids only
// (`ad::jacobian<0>(e, x, u)` is d e / d x; the other arguments are parameters).
//
// Nodes and evaluation. Every node holds its children by value (symbols are empty types), knows
// its size at compile time (`rows`), and `eval(env)` returns its concrete value, Values<S, rows>
// (a plain array of the environment's scalar type S): every node is materialised, no lazy
// expression escapes a node, nothing allocates, and the template depth of an evaluation is the
// depth of the expression tree. Values is a plain array rather than an Eigen vector because
// every (scalar, size) pair of an Eigen vector instantiates Eigen's whole class hierarchy, which
// dominates compile time and memory once expressions are evaluated at nested duals; Eigen types
// appear only at the boundaries (arguments, results, fn bodies, RBD function objects).
//
// Differentiation is forward mode over the same code: jacobian/gradient evaluate at
// S = Dual<T, n> with the differentiated arguments seeded (n = their total size, a compile-time
// constant); hessian evaluates at S = Dual<Dual<T, n>, n> (forward over forward; the result is
// symmetric to rounding). T is the arguments' scalar: double, float, or Counted to count
// operations (constants then fold, see op_count.hpp).
//
// Custom-derivative nodes. `call<Tag>(F{}, args...)` applies an RBD function object F (see
// rbd_functions.hpp: ForwardDynamics<R>, InverseDynamics<R>, FramePosition<R, Frame>) to the
// concatenation of args (F::nin rows). At a plain scalar it calls F::value. At S = Dual<T, K> it
// calls F::value_and_jacobian<Tag, T> once (value and Jacobian from the same pass) and applies the
// chain rule, out.d[k] = J x.d[k]; the rest of the expression is differentiated by this layer
// (CasADi's custom_jacobian). When the input is made of arguments directly (call<Tag>(F{}, q,
// v, tau)) their seeds are unit vectors known at compile time and the chain rule is a copy of
// J's columns (summed for an argument used twice): the node's Jacobian costs exactly the
// provider. Because T may itself be a Dual, the same node gives Hessians: Tag Analytical runs
// the analytical first-order routine in Dual arithmetic (the paper's H^a), AutoDiff runs nested
// duals through the RBD templates (H^c).
//
// Materialisation boundaries (shared subexpressions). A node that appears twice in a tree is
// evaluated twice, and a subexpression used k times inside a stage that is itself used k times
// is evaluated k^depth times (e.g. a naive RK4 step built from expressions). Two boundaries
// evaluate something once per evaluation:
//   let(e, [](auto v) { return ... v ... v ...; })   e is evaluated once; the lambda receives a
//       placeholder bound to that value, and its result is the expression (the lambda runs once,
//       at construction; its closure type is the placeholder's key);
//   fn<Nout>([](const auto& x, const auto& u) { ... }, x_expr, u_expr)   each argument is
//       evaluated once and the generic lambda runs on the concrete vectors (VecN<S, rows>, S any of
//       the scalar types above) and returns an Nout-vector (or a scalar when Nout == 1). It is
//       differentiated because it runs at Dual scalars: write it as generic scalar code (use
//       S(c) for constants mixed into Eigen products, arbor::sin/cos/sqrt for functions).
//
// The `auto` pitfall. `auto k1 = f(x, u);` stores an expression, not a value: every later use of
// k1 re-evaluates it (and its type, with everything inside it, is copied into each user). Use
// let(...) or fn<...>(...) when a subexpression is used more than once. Inside fn bodies the
// arguments are Eigen vectors, and there `auto y = a + b;` is an Eigen expression holding
// references: do not return it when it refers to the lambda's own locals; return a VecN (or
// `.eval()`). Expressions themselves hold their children by value and never dangle.
//
// Constant matrices. mul<K>(x) (or K{} * x) multiplies by a matrix whose entries are compile-time
// constants: K is any type with `static constexpr int rows, cols` and
// `static constexpr double at(int r, int c)` (e.g. reading a static constexpr array, or
// ConstMatrix<2, 3, {...}> where the compiler supports floating-point class-type template
// arguments). Zero entries generate no code; +-1 entries become additions and subtractions.
//
// Resources: no heap, no exceptions, no RTTI. Evaluations use the stack: at
// S = Dual<Dual<double, n>, n> every scalar is 8 (n + 1)^2 bytes, so keep n and the vector
// sizes of Hessian evaluations moderate on small targets. Custom nodes use the static
// workspaces of rbd_functions.hpp (not reentrant).
#pragma once

#include <Eigen/Core>
#include <array>
#include <concepts>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "arbor/ad/dual.hpp"
#include "arbor/core/math.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::ad {

/// The value of an expression node: N scalars of type S (a plain array, indexable by int).
template <class S, int N>
struct Values {
  static constexpr int size = N;  ///< number of elements
  S v[N];                         ///< the elements
  /// Element i.
  constexpr S& operator[](int i) { return v[i]; }
  /// Element i.
  constexpr const S& operator[](int i) const { return v[i]; }
};

/// An expression node: a type with `expression_tag`, `static constexpr int rows` and `eval(env)`.
template <class E>
concept Expression = requires {
  typename std::remove_cvref_t<E>::expression_tag;
  { std::remove_cvref_t<E>::rows } -> std::convertible_to<int>;
};

/// A matrix of compile-time constants: static constexpr rows, cols and at(r, c).
template <class K>
concept CompileTimeMatrix = requires {
  { K::rows } -> std::convertible_to<int>;
  { K::cols } -> std::convertible_to<int>;
  { K::at(0, 0) } -> std::convertible_to<double>;
};

#if defined(__cpp_nontype_template_args) && __cpp_nontype_template_args >= 201911L
/// A compile-time matrix from its entries in row-major order: ConstMatrix<2, 2, {1.0, 0.0, ...}>
/// (needs floating-point class-type template arguments: GCC >= 11, Clang >= 18).
template <int Rows, int Cols, std::array<double, std::size_t(Rows) * std::size_t(Cols)> Entries>
struct ConstMatrix {
  static constexpr int rows = Rows;  ///< number of rows
  static constexpr int cols = Cols;  ///< number of columns
  /// Entry (r, c).
  static constexpr double at(int r, int c) { return Entries[std::size_t(r * Cols + c)]; }
};
#endif

/// The transpose of a compile-time matrix K.
template <CompileTimeMatrix K>
struct TransposedMatrix {
  static constexpr int rows = K::cols;  ///< number of rows
  static constexpr int cols = K::rows;  ///< number of columns
  /// Entry (r, c) = K(c, r).
  static constexpr double at(int r, int c) { return K::at(c, r); }
};

namespace detail {

template <class>
inline constexpr bool always_false = false;

/// The innermost scalar of a (possibly nested) dual.
template <class S>
struct BaseScalar {
  using type = S;
};
template <class T, int N>
struct BaseScalar<Dual<T, N>> {
  using type = typename BaseScalar<T>::type;
};
template <class S>
using base_t = typename BaseScalar<S>::type;

/// S from a value of its innermost scalar type (all derivatives zero).
template <class S, class B>
S lift_constant(const B& c) {
  if constexpr (is_dual_v<S>)
    return S(lift_constant<typename S::Value>(c));
  else
    return S(c);
}

/// S (T nested in duals) from an argument value of type T: a constant (zero derivatives).
template <class S, class T>
S lift_argument(const T& x) {
  if constexpr (std::is_same_v<S, T>)
    return x;
  else
    return S(lift_argument<typename S::Value, T>(x));
}

/// S (T nested in duals) from an argument value of type T, seeded along direction k at every
/// dual level above T.
template <class S, class T>
S seed_argument(const T& x, int k) {
  if constexpr (std::is_same_v<S, T>)
    return x;
  else
    return S::variable(seed_argument<typename S::Value, T>(x, k), k);
}

/// x * c for a constant c of the innermost scalar type (every component scaled once).
template <class S, class B>
S scale(const S& x, const B& c) {
  if constexpr (is_dual_v<S>) {
    S r;
    r.v = scale(x.v, c);
    for (int k = 0; k < S::directions; ++k)
      r.d[k] = scale(x.d[k], c);
    return r;
  } else {
    return S(x * c);
  }
}

/// x / c for a constant c of the innermost scalar type.
template <class S, class B>
S divide(const S& x, const B& c) {
  if constexpr (is_dual_v<S>) {
    S r;
    r.v = divide(x.v, c);
    for (int k = 0; k < S::directions; ++k)
      r.d[k] = divide(x.d[k], c);
    return r;
  } else {
    return S(x / c);
  }
}

/// x + c for a constant c (only the innermost value changes).
template <class S, class B>
S shift(const S& x, const B& c) {
  if constexpr (is_dual_v<S>) {
    S r = x;
    r.v = shift(x.v, c);
    return r;
  } else {
    return S(x + c);
  }
}

/// c - x for a constant c.
template <class S, class B>
S rsub(const B& c, const S& x) {
  if constexpr (is_dual_v<S>) {
    S r;
    r.v = rsub(c, x.v);
    for (int k = 0; k < S::directions; ++k)
      r.d[k] = -x.d[k];
    return r;
  } else {
    return S(c - x);
  }
}

/// c / x for a constant c.
template <class S, class B>
S rdiv(const B& c, const S& x) {
  if constexpr (is_dual_v<S>)
    return lift_constant<typename S::Value>(c) / x;
  else
    return S(c / x);
}

// Elementwise operations: apply (both operands variable), const_left (c op x), const_right
// (x op c) with c a constant of the innermost scalar type.
struct AddOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a + b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return shift(x, c);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return shift(x, c);
  }
};
struct SubOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a - b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return rsub(c, x);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return shift(x, B(-c));
  }
};
struct MulOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a * b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return scale(x, c);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return scale(x, c);
  }
};
struct DivOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a / b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return rdiv(c, x);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return divide(x, c);
  }
};
struct NegOp {
  template <class S>
  static S apply(const S& x) {
    return -x;
  }
};
struct SinOp {
  template <class S>
  static S apply(const S& x) {
    return arbor::sin(x);
  }
};
struct CosOp {
  template <class S>
  static S apply(const S& x) {
    return arbor::cos(x);
  }
};
struct SqrtOp {
  template <class S>
  static S apply(const S& x) {
    return arbor::sqrt(x);
  }
};

/// acc (+)= K(I, J) x, skipping a zero entry and turning +-1 into an addition or subtraction;
/// `any` tells whether acc already holds a term (the sum starts from its first term, not from 0).
template <CompileTimeMatrix K, int I, int J, class S>
void accumulate_constant_term(S& acc, bool& any, const S& x) {
  using B = base_t<S>;
  constexpr double C = K::at(I, J);
  if constexpr (C == 0.0) {
    return;
  } else if constexpr (C == 1.0) {
    acc = any ? S(acc + x) : x;
  } else if constexpr (C == -1.0) {
    acc = any ? S(acc - x) : S(-x);
  } else {
    const S t = scale(x, B(C));
    acc = any ? S(acc + t) : t;
  }
  any = true;
}

/// Row I of K times x.
template <CompileTimeMatrix K, int I, class S, class X, int... J>
S constant_row(const X& x, std::integer_sequence<int, J...>) {
  S acc{};
  bool any = false;
  (accumulate_constant_term<K, I, J>(acc, any, S(x[J])), ...);
  if (!any)
    acc = lift_constant<S>(base_t<S>(0));
  return acc;
}

/// True for ConstantExpr nodes (their values are known numbers, used without lifting).
template <class E>
inline constexpr bool is_constant_expr_v = requires {
  E::is_constant_expression;
};

/// Environment of an evaluation: the argument values at scalar S (already seeded). When Seeded,
/// the outermost dual level of S belongs to this evaluation and argument Id occupies directions
/// Offsets[Id] .. Offsets[Id] + N - 1 (Offsets[Id] < 0: a parameter, zero derivatives).
template <class S, bool Seeded, auto Offsets, class... V>
struct RootEnv {
  using Scalar = S;                       ///< scalar type of the evaluation
  static constexpr bool seeded = Seeded;  ///< the outer dual level is this evaluation's
  std::tuple<V...> args;                  ///< argument values, Values<S, N_i>
  /// First derivative direction of argument Id (< 0: not differentiated).
  template <int Id>
  static constexpr int offset() {
    return Offsets[std::size_t(Id)];
  }
  /// Value of argument Id.
  template <int Id>
  const auto& arg() const {
    static_assert(Id >= 0 && Id < int(sizeof...(V)),
                  "a Symbol<Id, N> has no argument: pass one value per Id 0, 1, ...");
    return std::get<Id>(args);
  }
  /// A let placeholder outside its let: a compile-time error.
  template <class Key>
  void bound() const {
    static_assert(always_false<Key>, "a let placeholder was used outside the body of its let");
  }
};

/// Environment of a let body: the parent's arguments plus the value bound to Key.
template <class Key, class Parent, class V>
struct LetEnv {
  using Scalar = typename Parent::Scalar;         ///< scalar type of the evaluation
  static constexpr bool seeded = Parent::seeded;  ///< as the parent's
  const Parent& parent;                           ///< enclosing environment
  V value;                                        ///< the bound value
  /// First derivative direction of argument Id (< 0: not differentiated).
  template <int Id>
  static constexpr int offset() {
    return Parent::template offset<Id>();
  }
  /// Value of argument Id.
  template <int Id>
  const auto& arg() const {
    return parent.template arg<Id>();
  }
  /// Value bound to K (the innermost let with that key).
  template <class K>
  const auto& bound() const {
    if constexpr (std::is_same_v<K, Key>)
      return value;
    else
      return parent.template bound<K>();
  }
};

/// Size and scalar of an argument: an Eigen column vector, or a plain scalar (size 1).
template <class A, bool IsEigen = std::is_base_of_v<Eigen::EigenBase<A>, A>>
struct ArgTraits {
  static constexpr int rows = 1;
  using Scalar = A;
};
template <class A>
struct ArgTraits<A, true> {
  static_assert(A::ColsAtCompileTime == 1 && A::RowsAtCompileTime != Eigen::Dynamic,
                "arguments must be fixed-size column vectors");
  static constexpr int rows = A::RowsAtCompileTime;
  using Scalar = typename A::Scalar;
};

template <class... A>
struct ArgPack {
  using Scalar = std::common_type_t<typename ArgTraits<A>::Scalar...>;
  static constexpr std::array<int, sizeof...(A)> sizes{ArgTraits<A>::rows...};
};
template <>
struct ArgPack<> {
  using Scalar = double;
  static constexpr std::array<int, 0> sizes{};
};

/// True when Wrt lists valid, distinct argument Ids.
template <std::size_t K, int... Wrt>
consteval bool wrt_valid() {
  const int ids[] = {Wrt..., 0};
  for (std::size_t a = 0; a < sizeof...(Wrt); ++a) {
    if (ids[a] < 0 || ids[a] >= int(K))
      return false;
    for (std::size_t b = 0; b < a; ++b)
      if (ids[a] == ids[b])
        return false;
  }
  return true;
}

/// Offset of each argument in the stacked derivative directions, -1 when not differentiated.
/// All arguments in Id order when Wrt is empty, otherwise the listed Ids in the listed order.
template <std::size_t K, int... Wrt>
consteval std::array<int, K> wrt_offsets(const std::array<int, K>& sizes) {
  std::array<int, K> off{};
  for (auto& o : off)
    o = -1;
  int pos = 0;
  if constexpr (sizeof...(Wrt) == 0) {
    for (std::size_t i = 0; i < K; ++i) {
      off[i] = pos;
      pos += sizes[i];
    }
  } else {
    for (int id : {Wrt...}) {
      off[std::size_t(id)] = pos;
      pos += sizes[std::size_t(id)];
    }
  }
  return off;
}

/// Number of derivative directions.
template <std::size_t K>
consteval int wrt_size(const std::array<int, K>& sizes, const std::array<int, K>& off) {
  int n = 0;
  for (std::size_t i = 0; i < K; ++i)
    if (off[i] >= 0)
      n += sizes[i];
  return n;
}

/// One argument at scalar S: constants (Offset < 0) or seeded variables.
template <class S, class T, int Offset, class A>
Values<S, ArgTraits<A>::rows> make_arg(const A& a) {
  constexpr int n = ArgTraits<A>::rows;
  Values<S, n> r;
  if constexpr (std::is_base_of_v<Eigen::EigenBase<A>, A>) {
    const VecN<typename A::Scalar, n> av = a;
    for (int j = 0; j < n; ++j) {
      if constexpr (Offset < 0)
        r[j] = lift_argument<S, T>(T(av[j]));
      else
        r[j] = seed_argument<S, T>(T(av[j]), Offset + j);
    }
  } else {
    if constexpr (Offset < 0)
      r[0] = lift_argument<S, T>(T(a));
    else
      r[0] = seed_argument<S, T>(T(a), Offset);
  }
  return r;
}

template <class S, class T, bool Seeded, auto Offsets, std::size_t... I, class... A>
RootEnv<S, Seeded, Offsets, Values<S, ArgTraits<A>::rows>...> make_env(std::index_sequence<I...>,
                                                                       const A&... a) {
  return {std::tuple<Values<S, ArgTraits<A>::rows>...>(make_arg<S, T, Offsets[I]>(a)...)};
}

/// The result of an fn body (an Eigen Nout-vector, or a scalar if Nout == 1) as Values.
template <class S, int Nout, class R>
Values<S, Nout> to_values(const R& r) {
  Values<S, Nout> v;
  if constexpr (std::is_base_of_v<Eigen::EigenBase<R>, R>) {
    static_assert(R::RowsAtCompileTime == Nout && R::ColsAtCompileTime == 1,
                  "an fn body must return a vector of Nout rows");
    const VecN<S, Nout> e = r;
    for (int i = 0; i < Nout; ++i)
      v[i] = e[i];
  } else {
    static_assert(Nout == 1, "an fn body returning a scalar needs Nout == 1");
    v[0] = S(r);
  }
  return v;
}

/// Values as an Eigen vector.
template <class S, int N>
VecN<S, N> to_eigen(const Values<S, N>& x) {
  VecN<S, N> r;
  for (int i = 0; i < N; ++i)
    r[i] = x[i];
  return r;
}

}  // namespace detail

// ---- nodes ---------------------------------------------------------------------------------

/// Argument Id of an evaluation, an N-vector (an empty type: declare `constexpr Symbol<0, 3> x;`).
template <int Id, int N>
struct Symbol {
  static_assert(Id >= 0 && N >= 1, "Symbol<Id, N> needs Id >= 0 and N >= 1");
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = N;  ///< size
  static constexpr int id = Id;   ///< argument index
  /// The argument's value.
  template <class Env>
  const auto& eval(const Env& env) const {
    const auto& v = env.template arg<Id>();
    static_assert(std::remove_cvref_t<decltype(v)>::size == N,
                  "the argument's size differs from its Symbol's N");
    return v;
  }
};

/// A vector of run-time constants (parameters fixed at construction).
template <int N>
struct ConstantExpr {
  using expression_tag = void;                          ///< marks an expression node
  static constexpr int rows = N;                        ///< size
  static constexpr bool is_constant_expression = true;  ///< used without lifting in binary nodes
  std::array<double, std::size_t(N)> value;             ///< the constants
  /// The constants at scalar S (zero derivatives).
  template <class Env>
  Values<typename Env::Scalar, N> eval(const Env&) const {
    using S = typename Env::Scalar;
    Values<S, N> r;
    for (int i = 0; i < N; ++i)
      r[i] = detail::lift_constant<S>(detail::base_t<S>(value[std::size_t(i)]));
    return r;
  }
};

/// An elementwise function of one expression.
template <class Op, Expression A>
struct UnaryExpr {
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = A::rows;  ///< size
  A arg;                                ///< operand
  /// Op applied to every element.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    const auto& a = arg.eval(env);
    Values<typename Env::Scalar, rows> r;
    for (int i = 0; i < rows; ++i)
      r[i] = Op::apply(a[i]);
    return r;
  }
};

/// An elementwise binary operation; a 1-row operand is broadcast against an N-row one.
template <class Op, Expression L, Expression R>
struct BinaryExpr {
  static_assert(L::rows == R::rows || L::rows == 1 || R::rows == 1,
                "elementwise operands need equal sizes (or one of size 1)");
  using expression_tag = void;                                        ///< marks an expression node
  static constexpr int rows = L::rows > R::rows ? L::rows : R::rows;  ///< size
  L lhs;                                                              ///< left operand
  R rhs;                                                              ///< right operand
  /// The elementwise result; constant operands enter as numbers (no lifting to S).
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using S = typename Env::Scalar;
    using B = detail::base_t<S>;
    constexpr bool lc = detail::is_constant_expr_v<L>;
    constexpr bool rc = detail::is_constant_expr_v<R>;
    Values<S, rows> r;
    if constexpr (lc && !rc) {
      const auto& b = rhs.eval(env);
      for (int i = 0; i < rows; ++i)
        r[i] = Op::const_left(B(lhs.value[std::size_t(li(i))]), S(b[ri(i)]));
    } else if constexpr (!lc && rc) {
      const auto& a = lhs.eval(env);
      for (int i = 0; i < rows; ++i)
        r[i] = Op::const_right(S(a[li(i)]), B(rhs.value[std::size_t(ri(i))]));
    } else {
      const auto& a = lhs.eval(env);
      const auto& b = rhs.eval(env);
      for (int i = 0; i < rows; ++i)
        r[i] = Op::apply(S(a[li(i)]), S(b[ri(i)]));
    }
    return r;
  }

 private:
  static constexpr int li(int i) { return L::rows == 1 ? 0 : i; }
  static constexpr int ri(int i) { return R::rows == 1 ? 0 : i; }
};

/// Inner product of two expressions of equal size (1 row).
template <Expression L, Expression R>
struct DotExpr {
  static_assert(L::rows == R::rows, "dot needs operands of equal size");
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = 1;  ///< size
  L lhs;                          ///< left operand
  R rhs;                          ///< right operand
  /// sum_i lhs_i rhs_i, starting from the first term.
  template <class Env>
  Values<typename Env::Scalar, 1> eval(const Env& env) const {
    using S = typename Env::Scalar;
    using B = detail::base_t<S>;
    Values<S, 1> r;
    constexpr bool lc = detail::is_constant_expr_v<L>;
    constexpr bool rc = detail::is_constant_expr_v<R>;
    if constexpr (lc && rc) {
      double s = 0;
      for (int i = 0; i < L::rows; ++i)
        s += lhs.value[std::size_t(i)] * rhs.value[std::size_t(i)];
      r[0] = detail::lift_constant<S>(B(s));
    } else if constexpr (lc) {
      r[0] = weighted_sum<S>(lhs.value, rhs.eval(env));
    } else if constexpr (rc) {
      r[0] = weighted_sum<S>(rhs.value, lhs.eval(env));
    } else {
      const auto& a = lhs.eval(env);
      const auto& b = rhs.eval(env);
      S acc = a[0] * b[0];
      for (int i = 1; i < L::rows; ++i)
        acc += a[i] * b[i];
      r[0] = acc;
    }
    return r;
  }

 private:
  template <class S, class W, class X>
  static S weighted_sum(const W& w, const X& x) {
    using B = detail::base_t<S>;
    S acc = detail::scale(S(x[0]), B(w[0]));
    for (int i = 1; i < L::rows; ++i)
      acc += detail::scale(S(x[i]), B(w[std::size_t(i)]));
    return acc;
  }
};

/// Squared Euclidean norm of an expression (1 row).
template <Expression A>
struct SquaredNormExpr {
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = 1;  ///< size
  A arg;                          ///< operand
  /// sum_i a_i^2.
  template <class Env>
  Values<typename Env::Scalar, 1> eval(const Env& env) const {
    using S = typename Env::Scalar;
    const auto& a = arg.eval(env);
    S acc = a[0] * a[0];
    for (int i = 1; i < A::rows; ++i)
      acc += a[i] * a[i];
    Values<S, 1> r;
    r[0] = acc;
    return r;
  }
};

/// Sum of the elements of an expression (1 row).
template <Expression A>
struct SumExpr {
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = 1;  ///< size
  A arg;                          ///< operand
  /// sum_i a_i.
  template <class Env>
  Values<typename Env::Scalar, 1> eval(const Env& env) const {
    using S = typename Env::Scalar;
    const auto& a = arg.eval(env);
    S acc = a[0];
    for (int i = 1; i < A::rows; ++i)
      acc += a[i];
    Values<S, 1> r;
    r[0] = acc;
    return r;
  }
};

/// Product of a compile-time matrix K and an expression.
template <CompileTimeMatrix K, Expression A>
struct MatVecExpr {
  static_assert(K::cols == A::rows, "mul<K>(x): K::cols must equal the size of x");
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = K::rows;  ///< size
  A arg;                                ///< operand
  /// K x with zero entries skipped and +-1 entries as additions/subtractions.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using S = typename Env::Scalar;
    const auto& x = arg.eval(env);
    Values<S, rows> r;
    static_for<rows>([&](auto i) {
      r[i] = detail::constant_row<K, decltype(i)::value, S>(
          x, std::make_integer_sequence<int, K::cols>{});
    });
    return r;
  }
};

/// Elements Start .. Start + Len - 1 of an expression.
template <int Start, int Len, Expression A>
struct SegmentExpr {
  static_assert(Start >= 0 && Len >= 1 && Start + Len <= A::rows, "segment out of range");
  using expression_tag = void;      ///< marks an expression node
  static constexpr int rows = Len;  ///< size
  A arg;                            ///< operand
  /// The segment.
  template <class Env>
  Values<typename Env::Scalar, Len> eval(const Env& env) const {
    const auto& a = arg.eval(env);
    Values<typename Env::Scalar, Len> r;
    for (int i = 0; i < Len; ++i)
      r[i] = a[Start + i];
    return r;
  }
};

/// Concatenation of expressions (stacked vertically).
template <Expression... A>
struct CatExpr {
  static_assert(sizeof...(A) >= 1, "cat needs at least one operand");
  using expression_tag = void;                  ///< marks an expression node
  static constexpr int rows = (A::rows + ...);  ///< size
  std::tuple<A...> parts;                       ///< operands
  /// The stacked values.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    Values<typename Env::Scalar, rows> r;
    int off = 0;
    auto put = [&](const auto& p) {
      const auto& v = p.eval(env);
      for (int i = 0; i < std::remove_cvref_t<decltype(p)>::rows; ++i)
        r[off + i] = v[i];
      off += std::remove_cvref_t<decltype(p)>::rows;
    };
    std::apply([&](const auto&... p) { (put(p), ...); }, parts);
    return r;
  }
};

namespace detail {
/// True for a Symbol, or a concatenation of Symbols (the argument of a call node made of
/// arguments directly).
template <class A>
inline constexpr bool is_symbol_stack_v = false;
template <int Id, int N>
inline constexpr bool is_symbol_stack_v<Symbol<Id, N>> = true;
template <class... P>
inline constexpr bool is_symbol_stack_v<CatExpr<P...>> = (is_symbol_stack_v<P> && ...);

/// out[i].d[offset(Id) + j] += J(i, col + j) for a symbol part starting at column col.
template <class Env, int Id, int N, class S, int M, class JM>
void scatter_symbol(Values<S, M>& out, const JM& J, int col) {
  constexpr int off = Env::template offset<Id>();
  if constexpr (off >= 0) {
    for (int i = 0; i < M; ++i)
      for (int j = 0; j < N; ++j)
        out[i].d[off + j] += J(i, col + j);
  }
}
template <class Env, class S, int M, class JM, int Id, int N>
void scatter_columns(Values<S, M>& out, const JM& J, Symbol<Id, N>*) {
  scatter_symbol<Env, Id, N>(out, J, 0);
}
template <class Env, class S, int M, class JM, class... P>
void scatter_columns(Values<S, M>& out, const JM& J, CatExpr<P...>*) {
  int col = 0;
  ((scatter_symbol<Env, P::id, P::rows>(out, J, col), col += P::rows), ...);
}
}  // namespace detail

/// Custom-derivative node: RBD function object F applied to an F::nin-row expression, with its
/// Jacobian from F::value_and_jacobian<Tag, T> (Tag: Analytical or AutoDiff).
template <class Tag, class F, Expression A>
struct CallExpr {
  static_assert(A::rows == F::nin, "call: the arguments' total size must equal F::nin");
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = F::nout;  ///< size
  A arg;                                ///< the concatenated input
  /// F(x); at S = Dual<T, K>: value and Jacobian J from one provider call, d = J x.d.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using S = typename Env::Scalar;
    constexpr int nin = F::nin;
    const auto& x = arg.eval(env);
    Values<S, rows> out;
    if constexpr (is_dual_v<S>) {
      using T = typename S::Value;
      constexpr int K = S::directions;
      VecN<T, nin> xv;
      for (int j = 0; j < nin; ++j)
        xv[j] = x[j].v;
      VecN<T, rows> yv;
      Eigen::Matrix<T, rows, nin> J = Eigen::Matrix<T, rows, nin>::Zero();  // (set by F)
      F::template value_and_jacobian<Tag, T>(xv, yv, J);
      if constexpr (Env::seeded && detail::is_symbol_stack_v<A>) {
        // x is made of seeded arguments: x.d are unit vectors, so d = J x.d is a scatter of J's
        // columns (no products; parameters contribute nothing)
        for (int i = 0; i < rows; ++i)
          out[i] = S(yv[i]);
        detail::scatter_columns<Env>(out, J, static_cast<A*>(nullptr));
      } else {
        for (int i = 0; i < rows; ++i) {
          out[i].v = yv[i];
          for (int k = 0; k < K; ++k) {
            T acc = J(i, 0) * x[0].d[k];
            for (int j = 1; j < nin; ++j)
              acc += J(i, j) * x[j].d[k];
            out[i].d[k] = acc;
          }
        }
      }
    } else {
      VecN<S, rows> y;
      F::template value<S>(detail::to_eigen(x), y);
      for (int i = 0; i < rows; ++i)
        out[i] = y[i];
    }
    return out;
  }
};

/// Materialisation boundary: a generic function of the arguments' values, evaluated once.
template <int Nout, class F, Expression... A>
struct FnExpr {
  using expression_tag = void;       ///< marks an expression node
  static constexpr int rows = Nout;  ///< size
  F f;                               ///< the body, callable with VecN<S, A::rows>...
  std::tuple<A...> args;             ///< argument expressions
  /// f(args...) at the environment's scalar.
  template <class Env>
  Values<typename Env::Scalar, Nout> eval(const Env& env) const {
    using S = typename Env::Scalar;
    return std::apply(
        [&](const auto&... a) {
          return detail::to_values<S, Nout>(f(detail::to_eigen(a.eval(env))...));
        },
        args);
  }
};

/// Placeholder for the value bound by the let with key Key (see let()).
template <class Key, int N>
struct BoundExpr {
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = N;  ///< size
  /// The bound value.
  template <class Env>
  const auto& eval(const Env& env) const {
    return env.template bound<Key>();
  }
};

/// Materialisation boundary: Sub evaluated once, its value bound for Body.
template <class Key, Expression Sub, Expression Body>
struct LetExpr {
  using expression_tag = void;             ///< marks an expression node
  static constexpr int rows = Body::rows;  ///< size
  Sub sub;                                 ///< the shared subexpression
  Body body;                               ///< the expression using it through BoundExpr<Key>
  /// body with the placeholder bound to sub's value.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using V = Values<typename Env::Scalar, Sub::rows>;
    const detail::LetEnv<Key, Env, V> inner{env, sub.eval(env)};
    return body.eval(inner);
  }
};

// ---- construction ------------------------------------------------------------------------------

/// An operand of the binary operators: an expression or a plain number (a broadcast constant).
template <class X>
concept Operand = Expression<X> || Arithmetic<X>;

/// At least one of L and R is an expression.
template <class L, class R>
concept AnyExpression = Expression<L> || Expression<R>;

/// R and L are operands of a binary operator (L op R): operands, at least one an expression.
template <class R, class L>
concept OperandWith = Operand<L> && Operand<R> && AnyExpression<L, R>;

/// A fixed-size Eigen column vector type.
template <class V>
concept FixedVector = std::is_base_of_v<Eigen::EigenBase<V>, V> && V::ColsAtCompileTime == 1 &&
                      V::RowsAtCompileTime != Eigen::Dynamic;

/// A constant vector expression (parameters fixed at construction) from an Eigen vector.
template <FixedVector V>
ConstantExpr<V::RowsAtCompileTime> constant(const V& v) {
  ConstantExpr<V::RowsAtCompileTime> c{};
  const Eigen::Matrix<double, V::RowsAtCompileTime, 1> d = v.template cast<double>();
  for (int i = 0; i < V::RowsAtCompileTime; ++i)
    c.value[std::size_t(i)] = d[i];
  return c;
}
/// A constant scalar expression (1 row).
template <Arithmetic A>
ConstantExpr<1> constant(A a) {
  return ConstantExpr<1>{{double(a)}};
}

namespace detail {
template <class E>
auto as_expression(const E& e) {
  if constexpr (Expression<E>)
    return e;
  else
    return constant(e);
}
template <class Op, class L, class R>
auto binary(const L& l, const R& r) {
  using LE = decltype(as_expression(l));
  using RE = decltype(as_expression(r));
  return BinaryExpr<Op, LE, RE>{as_expression(l), as_expression(r)};
}
}  // namespace detail

/// Elementwise sum (a 1-row operand or a number is broadcast).
template <class L, OperandWith<L> R>
auto operator+(const L& l, const R& r) {
  return detail::binary<detail::AddOp>(l, r);
}
/// Elementwise difference (a 1-row operand or a number is broadcast).
template <class L, OperandWith<L> R>
auto operator-(const L& l, const R& r) {
  return detail::binary<detail::SubOp>(l, r);
}
/// Elementwise product; scalar * vector when one side has 1 row or is a number.
template <class L, OperandWith<L> R>
auto operator*(const L& l, const R& r) {
  return detail::binary<detail::MulOp>(l, r);
}
/// Elementwise quotient (a 1-row operand or a number is broadcast).
template <class L, OperandWith<L> R>
auto operator/(const L& l, const R& r) {
  return detail::binary<detail::DivOp>(l, r);
}
/// Elementwise negation.
template <Expression A>
UnaryExpr<detail::NegOp, A> operator-(const A& a) {
  return {a};
}
/// Elementwise sine.
template <Expression A>
UnaryExpr<detail::SinOp, A> sin(const A& a) {
  return {a};
}
/// Elementwise cosine.
template <Expression A>
UnaryExpr<detail::CosOp, A> cos(const A& a) {
  return {a};
}
/// Elementwise square root.
template <Expression A>
UnaryExpr<detail::SqrtOp, A> sqrt(const A& a) {
  return {a};
}
/// Inner product a^T b (1 row).
template <Expression L, Expression R>
DotExpr<L, R> dot(const L& a, const R& b) {
  return {a, b};
}
/// Squared Euclidean norm |a|^2 (1 row).
template <Expression A>
SquaredNormExpr<A> squared_norm(const A& a) {
  return {a};
}
/// Sum of the elements (1 row).
template <Expression A>
SumExpr<A> sum(const A& a) {
  return {a};
}
/// K a for a compile-time matrix K (zero entries cost nothing).
template <CompileTimeMatrix K, Expression A>
MatVecExpr<K, A> mul(const A& a) {
  return {a};
}
/// K a for a compile-time matrix K, written `K{} * a`.
template <CompileTimeMatrix K, Expression A>
MatVecExpr<K, A> operator*(const K&, const A& a) {
  return {a};
}
/// Elements Start .. Start + Len - 1.
template <int Start, int Len, Expression A>
SegmentExpr<Start, Len, A> segment(const A& a) {
  return {a};
}
/// Element I (1 row).
template <int I, Expression A>
SegmentExpr<I, 1, A> element(const A& a) {
  return {a};
}
/// Vertical concatenation (a single operand is returned as is).
template <Expression... A>
auto cat(const A&... a) {
  if constexpr (sizeof...(A) == 1)
    return (a, ...);
  else
    return CatExpr<A...>{std::tuple<A...>(a...)};
}
/// Custom-derivative node: F (an rbd_functions.hpp function object) of the concatenated args,
/// Jacobian from provider Tag (Analytical or AutoDiff).
template <class Tag, class F, Expression... A>
auto call(F, const A&... args) {
  using X = decltype(cat(args...));
  return CallExpr<Tag, F, X>{cat(args...)};
}
/// Materialisation boundary: f(values of args...) -> Nout-vector, each argument evaluated once.
template <int Nout, class F, Expression... A>
FnExpr<Nout, F, A...> fn(F f, const A&... args) {
  return {f, std::tuple<A...>(args...)};
}
/// Materialisation boundary: e evaluated once and bound to the placeholder passed to body.
template <Expression E, class F>
auto let(const E& e, F body) {
  using Bound = BoundExpr<F, std::remove_cvref_t<E>::rows>;
  using Body = decltype(body(Bound{}));
  static_assert(Expression<Body>, "a let body must return an expression");
  return LetExpr<F, E, Body>{e, body(Bound{})};
}

/// The scalar type of a vector passed to an fn body: `using S = ScalarOf<decltype(x)>;`.
template <class X>
using ScalarOf = typename std::remove_cvref_t<X>::Scalar;

// ---- evaluation and derivatives ----------------------------------------------------------------

/// Value and Jacobian of a vector expression (one evaluation).
template <class T, int M, int N>
struct ValueJacobian {
  VecN<T, M> value;                 ///< e(args)
  Eigen::Matrix<T, M, N> jacobian;  ///< d e / d (differentiated args)
};

/// Value, gradient and Hessian of a scalar expression (one evaluation).
template <class T, int N>
struct ValueGradientHessian {
  T value;              ///< e(args)
  VecN<T, N> gradient;  ///< d e / d (differentiated args)
  MatN<T, N> hessian;   ///< d^2 e / d (differentiated args)^2 (symmetric to rounding)
};

namespace detail {
template <class... A>
using scalar_of_args = typename ArgPack<std::remove_cvref_t<A>...>::Scalar;

template <int... Wrt>
struct IdList {};

/// Where each argument's derivative directions start (-1: not differentiated) and how many.
template <class Ids, class... A>
struct Layout;
template <int... Wrt, class... A>
struct Layout<IdList<Wrt...>, A...> {
  static_assert(wrt_valid<sizeof...(A), Wrt...>(),
                "the Ids to differentiate with respect to must be distinct argument indices");
  static constexpr std::array<int, sizeof...(A)> offsets =
      wrt_offsets<sizeof...(A), Wrt...>(ArgPack<std::remove_cvref_t<A>...>::sizes);
  static constexpr int directions = wrt_size(ArgPack<std::remove_cvref_t<A>...>::sizes, offsets);
};

/// e evaluated at S with the arguments seeded as listed in Wrt.
template <class S, int... Wrt, Expression E, class... A>
Values<S, E::rows> eval_at(const E& e, const A&... args) {
  using T = scalar_of_args<A...>;
  constexpr auto off = Layout<IdList<Wrt...>, A...>::offsets;
  const auto env =
      make_env<S, T, !std::is_same_v<S, T>, off>(std::index_sequence_for<A...>{}, args...);
  return e.eval(env);
}
}  // namespace detail

/// Value of e; argument i is the value of Symbol<i, N> (Eigen N-vector, or a scalar if N == 1).
template <Expression E, class... A>
VecN<detail::scalar_of_args<A...>, E::rows> evaluate(const E& e, const A&... args) {
  return detail::to_eigen(detail::eval_at<detail::scalar_of_args<A...>>(e, args...));
}

/// Value and Jacobian of e with respect to the arguments Wrt... (all, stacked by Id, if none).
template <int... Wrt, Expression E, class... A>
auto value_and_jacobian(const E& e, const A&... args) {
  using T = detail::scalar_of_args<A...>;
  constexpr int n = detail::Layout<detail::IdList<Wrt...>, A...>::directions;
  static_assert(n >= 1, "nothing to differentiate with respect to");
  const Values<Dual<T, n>, E::rows> r = detail::eval_at<Dual<T, n>, Wrt...>(e, args...);
  ValueJacobian<T, E::rows, n> out;
  for (int i = 0; i < E::rows; ++i) {
    out.value[i] = r[i].v;
    for (int k = 0; k < n; ++k)
      out.jacobian(i, k) = r[i].d[k];
  }
  return out;
}

/// Jacobian of e with respect to the arguments Wrt... (all, stacked by Id, if none).
template <int... Wrt, Expression E, class... A>
auto jacobian(const E& e, const A&... args) {
  return value_and_jacobian<Wrt...>(e, args...).jacobian;
}

/// Gradient of a scalar expression (1 row) with respect to Wrt... (all if none).
template <int... Wrt, Expression E, class... A>
auto gradient(const E& e, const A&... args) {
  static_assert(E::rows == 1, "gradient needs a scalar (1-row) expression");
  using T = detail::scalar_of_args<A...>;
  constexpr int n = detail::Layout<detail::IdList<Wrt...>, A...>::directions;
  return VecN<T, n>(value_and_jacobian<Wrt...>(e, args...).jacobian.transpose());
}

/// Value, gradient and Hessian of a scalar expression with respect to Wrt... (all if none),
/// from one evaluation at Dual<Dual<T, n>, n>.
template <int... Wrt, Expression E, class... A>
auto value_gradient_hessian(const E& e, const A&... args) {
  static_assert(E::rows == 1, "hessian needs a scalar (1-row) expression");
  using T = detail::scalar_of_args<A...>;
  constexpr int n = detail::Layout<detail::IdList<Wrt...>, A...>::directions;
  static_assert(n >= 1, "nothing to differentiate with respect to");
  using S = Dual<Dual<T, n>, n>;
  const Values<S, 1> r = detail::eval_at<S, Wrt...>(e, args...);
  ValueGradientHessian<T, n> out;
  out.value = r[0].v.v;
  for (int a = 0; a < n; ++a) {
    out.gradient[a] = r[0].v.d[a];
    for (int b = 0; b < n; ++b)
      out.hessian(a, b) = r[0].d[a].d[b];
  }
  return out;
}

/// Hessian of a scalar expression with respect to Wrt... (all if none).
template <int... Wrt, Expression E, class... A>
auto hessian(const E& e, const A&... args) {
  return value_gradient_hessian<Wrt...>(e, args...).hessian;
}

}  // namespace arbor::ad
