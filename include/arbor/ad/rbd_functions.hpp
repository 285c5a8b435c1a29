// arbor: RBD functions as differentiable function objects, with a choice of Jacobian provider and
// caller-owned workspaces.
//
// A function F is a stateless descriptor with
//   static constexpr int nin, nout;
//   template <class T, class W> static void value(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y);
//   template <class T, class W> static void analytical(W& ws, x, y, J);   // y and J^a, one pass
// and three workspace plans: ValueWorkspace<F, T>, JacobianWorkspace<F, Tag, T> and
// HessianWorkspace<F, Tag, T> (ad/contracted_hessian.hpp) name the RbdWorkspace that a call needs.
// `bind<F>(ws)` makes a handle (a pointer to the caller's workspace, cheap to copy) with
//   value(x, y)                          y = F(x)
//   value_and_jacobian<Tag>(x, y, J)     y and J = dy/dx from provider Tag, in one pass
// which is also what the expression layer's call<Tag>(handle, args...) node uses. The provider:
//   Analytical  the analytical derivative routines (rnea_derivatives, aba_derivatives,
//               frame_position_derivative): the paper's J^a;
//   AutoDiff    Dual<T, nin> through the RBD templates: the paper's J^c;
//   Generated   straight-line code generated at build time by symbolic differentiation of the
//               same templates (gen/ad; include the robot's generated header, e.g.
//               <robots/kinova_gen3_ad.hpp> from arbor_add_robot_ad): J^c as CasADi makes it.
// The functions are:
//   ForwardDynamics<R>      x = (q, v, tau) -> ddq         (aba)
//   InverseDynamics<R>      x = (q, v, a)   -> tau         (rnea)
//   FramePosition<R, F>     x = q           -> p_F (world) (forward kinematics; F a frame_id)
// and, in frame_functions.hpp, FramePose, FrameOrientationError and FrameVelocity.
// Cost per call: value = one RBD pass at T; J^a = one analytical derivative sweep; J^c = one RBD
// pass at Dual<T, nin> (nin + 1 times the arithmetic of a value).
//
// Reentrancy: a handle touches only its workspace, so two controllers, an interrupt and a task,
// or two robots each with their own workspace never share state. Sizes: sizeof the workspace
// (e.g. JacobianWorkspace<ForwardDynamics<Kinova>, AutoDiff> holds one Data<Kinova, Dual<double,
// 21>>). Eigen refuses fixed-size matrices above EIGEN_STACK_ALLOCATION_LIMIT (128 KB) even in
// static storage: Data<R, Dual<T, n>> for large robots (Atlas: 30 x 30 x 91 doubles) needs that
// limit raised (EIGEN_STACK_ALLOCATION_LIMIT=0) in the program that instantiates it.
#pragma once

#include <Eigen/Core>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/provider.hpp"
#include "arbor/ad/rbd_workspace.hpp"
#include "arbor/derivatives/aba_derivatives.hpp"
#include "arbor/derivatives/frame_derivatives.hpp"
#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/dynamics/aba.hpp"
#include "arbor/dynamics/jacobian.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"

namespace arbor::ad {

namespace detail {
template <class T, int N, class X>
void seed(const Eigen::MatrixBase<X>& x, VecN<Dual<T, N>, N>& xd) {
  for (int k = 0; k < N; ++k)
    xd[k] = Dual<T, N>::variable(x[k], k);
}
template <class T, int N, int M>
void unseed(const VecN<Dual<T, N>, M>& yd, VecN<T, M>& y, Eigen::Matrix<T, M, N>& J) {
  for (int i = 0; i < M; ++i) {
    y[i] = yd[i].v;
    for (int k = 0; k < N; ++k)
      J(i, k) = yd[i].d[k];
  }
}

/// True when F declares `static constexpr bool generated_fallback = true` (no generated code;
/// the Generated tag runs AutoDiff for it).
template <class F>
inline constexpr bool generated_fallback_v = requires {
  requires F::generated_fallback;
};
}  // namespace detail

/// The provider that serves tag Tag for function F: Tag itself, except that Generated runs
/// AutoDiff for a function that has no generated code and declares `generated_fallback`
/// (FramePose, FrameOrientationError, FrameVelocity: frame_functions.hpp). So one tag serves a
/// whole problem; ForwardDynamics, InverseDynamics and FramePosition without their generated
/// header are still a compile error under Generated.
template <class Tag, class F>
using ProviderOf =
    std::conditional_t<std::is_same_v<Tag, Generated> && !GeneratedCode<F>::available &&
                           detail::generated_fallback_v<F>,
                       AutoDiff, Tag>;

namespace detail {

/// Whether workspace W holds the analytical routines' storage at scalar T (a Data, and a
/// DerivativeData when Deriv), which the Generated provider falls back to while a payload is set.
template <class W, class T, bool Deriv>
constexpr bool can_fall_back() {
  if constexpr (requires { W::template holds_data<T>; })
    return W::template holds_data<T> && (!Deriv || W::template holds_derivatives<T>);
  else
    return false;
}

/// y = F(x) and J = d y / d x at scalar T from provider Tag, with workspace ws (the one place
/// where the provider tag is dispatched). AutoDiff: one pass of Dual<T, F::nin> through
/// F::value; Analytical: F::analytical. Called through Bound::value_and_jacobian.
template <class F, class Tag0, class T, class W>
void provider_value_and_jacobian(W& ws, const VecN<T, F::nin>& x, VecN<T, F::nout>& y,
                                 Eigen::Matrix<T, F::nout, F::nin>& J) {
  using Tag = ProviderOf<Tag0, F>;
  if constexpr (std::is_same_v<Tag, Analytical>) {
    F::analytical(ws, x, y, J);
  } else if constexpr (std::is_same_v<Tag, Generated>) {
    static_assert(GeneratedCode<F>::available,
                  "no generated code for this function: generate the robot's AD header "
                  "(CMake arbor_add_robot_ad) and include it before this call");
    // a payload set on the workspace (it holds the analytical routines' Data): the generated code
    // knows only the robot's constant inertias, so the analytical routines answer
    if constexpr (can_fall_back<W, T, F::needs_derivative_data>()) {
      if (ws.template data<T>().payload.active) {
        F::analytical(ws, x, y, J);
        return;
      }
    }
    (void)ws;
    GeneratedCode<F>::jacobian(x.data(), y.data(), J.data());
  } else {
    static_assert(std::is_same_v<Tag, AutoDiff>, "Tag must be Analytical, AutoDiff or Generated");
    using D = Dual<T, F::nin>;
    VecN<D, F::nin> xd;
    seed<T, F::nin>(x, xd);
    VecN<D, F::nout> yd;
    F::value(ws, xd, yd);
    unseed<T, F::nin, F::nout>(yd, y, J);
  }
}
}  // namespace detail

/// The workspace F::value needs at scalar T.
template <class F, class T = double>
using ValueWorkspace = RbdWorkspace<typename F::Robot, Scalars<T>>;

/// The workspace value_and_jacobian<F, Tag, T> needs: Analytical, a Data and (for the dynamics)
/// a DerivativeData at T; AutoDiff, a Data at Dual<T, F::nin>; Generated, nothing (its
/// temporaries are the generated function's locals, on the stack; a function that falls back to
/// AutoDiff, AutoDiff's).
template <class F, class Tag0, class T = double, class Tag = ProviderOf<Tag0, F>>
using JacobianWorkspace = std::conditional_t<
    std::is_same_v<Tag, Generated>, RbdWorkspace<typename F::Robot, Scalars<>>,
    std::conditional_t<
        std::is_same_v<Tag, Analytical>,
        RbdWorkspace<typename F::Robot, Scalars<T>,
                     std::conditional_t<F::needs_derivative_data, Scalars<T>, Scalars<>>>,
        RbdWorkspace<typename F::Robot, Scalars<Dual<T, F::nin>>>>>;

/// A handle binding function F to a caller-owned workspace W (a pointer: cheap to copy; the
/// workspace must outlive the handle and provide every scalar the handle is called at).
template <class F, class W>
struct Bound {
  static constexpr int nin = F::nin;    ///< inputs
  static constexpr int nout = F::nout;  ///< outputs
  using Function = F;                   ///< the function descriptor
  W* ws;                                ///< the caller's workspace

  /// y = F(x) at scalar T.
  template <class T>
  void value(const VecN<T, nin>& x, VecN<T, nout>& y) const {
    F::value(*ws, x, y);
  }
  /// y = F(x) and J = d y / d x from provider Tag, in one pass.
  template <class Tag, class T>
  void value_and_jacobian(const VecN<T, nin>& x, VecN<T, nout>& y,
                          Eigen::Matrix<T, nout, nin>& J) const {
    detail::provider_value_and_jacobian<F, Tag>(*ws, x, y, J);
  }
};

/// A handle for function F on workspace ws.
template <class F, class W>
Bound<F, W> bind(W& ws) {
  static_assert(std::is_same_v<typename W::Robot, typename F::Robot>,
                "the workspace belongs to another robot");
  return Bound<F, W>{&ws};
}

/// Forward dynamics x = (q, v, tau) -> ddq of robot R.
template <Robot R>
struct ForwardDynamics {
  using Robot = R;
  static constexpr int nv = R::nv;                     ///< DoF
  static constexpr int nin = 3 * nv;                   ///< inputs (q, v, tau)
  static constexpr int nout = nv;                      ///< outputs (ddq)
  static constexpr bool needs_derivative_data = true;  ///< J^a uses aba_derivatives

  /// y = aba(q, v, tau).
  template <class T, class W>
  static void value(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = ws.template data<T>();
    y = aba<R>(d, x.template segment<nv>(0), x.template segment<nv>(nv),
               x.template segment<nv>(2 * nv));
  }

  /// y = aba(q, v, tau) and J^a = d y / d x from aba_derivatives, in one pass.
  template <class T, class W>
  static void analytical(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y,
                         Eigen::Matrix<T, nout, nin>& J) {
    auto& d = ws.template data<T>();
    auto& dd = ws.template derivatives<T>();
    aba_derivatives<R>(d, dd, x.template segment<nv>(0), x.template segment<nv>(nv),
                       x.template segment<nv>(2 * nv));
    y = d.ddq;
    J.template leftCols<nv>() = dd.ddq_dq;
    J.template middleCols<nv>(nv) = dd.ddq_dv;
    J.template rightCols<nv>() = d.Minv;
  }
};

/// Inverse dynamics x = (q, v, a) -> tau of robot R.
template <Robot R>
struct InverseDynamics {
  using Robot = R;
  static constexpr int nv = R::nv;                     ///< DoF
  static constexpr int nin = 3 * nv;                   ///< inputs (q, v, a)
  static constexpr int nout = nv;                      ///< outputs (tau)
  static constexpr bool needs_derivative_data = true;  ///< J^a uses rnea_derivatives

  /// y = rnea(q, v, a).
  template <class T, class W>
  static void value(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = ws.template data<T>();
    y = rnea<R>(d, x.template segment<nv>(0), x.template segment<nv>(nv),
                x.template segment<nv>(2 * nv));
  }

  /// y = rnea(q, v, a) and J^a = d y / d x from rnea_derivatives, in one pass.
  template <class T, class W>
  static void analytical(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y,
                         Eigen::Matrix<T, nout, nin>& J) {
    auto& d = ws.template data<T>();
    auto& dd = ws.template derivatives<T>();
    rnea_derivatives<R>(d, dd, x.template segment<nv>(0), x.template segment<nv>(nv),
                        x.template segment<nv>(2 * nv));
    y = d.tau;
    J.template leftCols<nv>() = dd.dtau_dq;
    J.template middleCols<nv>(nv) = dd.dtau_dv;
    J.template rightCols<nv>() = d.M;
  }
};

/// World position of operational frame F of robot R (pass R::frame_id::<link>): x = q -> p (3).
template <Robot R, int F>
struct FramePosition {
  static_assert(F >= 0 && F < R::nf, "operational frame index out of range");
  using Robot = R;
  static constexpr int nin = R::nv;                     ///< inputs (q)
  static constexpr int nout = 3;                        ///< outputs (position)
  static constexpr bool needs_derivative_data = false;  ///< J^a needs Data only

  /// y = position of frame F at q.
  template <class T, class W>
  static void value(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = ws.template data<T>();
    forward_kinematics<R>(d, x);
    y = frame_placement<R>(d, F).p;
  }

  /// y and J^a = d y / d q from compute_frame_position_derivative, in one pass; or from
  /// ws.pose_cache (frame_functions.hpp) when ws has one at scalar T that holds this frame at
  /// bitwise the same q (the last analytical FramePose).
  template <class T, class W>
  static void analytical(W& ws, const VecN<T, nin>& x, VecN<T, nout>& y,
                         Eigen::Matrix<T, nout, nin>& J) {
    if constexpr (requires { ws.pose_cache; })
      if constexpr (std::is_same_v<T, typename decltype(ws.pose_cache)::Scalar>)
        if (ws.pose_cache.lookup(F, x, y, J))
          return;
    auto& d = ws.template data<T>();
    compute_frame_position_derivative<R>(d, x, F, J);
    y = d.oMf[F].p;
  }
};

}  // namespace arbor::ad
