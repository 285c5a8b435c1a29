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
/// Jacobian and Hessian provider tag: straight-line code generated at build time by symbolic
/// differentiation of the RBD templates (gen/ad, CMake arbor_add_robot_ad; the paper's J^c and
/// H^c as CasADi generates them). The robot's generated header must be included.
struct Generated {};

/// The generated Jacobian of function object F (ForwardDynamics<R>, InverseDynamics<R>,
/// FramePosition<R, f>). This primary template says "none"; <robots/NAME_ad.hpp>, written by
/// arbor-adgen, specialises it with available = true and
///   template <class S> static void jacobian(const S* x, S* y, S* J);   // J column major
template <class F>
struct GeneratedCode {
  static constexpr bool available = false;
};
/// The generated Hessian of lambda^T F (ForwardDynamics<R>, InverseDynamics<R>): none here;
/// <robots/NAME_ad_hessian.hpp> (arbor_add_robot_ad ... HESSIANS) specialises it with
///   template <class S> static void hessian(const S* x, const S* lambda, S* y, S* H);
template <class F>
struct GeneratedHessian {
  static constexpr bool available = false;
};

}  // namespace arbor::ad
