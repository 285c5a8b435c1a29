// arbor: RbdWorkspace, the caller-owned storage of the AD layer's RBD function objects: one Data
// per scalar type the functions are evaluated at (double, a Dual for AutoDiff Jacobians, nested
// Duals for Hessians) and one DerivativeData per scalar type the analytical derivatives run at.
// Its sizeof is the memory the functions use; nothing is static or hidden.
#pragma once

#include <tuple>
#include <type_traits>

#include "arbor/derivatives/derivative_data.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/payload.hpp"

namespace arbor::ad {

/// A list of scalar types (a workspace's storage plan).
template <class... Ts>
struct Scalars {};

namespace detail {
template <class T, class... Ts>
inline constexpr bool contains = (std::is_same_v<T, Ts> || ...);
template <class List, class T>
struct PushUnique;
template <class... Ts, class T>
struct PushUnique<Scalars<Ts...>, T> {
  using type = std::conditional_t<contains<T, Ts...>, Scalars<Ts...>, Scalars<Ts..., T>>;
};
}  // namespace detail

/// The union of scalar lists, each type once, in first-seen order.
template <class... Lists>
struct Union;
template <>
struct Union<> {
  using type = Scalars<>;
};
template <class... Ts>
struct Union<Scalars<Ts...>> {
  using type = typename Union<Scalars<>, Scalars<Ts...>>::type;
};
template <class... As>
struct Union<Scalars<As...>, Scalars<>> {
  using type = Scalars<As...>;
};
template <class... As, class B, class... Bs>
struct Union<Scalars<As...>, Scalars<B, Bs...>> {
  using type =
      typename Union<typename detail::PushUnique<Scalars<As...>, B>::type, Scalars<Bs...>>::type;
};
template <class L1, class L2, class L3, class... Ls>
struct Union<L1, L2, L3, Ls...> {
  using type = typename Union<typename Union<L1, L2>::type, L3, Ls...>::type;
};

template <class R, class DataScalars, class DerivativeScalars = Scalars<>>
struct RbdWorkspace;

/// Storage for robot R: a Data<R, T> for each T in Ds and a DerivativeData<R, T> for each T in Gs
/// (each type at most once). Default constructible; large for nested duals, so give it static
/// storage or a member of a long-lived object, not a stack frame.
template <class R, class... Ds, class... Gs>
struct RbdWorkspace<R, Scalars<Ds...>, Scalars<Gs...>> {
  using Robot = R;                                         ///< the robot type
  [[no_unique_address]] std::tuple<Data<R, Ds>...> data_;  ///< one Data per scalar of Ds
  [[no_unique_address]] std::tuple<DerivativeData<R, Gs>...>
      deriv_;  ///< one DerivativeData per scalar of Gs

  /// Whether it holds a Data, a DerivativeData of scalar type T.
  template <class T>
  static constexpr bool holds_data = detail::contains<T, Ds...>;
  template <class T>
  static constexpr bool holds_derivatives = detail::contains<T, Gs...>;

  /// The Data of scalar type T.
  template <class T>
  Data<R, T>& data() {
    static_assert(detail::contains<T, Ds...>,
                  "this RbdWorkspace has no Data for that scalar type: use the workspace alias of "
                  "the call (ValueWorkspace, JacobianWorkspace, HessianWorkspace) or add it");
    return std::get<Data<R, T>>(data_);
  }
  /// The DerivativeData of scalar type T.
  template <class T>
  DerivativeData<R, T>& derivatives() {
    static_assert(detail::contains<T, Gs...>,
                  "this RbdWorkspace has no DerivativeData for that scalar type: use the "
                  "workspace alias of the call (JacobianWorkspace, HessianWorkspace) or add it");
    return std::get<DerivativeData<R, T>>(deriv_);
  }
};

/// Sets the payload (set_payload, dynamics/payload.hpp) on every Data of ws, at each one's scalar
/// type (AD scalars as constants: the payload is not differentiated). The function objects then
/// evaluate and differentiate the robot with the payload under the Analytical, AutoDiff and
/// SecondOrder providers; Generated code has the robot's constant inertias folded in, so a
/// Generated call on a workspace that holds a Data at its scalar (and a DerivativeData, for the
/// dynamics) runs the analytical routines while a payload is set (rbd_functions.hpp). Returns
/// false (payload cleared) for a bad frame or a negative mass, and when ws holds no Data at all.
template <class R, class... Ds, class... Gs, class T>
bool set_payload(RbdWorkspace<R, Scalars<Ds...>, Scalars<Gs...>>& ws, int frame, const T& mass,
                 const std::type_identity_t<Vec3<T>>& com,
                 const std::type_identity_t<Mat3<T>>& Ic) {
  bool ok = sizeof...(Ds) > 0;
  ((ok = arbor::set_payload<R, Ds>(ws.template data<Ds>(), frame, Ds(mass),
                                   com.template cast<Ds>().eval(), Ic.template cast<Ds>().eval()) &&
         ok),
   ...);
  return ok;
}

/// Removes the payload from every Data of ws.
template <class R, class... Ds, class... Gs>
void clear_payload(RbdWorkspace<R, Scalars<Ds...>, Scalars<Gs...>>& ws) {
  (arbor::clear_payload<R, Ds>(ws.template data<Ds>()), ...);
}

/// The workspace that serves every call of each of the workspaces Ws (same robot).
template <class... Ws>
struct MergedWorkspaceOf;
template <class R, class... D, class... G>
struct MergedWorkspaceOf<RbdWorkspace<R, D, G>...> {
  using type = RbdWorkspace<R, typename Union<D...>::type, typename Union<G...>::type>;
};
template <class... Ws>
using MergedWorkspace = typename MergedWorkspaceOf<Ws...>::type;

}  // namespace arbor::ad
