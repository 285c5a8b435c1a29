// arbor: a user's OCP function as a call node with generated straight-line derivatives: the
// function written once as generic scalar code, its Jacobian generated at build time by the same
// symbolic pass as the RBD functions' (gen/ad: folding, common subexpressions, dead code,
// forward or reverse mode, whichever executes fewer operations), so the derivative costs its live
// operation count, not (number of directions) x (primal) as forward mode does.
//
//   struct Track {                                   // a UserFunction
//     static constexpr int nin = 14, nout = 9, nparam = 13;
//     template <class S> static void eval(const S* x, const S* p, S* y);   // y = f(x; p)
//   };
//   // CMake: arbor_add_function_ad(my_fn_ad HEADER my_fn_ad.hpp INCLUDE my_functions.hpp
//   //                              FUNCTIONS Track INCLUDE_DIRS ...)  -> GeneratedFunction<Track>
//   const double params[13] = {...};                 // caller-owned, read at every evaluation
//   auto e = ad::call<ad::Generated>(ad::user_function<Track>(params), pose, ad::segment<14,
//   2>(x));
//
// x are the differentiated inputs; p are parameters (run-time values, not differentiated; the
// handle keeps a pointer to them, so they may change between evaluations). Providers: Generated
// (the generated header included), AutoDiff (Dual<T, nin> through eval; no generation needed).
// eval must be branch-free in the traced values (the generator refuses value-dependent
// branches) and use arbor::sin/cos/sqrt. Cost: Generated, the emitted operations
// (GeneratedFunction<F>::jacobian_ops); AutoDiff, eval at Dual<T, nin>. No heap; the generated
// temporaries are locals.
#pragma once

#include <Eigen/Core>
#include <array>
#include <concepts>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/provider.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::ad {

/// A user function: nin differentiated inputs, nout outputs, nparam parameters, and
/// `template <class S> static void eval(const S* x, const S* p, S* y)`, generic over S.
template <class F>
concept UserFunction = requires {
  { F::nin } -> std::convertible_to<int>;
  { F::nout } -> std::convertible_to<int>;
  { F::nparam } -> std::convertible_to<int>;
}
&&F::nin >= 1 && F::nout >= 1 && F::nparam >= 0;

/// The generated Jacobian of user function F: none here; a header written by arbor-adgen
/// (CMake arbor_add_function_ad) specialises it with available = true, primal_ops,
/// jacobian_ops, nonzero[nout * nin] (the entries of J not identically zero) and
///   template <class S> static void jacobian(const S* x, const S* p, S* y, S* J);  // J col-major
template <class F>
struct GeneratedFunction {
  static constexpr bool available = false;
};

/// A call-node function object for user function F with parameters at *params (F::nparam values
/// of type P, owned by the caller, read at every evaluation). Trivially copyable (a pointer).
template <UserFunction F, class P = double>
struct UserFunctionHandle {
  static constexpr int nin = F::nin;    ///< inputs
  static constexpr int nout = F::nout;  ///< outputs
  const P* params = nullptr;            ///< F::nparam parameters (caller-owned)

  /// Which entries of the Jacobian (column major) are not identically zero: the generated code's
  /// structure when there is one, else all. A call node skips the others in its chain rule.
  static constexpr std::array<bool, std::size_t(nout* nin)> jacobian_nonzero() {
    std::array<bool, std::size_t(nout * nin)> nz{};
    for (std::size_t k = 0; k < nz.size(); ++k) {
      if constexpr (GeneratedFunction<F>::available)
        nz[k] = GeneratedFunction<F>::nonzero[k];
      else
        nz[k] = true;
    }
    return nz;
  }

  /// y = f(x; p) at scalar T.
  template <class T>
  void value(const VecN<T, nin>& x, VecN<T, nout>& y) const {
    const auto p = parameters<T>();
    F::template eval<T>(x.data(), p.data(), y.data());
  }
  /// y and J = d y / d x at scalar T from provider Tag (Generated or AutoDiff).
  template <class Tag, class T>
  void value_and_jacobian(const VecN<T, nin>& x, VecN<T, nout>& y,
                          Eigen::Matrix<T, nout, nin>& J) const {
    if constexpr (std::is_same_v<Tag, Generated>) {
      static_assert(GeneratedFunction<F>::available,
                    "no generated code for this user function: list it in "
                    "arbor_add_function_ad(... FUNCTIONS ...) and include the generated header");
      const auto p = parameters<T>();
      GeneratedFunction<F>::jacobian(x.data(), p.data(), y.data(), J.data());
    } else {
      static_assert(std::is_same_v<Tag, AutoDiff>,
                    "a user function's provider is Generated or AutoDiff");
      using D = Dual<T, nin>;
      D xd[nin];
      for (int k = 0; k < nin; ++k)
        xd[k] = D::variable(x[k], k);
      const auto pd = parameters<T, D>();
      D yd[nout];
      F::template eval<D>(xd, pd.data(), yd);
      for (int i = 0; i < nout; ++i) {
        y[i] = yd[i].v;
        for (int k = 0; k < nin; ++k)
          J(i, k) = yd[i].d[k];
      }
    }
  }

 private:
  /// The parameters as constants of type U (through T: U may be a dual of T).
  template <class T, class U = T>
  std::array<U, std::size_t(F::nparam)> parameters() const {
    std::array<U, std::size_t(F::nparam)> p;
    for (int k = 0; k < F::nparam; ++k)
      p[std::size_t(k)] = U(T(params[k]));
    return p;
  }
};

/// The call-node handle of user function F with parameters at params (F::nparam values).
template <UserFunction F, class P>
UserFunctionHandle<F, P> user_function(const P* params) {
  return {params};
}
/// The call-node handle of a user function without parameters.
template <UserFunction F>
UserFunctionHandle<F, double> user_function() {
  static_assert(F::nparam == 0, "this user function has parameters: pass a pointer to them");
  return {nullptr};
}

}  // namespace arbor::ad
