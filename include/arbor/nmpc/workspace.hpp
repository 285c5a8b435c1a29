// arbor::nmpc: the workspace of a problem's RBD function objects at the scalars a controller
// evaluates them at, from what the controller type already fixes: the problem's Dims D, the
// provider Tag of its call nodes, the controller's Scalar T and HessianKind H.
//
//   nmpc::Workspace<D, Tag, T, H, F1, F2, ...>   one ad::RbdWorkspace (one robot) holding
//     for every Fi          ValueWorkspace<Fi, T> (merit, line search, shift) and
//                           JacobianWorkspace<Fi, Tag, T> (a call node at Dual<T, n> runs the
//                           provider at T: SCQP, and the exact mode's Gauss-Newton fallback)
//     H = exact, also       JacobianWorkspace<Fi, Tag, Dual<T, nx + nu>> (path stages: the
//                           Lagrangian at Dual<Dual<T, n>, n> runs the provider at Dual<T, n>)
//                           and JacobianWorkspace<Fi, Tag, Dual<T, nx>> (terminal stage), the
//                           latter not for Fi = PathOnly<F> (a function that no terminal term
//                           calls: the dynamics, path constraints)
//     a FramePose among Fi  a PoseCache at T (ad::WithPoseCache: a FramePosition of the same
//                           frame at the same q reuses the pose's analytical Jacobian)
// Each scalar's Data (and DerivativeData) is held once however many functions need it; the
// provider decides what a Jacobian needs (JacobianWorkspace: Analytical, a Data and for the
// dynamics a DerivativeData at the scalar; AutoDiff, a Data at Dual<scalar, nin>; Generated,
// nothing, or AutoDiff's for functions without generated code, ad::ProviderOf). Sizes: the
// exact Hessian with AutoDiff holds Data<R, Dual<Dual<T, nx + nu>, nin>>, megabytes for a
// 7-DoF arm: give the workspace static storage. Listing a function the problem does not call
// only costs memory; leaving one out is a compile error naming the missing scalar.
// Nothing here runs: it is a type computation.
#pragma once

#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/frame_functions.hpp"
#include "arbor/ad/rbd_functions.hpp"
#include "arbor/ad/rbd_workspace.hpp"
#include "arbor/ocp/linearize.hpp"

namespace arbor::nmpc {

/// Marks function F as called by path stages only (dynamics, path costs and constraints): no
/// terminal-stage storage for the exact Hessian.
template <class F>
struct PathOnly {
  using Function = F;  ///< the function object
};

namespace detail {
template <class E>
struct Use {
  using Function = E;
  static constexpr bool terminal = true;
};
template <class F>
struct Use<PathOnly<F>> {
  using Function = F;
  static constexpr bool terminal = false;
};

template <class F>
inline constexpr bool is_pose = false;
template <class R, int f>
inline constexpr bool is_pose<ad::FramePose<R, f>> = true;

/// The plan of one function entry E (F or PathOnly<F>).
template <class D, class Tag, class T, ocp::HessianKind H, class E>
struct PlanOf {
  using F = typename Use<E>::Function;
  using base = ad::MergedWorkspace<ad::ValueWorkspace<F, T>, ad::JacobianWorkspace<F, Tag, T>>;
  using path = ad::JacobianWorkspace<F, Tag, ad::Dual<T, D::nx + D::nu>>;
  using terminal = ad::JacobianWorkspace<F, Tag, ad::Dual<T, D::nx>>;
  using exact = std::conditional_t<Use<E>::terminal, ad::MergedWorkspace<base, path, terminal>,
                                   ad::MergedWorkspace<base, path>>;
  using type = std::conditional_t<H == ocp::HessianKind::exact, exact, base>;
};

template <class D, class Tag, class T, ocp::HessianKind H, class... Es>
struct WorkspaceOf {
  static_assert(sizeof...(Es) >= 1, "nmpc::Workspace: list the problem's RBD function objects");
  using merged = ad::MergedWorkspace<typename PlanOf<D, Tag, T, H, Es>::type...>;
  using type = std::conditional_t<(is_pose<typename Use<Es>::Function> || ...),
                                  ad::WithPoseCache<merged, T>, merged>;
};
}  // namespace detail

/// The workspace of the RBD function objects Fs... (each F or PathOnly<F>; one robot) of a
/// problem with dimensions D (ocp::Dims) whose call nodes use provider Tag, for a controller
/// nmpc::Nmpc<Problem, T, H>. Declare one (static storage), bind every handle to it.
template <class D, class Tag, class T, ocp::HessianKind H, class... Fs>
using Workspace = typename detail::WorkspaceOf<D, Tag, T, H, Fs...>::type;

}  // namespace arbor::nmpc
