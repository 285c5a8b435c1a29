// nmpc::Workspace (nmpc/workspace.hpp), the workspace deduced from the problem's dimensions, the
// provider, the controller's scalar and Hessian kind: at compile time, the Data and
// DerivativeData it holds for every provider (Analytical, AutoDiff, Generated) and Hessian kind
// (PathOnly, the pose cache); at run time, the exact-Hessian SQP on the 2-DoF arm (arm.hpp) with
// the deduced workspace against the same controller on the hand-assembled one (ArmWorkspace):
// the same plan after 8 iterations. One provider per executable (compile memory, as the IPOPT
// arm tests): ARM_WORKSPACE_AUTODIFF selects AutoDiff.
#include <gtest/gtest.h>

#include <arbor/nmpc/controller.hpp>
#include <arbor/nmpc/workspace.hpp>
#include <memory>
#include <tuple>

#include "arm.hpp"

namespace {
using namespace nmpc_test;
using arbor::ad::Dual;
using arbor::ocp::HessianKind;
using R = ArmData::Robot;

template <class T, class Tuple>
inline constexpr bool in_tuple = false;
template <class T, class... Ts>
inline constexpr bool in_tuple<T, std::tuple<Ts...>> = (std::is_same_v<T, Ts> || ...);
/// W holds a Data at each of Ds and a DerivativeData at each of Gs, and nothing else.
template <class W, class Ds, class Gs>
struct Holds;
template <class W, class... Ds, class... Gs>
struct Holds<W, arbor::ad::Scalars<Ds...>, arbor::ad::Scalars<Gs...>> {
  using DT = decltype(W::data_);
  using GT = decltype(W::deriv_);
  static constexpr bool value = std::tuple_size_v<DT> == sizeof...(Ds) &&
                                std::tuple_size_v<GT> == sizeof...(Gs) &&
                                (in_tuple<arbor::Data<R, Ds>, DT> && ...) &&
                                (in_tuple<arbor::DerivativeData<R, Gs>, GT> && ...);
};
template <class W, class Ds, class Gs = arbor::ad::Scalars<>>
inline constexpr bool holds = Holds<W, Ds, Gs>::value;
using arbor::ad::Scalars;
using D = ocp::Dims<4, 2, 1, 10>;  // the arm's: nx = 4, nu = 2
using Fd = ArmFd;                  // nin = 6
using Ee = ArmEe;                  // nin = 2
using Pose = arbor::ad::FramePose<R, ArmData::ee_frame>;
template <class Tag, HessianKind H, class... F>
using W = arbor::nmpc::Workspace<D, Tag, double, H, F...>;
constexpr auto gn = HessianKind::gauss_newton;
constexpr auto ex = HessianKind::exact;
using A = arbor::ad::Analytical;
using C = arbor::ad::AutoDiff;
using G = arbor::ad::Generated;
using D6 = Dual<double, 6>;
using D4 = Dual<double, 4>;
// SCQP: values and Jacobians at double
static_assert(holds<W<A, gn, Fd, Ee>, Scalars<double>, Scalars<double>>);
static_assert(holds<W<C, gn, Fd, Ee>, Scalars<double, Dual<double, 6>, Dual<double, 2>>>);
static_assert(holds<W<G, gn, Fd, Ee>, Scalars<double>>);
// exact: Jacobians at Dual<double, nx + nu> (path) and Dual<double, nx> (terminal)
static_assert(holds<W<A, ex, Fd, Ee>, Scalars<double, D6, D4>, Scalars<double, D6, D4>>);
static_assert(holds<W<A, ex, arbor::nmpc::PathOnly<Fd>, Ee>, Scalars<double, D6, D4>,
                    Scalars<double, D6>>);  // Ee needs no DerivativeData
static_assert(holds<W<A, ex, arbor::nmpc::PathOnly<Fd>, arbor::nmpc::PathOnly<Ee>>,
                    Scalars<double, D6>, Scalars<double, D6>>);
static_assert(
    holds<W<C, ex, arbor::nmpc::PathOnly<Fd>, Ee>, Scalars<double, Dual<double, 6>, Dual<double, 2>,
                                                           Dual<D6, 6>, Dual<D6, 2>, Dual<D4, 2>>>);
static_assert(holds<W<G, ex, Fd, Ee>, Scalars<double>>);
// Generated for a function without generated code: AutoDiff's, at every scalar
static_assert(
    holds<W<G, ex, arbor::nmpc::PathOnly<Pose>>, Scalars<double, Dual<double, 2>, Dual<D6, 2>>>);
// a FramePose brings the pose cache at the controller's scalar
static_assert(
    std::is_same_v<decltype(W<A, gn, Pose, Ee>::pose_cache), arbor::ad::PoseCache<R, double>>);
template <class X>
concept has_pose_cache = requires(X& w) {
  w.pose_cache;
};
static_assert(!has_pose_cache<W<A, gn, Fd, Ee>>);

#if defined(ARM_WORKSPACE_AUTODIFF)
using Tag = arbor::ad::AutoDiff;
#else
using Tag = arbor::ad::Analytical;
#endif
constexpr int N = 20, M = 2;

/// The plan (states and inputs) after `iters` exact-Hessian SQP iterations on workspace type Ws.
template <class Ws>
std::pair<arbor::nmpc::NmpcStatus, Eigen::VectorXd> plan_after(int iters) {
  const auto ws = std::make_unique<Ws>();
  const auto problem = arm_problem<N, M, Tag>(*ws);
  using Ctrl = arbor::nmpc::Nmpc<std::remove_cvref_t<decltype(problem)>, double, ex>;
  const auto ctrl = std::make_unique<Ctrl>(problem);
  ctrl->settings().max_iter = iters;
  const Eigen::Vector4d x0(M_PI, 0, 0, 0);
  EXPECT_EQ(ctrl->set_initial_guess(x0, Eigen::Vector2d::Zero()),
            arbor::nmpc::NmpcStatus::accepted);
  const auto st = ctrl->solve(x0);
  Eigen::VectorXd w((N + 1) * 4 + N * 2);
  for (int k = 0; k <= N; ++k)
    w.segment<4>(4 * k) = ctrl->state(k);
  for (int k = 0; k < N; ++k)
    w.segment<2>(4 * (N + 1) + 2 * k) = ctrl->input(k);
  return {st, w};
}

TEST(NmpcWorkspace, DeducedEqualsHandAssembledExactHessian) {
  using Deduced = arbor::nmpc::Workspace<ocp::Dims<4, 2, 1, N>, Tag, double, ex,
                                         arbor::nmpc::PathOnly<Fd>, arbor::nmpc::PathOnly<Ee>>;
  const auto [s1, w1] = plan_after<Deduced>(8);
  const auto [s2, w2] = plan_after<ArmWorkspace<Tag, true>>(8);
  EXPECT_EQ(s1, s2);
  EXPECT_TRUE(w1.allFinite());
  EXPECT_GT(w1.norm(), 1.0);                        // (the plan moved from the guess)
  EXPECT_EQ((w1 - w2).cwiseAbs().maxCoeff(), 0.0);  // the same arithmetic
  std::printf("deduced workspace %zu bytes, hand-assembled %zu bytes\n", sizeof(Deduced),
              sizeof(ArmWorkspace<Tag, true>));
}

}  // namespace
