// arbor: the derivative-provider tags of the AD layer. A call node of an RBD function (or a
// function object's value_and_jacobian) is told at compile time where its Jacobian comes from.
#pragma once

namespace arbor::ad {

/// Jacobian provider tag: the analytical derivative routines (the paper's J^a; H^a for second
/// order, where the analytical first-order routine runs in dual arithmetic).
struct Analytical {};
/// Jacobian provider tag: dual numbers through the RBD templates (the paper's J^c; H^c for second
/// order, nested duals).
struct AutoDiff {};
/// Hessian provider tag (contracted_hessian only): the analytical second-order routines
/// (rnea_second_order_derivatives, aba_second_order_derivatives), no dual numbers.
struct SecondOrder {};

}  // namespace arbor::ad
