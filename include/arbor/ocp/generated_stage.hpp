// arbor::ocp: Gauss-Newton stage linearisations from generated code. The build (CMake
// arbor_add_stage_ad, gen/ad/ArborAddStageAd.cmake) traces linearize_path and linearize_terminal
// of a problem definition once at gen/ad's symbolic scalar and writes every QP block of a path
// stage (A, B, b, Q, S, R, q, r, C, D, lg, ug) and of the terminal stage (Q, q, C, lg, ug) as one
// straight-line function each, generic over the scalar: GeneratedStage<Def>. The expression
// layer stays the reference it is tested against (tests/ocp/generated_stage_test.cpp); the
// values agree to round-off wherever both are finite.
//
//   struct MyStage {                                   // the problem definition
//     template <class T> using Workspace = ...;        // RBD workspaces at scalar T
//     template <class W> static auto problem(W& ws);   // the problem on them
//   };
//   // CMake: arbor_add_stage_ad(my_stage HEADER my_stage_ad.hpp INCLUDE my_stage.hpp
//   //                           DEFINITIONS MyStage)  -> GeneratedStage<MyStage>
//   static MyStage::Workspace<double> ws;
//   const auto problem = ocp::with_generated_stage<MyStage>(MyStage::problem(ws));
//   static nmpc::Nmpc<std::remove_const_t<decltype(problem)>> ctrl(problem);  // generated SCQP
//
// WithGeneratedStage<P, Def> is P (its expressions still serve the merit function, the shift,
// the exact Hessian and every other evaluation); only Gauss-Newton linearisations change. What
// the trace compiles in: every constant of the definition (weights, references, radii, bounds of
// constraint rows): values that change at run time must be stage parameters (p). The problem's
// type must be the definition's at the controller's scalar (a static_assert checks it), so a
// differently built problem (another RK4 sensitivity, another provider) does not compile.
// Branches: linearize_path skips zero entries and a constraint's Gauss-Newton term at a
// multiplier <= 0 (known_zero, positive_part in core/math.hpp); the generated code keeps only
// the structural zeros and computes max(mu, 0) instead: the same values, without the skip.
// Values: the same as the expression layer's to round-off wherever both are finite; the trace
// folds x - x, 0 * x and x / x, so where the expression layer meets a NaN or an infinity the
// generated code may give a finite value (the controller's non-finite check can then differ).
// Cost: the generated operations (GeneratedStage<Def>::path_ops, terminal_ops); stack: the
// chunks' shared values (gen/ad's emit_function), no heap, no statics. The blocks are written
// through data(): the QP's stage types (qp/problem.hpp: fixed-size, column-major Eigen).
// Batched path stages (linearize_paths, path_lanes): on a SIMD target the controller runs the
// generated path code at Pack<T, L> (core/pack.hpp), L = pack_lanes<T> stages of the horizon at
// once (4 doubles with AVX, 2 with SSE2 or NEON), the rest one by one; the same values to
// round-off (the compiler may contract a * b + c differently in vector code). Cost per group: one
// path's operations in L-lane arithmetic (sin, cos and sqrt lane by lane) plus copying the
// inputs into lanes and the blocks out; stack: the generated code's shared values and the
// blocks, L lanes each (~80 KB for the contour OCP-FD at 4 doubles). Targets without SIMD
// (Cortex-M) compile none of it.
#pragma once

#include <type_traits>
#include <utility>

#include "arbor/core/math.hpp"
#include "arbor/core/pack.hpp"
#include "arbor/ocp/linearize.hpp"

namespace arbor::ocp {

/// Generated stage code of problem definition Def (specialised in the header arbor_add_stage_ad
/// writes): static path(...) and terminal(...), their operation counts, and
/// Problem<T>, the type of Def's problem at scalar T. available = false: none.
template <class Def>
struct GeneratedStage {
  static constexpr bool available = false;
};

/// The type of problem definition Def's problem at scalar T.
template <class Def, class T>
using DefinedProblem = std::remove_cvref_t<decltype(Def::problem(
    std::declval<typename Def::template Workspace<T>&>()))>;

/// Problem P (Def's problem at some scalar) whose Gauss-Newton stage linearisations come from
/// GeneratedStage<Def>; everything else is P's.
template <class P, class Def>
struct WithGeneratedStage : P {
  using Definition = Def;  ///< the problem definition the code was generated from
  using Base = P;          ///< the problem of the expression layer
  /// Use the generated code (default). Set it to false before a controller copies the problem
  /// when something the generated code cannot see applies: other constants than the
  /// definition's, a payload declared on the RBD workspace at run time (ad::set_payload); the
  /// stages then come from the expression layer (one branch per stage).
  bool generated = true;
  /// Where path_lanes > 1: the controller linearises the path stages that many at a time
  /// (linearize_paths, default). false: one by one (the scalar generated code's values bitwise).
  bool batched = true;
  explicit WithGeneratedStage(const P& p, bool use_generated = true)
      : P(p), generated(use_generated) {}
  /// The problem of the expression layer (the reference).
  const P& expressions() const { return *this; }
};

/// P with Def's generated stage code (see the top of this file).
template <class Def, class P>
WithGeneratedStage<P, Def> with_generated_stage(const P& problem) {
  static_assert(GeneratedStage<Def>::available,
                "no generated stage code for this definition: generate it (CMake "
                "arbor_add_stage_ad) and include its header before this call");
  return WithGeneratedStage<P, Def>(problem);
}

namespace detail {
template <class P, class Def, class T>
constexpr void check_generated_problem() {
  static_assert(std::is_same_v<P, DefinedProblem<Def, T>>,
                "the problem is not the one its definition builds at the controller's scalar "
                "(another expression, sensitivity or provider than the generated code's)");
  using G = GeneratedStage<Def>;  // (a stale header, e.g. a host build's read by a cross build)
  static_assert(G::nx == P::nx && G::nw == P::nu + P::ns && G::np == P::np &&
                    G::ng == qp_rows(P::ng) && G::ngn == qp_rows(P::ngn),
                "the generated stage code's sizes are not the problem's: regenerate its header");
}
}  // namespace detail

/// linearize_path for a problem with generated stages: Gauss-Newton from GeneratedStage<Def>,
/// the exact Hessian from the expression layer.
template <HessianKind H, class P, class Def, class T, class Stage>
void linearize_path(const WithGeneratedStage<P, Def>& prob, const VecN<T, P::nx>& x,
                    const VecN<T, P::nu + P::ns>& w, const VecN<T, P::np>& p,
                    const VecN<T, P::nx>& x_next, const VecN<T, P::nx>& lam_dyn,
                    const VecN<T, qp_rows(P::ng)>& lam_g, Stage& st) {
  if constexpr (H == HessianKind::gauss_newton) {
    detail::check_generated_problem<P, Def, T>();
    if (!prob.generated)
      return linearize_path<H>(prob.expressions(), x, w, p, x_next, lam_dyn, lam_g, st);
    GeneratedStage<Def>::template path<T>(
        x.data(), w.data(), p.data(), x_next.data(), lam_dyn.data(), lam_g.data(), st.A.data(),
        st.B.data(), st.b.data(), st.Q.data(), st.S.data(), st.R.data(), st.q.data(), st.r.data(),
        st.C.data(), st.D.data(), st.lg.data(), st.ug.data());
  } else {
    linearize_path<H>(prob.expressions(), x, w, p, x_next, lam_dyn, lam_g, st);
  }
}

/// Lanes of the batched Gauss-Newton path linearisation (linearize_paths) of problem P at scalar
/// T: pack_lanes<T> for a problem with generated stages on a SIMD target, else 0 (none: every
/// stage through linearize_path).
template <class P, class T>
inline constexpr int path_lanes = 0;
template <class P, class Def, class T>
inline constexpr int path_lanes<WithGeneratedStage<P, Def>, T> =
    pack_lanes<T> > 1 ? pack_lanes<T> : 0;

/// The inputs of one path stage for linearize_paths: linearize_path's vectors as pointers to
/// their first entries (x, w, p, x_next, lam_dyn, lam_g).
template <class T>
struct PathPoint {
  const T* x;
  const T* w;
  const T* p;
  const T* x_next;
  const T* lam_dyn;
  const T* lam_g;
};

/// The Gauss-Newton linearize_path at L points at once: GeneratedStage<Def>::path at Pack<T, L>,
/// lane l at point pt[l], its blocks written to *st[l] (see the top of this file). Returns false,
/// writing nothing, when prob.generated or prob.batched is off.
template <int L, class P, class Def, class T, class Stage>
bool linearize_paths(const WithGeneratedStage<P, Def>& prob, const PathPoint<T> (&pt)[L],
                     Stage* const (&st)[L]) {
  detail::check_generated_problem<P, Def, T>();
  if (!prob.generated || !prob.batched)
    return false;
  using V = Pack<T, L>;
  constexpr int nx = P::nx, nw = P::nu + P::ns, np = P::np, ng = qp_rows(P::ng);
  auto gather = [&](V* dst, int n, const T* PathPoint<T>::*src) {
    for (int i = 0; i < n; ++i)
      for (int l = 0; l < L; ++l)
        dst[i].set(l, (pt[l].*src)[i]);
  };
  V x[nx], w[nw], xn[nx], ld[nx], p[np > 0 ? np : 1], lg[ng > 0 ? ng : 1];
  gather(x, nx, &PathPoint<T>::x);
  gather(w, nw, &PathPoint<T>::w);
  gather(p, np, &PathPoint<T>::p);
  gather(xn, nx, &PathPoint<T>::x_next);
  gather(ld, nx, &PathPoint<T>::lam_dyn);
  gather(lg, ng, &PathPoint<T>::lam_g);
  // the blocks in lanes, sized by the stage's own (fixed-size) members
  constexpr auto n = []<class M>(M Stage::*) {
    return M::SizeAtCompileTime > 0 ? int(M::SizeAtCompileTime) : 1;
  };
  V A[n(&Stage::A)], B[n(&Stage::B)], b[n(&Stage::b)], Q[n(&Stage::Q)], S[n(&Stage::S)],
      R[n(&Stage::R)], q[n(&Stage::q)], r[n(&Stage::r)], C[n(&Stage::C)], D[n(&Stage::D)],
      lgo[n(&Stage::lg)], ugo[n(&Stage::ug)];
  GeneratedStage<Def>::template path<V>(x, w, p, xn, ld, lg, A, B, b, Q, S, R, q, r, C, D, lgo,
                                        ugo);
  auto scatter = [&](const V* src, auto Stage::*m) {
    for (int l = 0; l < L; ++l) {
      auto& block = (*st[l]).*m;
      T* d = block.data();
      for (int i = 0; i < int(block.size()); ++i)
        d[i] = src[i][l];
    }
  };
  scatter(A, &Stage::A);
  scatter(B, &Stage::B);
  scatter(b, &Stage::b);
  scatter(Q, &Stage::Q);
  scatter(S, &Stage::S);
  scatter(R, &Stage::R);
  scatter(q, &Stage::q);
  scatter(r, &Stage::r);
  scatter(C, &Stage::C);
  scatter(D, &Stage::D);
  scatter(lgo, &Stage::lg);
  scatter(ugo, &Stage::ug);
  return true;
}

/// linearize_terminal for a problem with generated stages (see linearize_path above).
template <HessianKind H, class P, class Def, class T, class Terminal>
void linearize_terminal(const WithGeneratedStage<P, Def>& prob, const VecN<T, P::nx>& x,
                        const VecN<T, P::np>& p, const VecN<T, qp_rows(P::ngn)>& lam_g,
                        Terminal& t) {
  if constexpr (H == HessianKind::gauss_newton) {
    detail::check_generated_problem<P, Def, T>();
    if (!prob.generated)
      return linearize_terminal<H>(prob.expressions(), x, p, lam_g, t);
    GeneratedStage<Def>::template terminal<T>(x.data(), p.data(), lam_g.data(), t.Q.data(),
                                              t.q.data(), t.C.data(), t.lg.data(), t.ug.data());
  } else {
    linearize_terminal<H>(prob.expressions(), x, p, lam_g, t);
  }
}

}  // namespace arbor::ocp
