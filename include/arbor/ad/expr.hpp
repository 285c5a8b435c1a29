// arbor: expression templates for OCP functions, with custom-derivative nodes (the one header
// users include; the parts are in ad/expr/, one concern each).
//
// An expression is a small value type built from symbols and operators:
//
//   constexpr ad::Symbol<0, 7> q;          // argument 0: a 7-vector
//   constexpr ad::Symbol<1, 1> s;          // argument 1: a scalar
//   auto e = ad::call<ad::Analytical>(frame_position_handle, q) - p_ref(s);
//   auto cost = ad::squared_norm(e);
//   auto g = ad::gradient(cost, q_value, s_value);   // d cost / d (q, s), an 8-vector
//   auto H = ad::hessian(cost, q_value, s_value);    // 8 x 8
//
// Nodes and evaluation. Every node holds its children by value (symbols are empty types), knows
// its size at compile time (`rows`), and `eval(env)` returns its concrete value, Values<S, rows>
// (a plain array of the environment's scalar type S): every node is materialised, no lazy
// expression escapes a node, nothing allocates, and the template depth of an evaluation is the
// depth of the expression tree. Differentiation is forward mode over the same code, at Dual
// scalars. T, the arguments' scalar, is double, float, or an operation-counting type.
//
//   expr/values.hpp           Values<S, N>, the Expression concept, Eigen conversions
//   expr/scalar.hpp           (detail) constants and seeds in nested duals, scaling by a number
//   expr/environment.hpp      (detail) the arguments of an evaluation and their seeds
//   expr/leaves.hpp           Symbol<Id, N>, constant(v)
//   expr/elementwise.hpp      + - * / (broadcasting), unary -, sin, cos, sqrt
//   expr/reductions.hpp       dot, squared_norm, sum
//   expr/blocks.hpp           segment, element, cat
//   expr/constant_matrix.hpp  mul<K>(x), K{} * x: compile-time constant matrices
//                             (spatial/constant.hpp's products), ConstMatrix, TransposedMatrix
//   expr/structure.hpp        (detail) the derivative directions each node depends on, and the
//                             compressed duals fn bodies run at (structure-aware forward mode)
//   expr/boundaries.hpp       let, fn, fn_dense: subexpressions evaluated once (and the `auto`
//                             pitfall)
//   expr/call.hpp             call<Tag>(f, args...): custom-derivative nodes (f a cheap handle)
//   expr/evaluate.hpp         evaluate, jacobian, gradient, hessian, value_and_jacobian,
//                             value_gradient_hessian
//
// Resources: no heap, no exceptions, no RTTI. Evaluations use the stack: at
// S = Dual<Dual<double, n>, n> every scalar is 8 (n + 1)^2 bytes, so keep n and the vector
// sizes of Hessian evaluations moderate on small targets. Custom nodes use the workspace their
// function object refers to (caller-owned; one per concurrent evaluation). See
// docs/ad_expressions.md.
#pragma once

#include "arbor/ad/expr/blocks.hpp"
#include "arbor/ad/expr/boundaries.hpp"
#include "arbor/ad/expr/call.hpp"
#include "arbor/ad/expr/constant_matrix.hpp"
#include "arbor/ad/expr/elementwise.hpp"
#include "arbor/ad/expr/environment.hpp"
#include "arbor/ad/expr/evaluate.hpp"
#include "arbor/ad/expr/leaves.hpp"
#include "arbor/ad/expr/reductions.hpp"
#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/structure.hpp"
#include "arbor/ad/expr/values.hpp"
