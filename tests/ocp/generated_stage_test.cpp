// Generated stage code (arbor/ocp/generated_stage.hpp, gen/ad/adgen_stage.hpp) against its
// reference, the expression layer (ocp::linearize_path / linearize_terminal, dual numbers through
// the same problem): every QP block of path and terminal stages at random points, with
// multipliers of both signs and zero (the Gauss-Newton term of a convex row is linearize_path's
// branch, the generated code's max(mu, 0)), on three definitions (stage_definitions.hpp: the
// contour OCP-FD and OCP-ID on the Kinova, a soft-tunnel task on a random 3-joint robot); the
// generated code at float against the expression layer at double; and the controller: an RTI
// loop of Nmpc on the generated stages against the same loop on the expression layer.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <type_traits>

#include "arbor/nmpc/controller.hpp"
#include "arbor_test.hpp"
#include "stage_definitions_ad.hpp"

namespace {

using namespace arbor;
using ocp::HessianKind;

/// max |a - b| / (1 + max |b|) over the finite entries of b; an infinite entry of b must be
/// matched exactly (the row bounds' infinities); NaN anywhere: infinity.
template <class A, class B>
double rel_diff(const A& a, const B& b) {
  double d = 0, s = 0;
  for (int j = 0; j < int(b.cols()); ++j)
    for (int i = 0; i < int(b.rows()); ++i) {
      const double x = double(a(i, j)), y = double(b(i, j));
      if (std::isnan(x) || std::isnan(y))
        return INFINITY;
      if (std::isinf(y)) {
        if (x != y)
          return INFINITY;
        continue;
      }
      d = std::max(d, std::abs(x - y));
      s = std::max(s, std::abs(y));
    }
  return d / (1 + s);
}

/// The largest rel_diff over the twelve blocks of two path stages.
template <class St>
double stage_diff(const St& a, const St& r) {
  return std::max({rel_diff(a.A, r.A), rel_diff(a.B, r.B), rel_diff(a.b, r.b), rel_diff(a.Q, r.Q),
                   rel_diff(a.S, r.S), rel_diff(a.R, r.R), rel_diff(a.q, r.q), rel_diff(a.r, r.r),
                   rel_diff(a.C, r.C), rel_diff(a.D, r.D), rel_diff(a.lg, r.lg),
                   rel_diff(a.ug, r.ug)});
}

/// Every block of two path stages (or terminal stages) bitwise equal.
template <class St>
bool same_blocks(const St& a, const St& b) {
  if constexpr (requires { a.A; })
    return a.A == b.A && a.B == b.B && a.b == b.b && a.Q == b.Q && a.S == b.S && a.R == b.R &&
           a.q == b.q && a.r == b.r && a.C == b.C && a.D == b.D && a.lg == b.lg && a.ug == b.ug;
  else
    return a.Q == b.Q && a.q == b.q && a.C == b.C && a.lg == b.lg && a.ug == b.ug;
}

/// A random point of definition Def's stage: states, inputs, slacks, parameters, successor,
/// multipliers uniform in [-0.6, 0.6] (inputs x 3); row multipliers -0.3, 0 or in (0, 1].
template <class P>
struct Point {
  static constexpr int nx = P::nx, nw = P::nu + P::ns, np = P::np;
  static constexpr int ng = ocp::qp_rows(P::ng), ngn = ocp::qp_rows(P::ngn);
  VecN<double, nx> x, xn, lam;
  VecN<double, nw> w;
  VecN<double, np> p;
  VecN<double, ng> lg;
  VecN<double, ngn> lgn;
  explicit Point(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-0.6, 0.6), pos(0.0, 1.0);
    for (int i = 0; i < nx; ++i) {
      x[i] = u(rng);
      xn[i] = u(rng);
      lam[i] = u(rng);
    }
    for (int i = 0; i < nw; ++i)
      w[i] = 3 * u(rng);
    for (int i = 0; i < np; ++i)
      p[i] = u(rng);
    auto mult = [&] {
      const int c = int(rng() % 3);
      return c == 0 ? -0.3 : (c == 1 ? 0.0 : pos(rng) + 1e-3);
    };
    for (int i = 0; i < ng; ++i)
      lg[i] = mult();
    for (int i = 0; i < ngn; ++i)
      lgn[i] = mult();
  }
};

/// Path and terminal blocks of generated code and expression layer at `points` random points:
/// at double (the same problem, through with_generated_stage) within tol, and the generated code
/// at float against the expression layer at double within ftol.
template <class Def>
void check_definition(const char* name, int points, unsigned seed, double tol, double ftol) {
  static typename Def::template Workspace<double> ws;  // (large: static storage)
  const auto prob = Def::problem(ws);
  using P = std::remove_cvref_t<decltype(prob)>;
  using G = ocp::GeneratedStage<Def>;
  const auto gen = ocp::with_generated_stage<Def>(prob);
  using Qp = ocp::QpOf<P, double>;
  using Qf = ocp::QpOf<P, float>;
  static_assert(G::nx == P::nx && G::nw == P::nu + P::ns && G::np == P::np && G::ng == Qp::ng &&
                G::ngn == Qp::ngn);
  std::printf(
      "%s: nx %d, nw %d, np %d, ng %d, ngn %d; generated operations: path %ld, terminal "
      "%ld\n",
      name, G::nx, G::nw, G::np, G::ng, G::ngn, G::path_ops, G::terminal_ops);
  std::mt19937 rng(seed);
  double worst = 0, worst_f = 0;
  for (int k = 0; k < points; ++k) {
    const Point<P> pt(rng);
    typename Qp::Stage r, g;
    ocp::linearize_path<HessianKind::gauss_newton>(prob, pt.x, pt.w, pt.p, pt.xn, pt.lam, pt.lg, r);
    ocp::linearize_path<HessianKind::gauss_newton>(gen, pt.x, pt.w, pt.p, pt.xn, pt.lam, pt.lg, g);
    const double d[] = {rel_diff(g.A, r.A), rel_diff(g.B, r.B),   rel_diff(g.b, r.b),
                        rel_diff(g.Q, r.Q), rel_diff(g.S, r.S),   rel_diff(g.R, r.R),
                        rel_diff(g.q, r.q), rel_diff(g.r, r.r),   rel_diff(g.C, r.C),
                        rel_diff(g.D, r.D), rel_diff(g.lg, r.lg), rel_diff(g.ug, r.ug)};
    const char* names[] = {"A", "B", "b", "Q", "S", "R", "q", "r", "C", "D", "lg", "ug"};
    for (int i = 0; i < 12; ++i) {
      EXPECT_LE(d[i], tol) << name << " path block " << names[i] << ", point " << k;
      worst = std::max(worst, d[i]);
    }
    if (k == 0) {
      // the overload ran the generated code: its blocks are G::path's, bitwise
      typename Qp::Stage d;
      G::template path<double>(pt.x.data(), pt.w.data(), pt.p.data(), pt.xn.data(), pt.lam.data(),
                               pt.lg.data(), d.A.data(), d.B.data(), d.b.data(), d.Q.data(),
                               d.S.data(), d.R.data(), d.q.data(), d.r.data(), d.C.data(),
                               d.D.data(), d.lg.data(), d.ug.data());
      EXPECT_TRUE(same_blocks(g, d)) << name;
      // switched off: the expression layer's blocks, bitwise
      const ocp::WithGeneratedStage<P, Def> off(prob, false);
      typename Qp::Stage o;
      ocp::linearize_path<HessianKind::gauss_newton>(off, pt.x, pt.w, pt.p, pt.xn, pt.lam, pt.lg,
                                                     o);
      EXPECT_TRUE(same_blocks(o, r)) << name;
      typename Qp::Terminal to, tr, td, tg;
      ocp::linearize_terminal<HessianKind::gauss_newton>(off, pt.x, pt.p, pt.lgn, to);
      ocp::linearize_terminal<HessianKind::gauss_newton>(prob, pt.x, pt.p, pt.lgn, tr);
      ocp::linearize_terminal<HessianKind::gauss_newton>(gen, pt.x, pt.p, pt.lgn, tg);
      G::template terminal<double>(pt.x.data(), pt.p.data(), pt.lgn.data(), td.Q.data(),
                                   td.q.data(), td.C.data(), td.lg.data(), td.ug.data());
      EXPECT_TRUE(same_blocks(to, tr)) << name;
      EXPECT_TRUE(same_blocks(tg, td)) << name;
    }
    typename Qp::Terminal rt, gt;
    ocp::linearize_terminal<HessianKind::gauss_newton>(prob, pt.x, pt.p, pt.lgn, rt);
    ocp::linearize_terminal<HessianKind::gauss_newton>(gen, pt.x, pt.p, pt.lgn, gt);
    const double dt[] = {rel_diff(gt.Q, rt.Q), rel_diff(gt.q, rt.q), rel_diff(gt.C, rt.C),
                         rel_diff(gt.lg, rt.lg), rel_diff(gt.ug, rt.ug)};
    for (double v : dt) {
      EXPECT_LE(v, tol) << name << " terminal, point " << k;
      worst = std::max(worst, v);
    }
    // the generated code at float against the expression layer at double
    typename Qf::Stage f;
    const VecN<float, Point<P>::nx> x = pt.x.template cast<float>(),
                                    xn = pt.xn.template cast<float>(),
                                    lam = pt.lam.template cast<float>();
    const VecN<float, Point<P>::nw> w = pt.w.template cast<float>();
    const VecN<float, Point<P>::np> p = pt.p.template cast<float>();
    const VecN<float, Point<P>::ng> lg = pt.lg.template cast<float>();
    G::template path<float>(x.data(), w.data(), p.data(), xn.data(), lam.data(), lg.data(),
                            f.A.data(), f.B.data(), f.b.data(), f.Q.data(), f.S.data(), f.R.data(),
                            f.q.data(), f.r.data(), f.C.data(), f.D.data(), f.lg.data(),
                            f.ug.data());
    const double df[] = {rel_diff(f.A, r.A), rel_diff(f.B, r.B),   rel_diff(f.b, r.b),
                         rel_diff(f.Q, r.Q), rel_diff(f.S, r.S),   rel_diff(f.R, r.R),
                         rel_diff(f.q, r.q), rel_diff(f.r, r.r),   rel_diff(f.C, r.C),
                         rel_diff(f.D, r.D), rel_diff(f.lg, r.lg), rel_diff(f.ug, r.ug)};
    for (int i = 0; i < 12; ++i) {
      EXPECT_LE(df[i], ftol) << name << " float path block " << names[i] << ", point " << k;
      worst_f = std::max(worst_f, df[i]);
    }
    typename Qf::Terminal ft;
    const VecN<float, Point<P>::ngn> lgn = pt.lgn.template cast<float>();
    G::template terminal<float>(x.data(), p.data(), lgn.data(), ft.Q.data(), ft.q.data(),
                                ft.C.data(), ft.lg.data(), ft.ug.data());
    const double dft[] = {rel_diff(ft.Q, rt.Q), rel_diff(ft.q, rt.q), rel_diff(ft.C, rt.C),
                          rel_diff(ft.lg, rt.lg), rel_diff(ft.ug, rt.ug)};
    for (double v : dft) {
      EXPECT_LE(v, ftol) << name << " float terminal, point " << k;
      worst_f = std::max(worst_f, v);
    }
  }
  std::printf("%s: %d points, largest relative difference %.2e (double), %.2e (float code)\n", name,
              points, worst, worst_f);
}

TEST(GeneratedStage, ContourFdEqualsTheExpressionLayer) {
  check_definition<contour::FdStage>("contour OCP-FD", 40, 1, 1e-11, 2e-4);
}

TEST(GeneratedStage, ContourIdEqualsTheExpressionLayer) {
  check_definition<contour::IdStage>("contour OCP-ID", 40, 2, 1e-11, 2e-4);
}

TEST(GeneratedStage, RandomRobotSoftTaskEqualsTheExpressionLayer) {
  check_definition<ocp_test::RandomSoftStage>("random 3-joint robot, soft tunnel", 100, 3, 1e-11,
                                              2e-4);
}

/// ocp::linearize_paths (the generated path code at Pack<T, L>, L stages at once) against L calls
/// of the scalar generated code through linearize_path: every block of every lane within tol
/// (bitwise unless the compiler contracts a * b + c differently in vector code), each lane at
/// its own random point, in `groups` groups; switched off (batched = false) it returns false
/// and writes nothing.
template <class Def, class T, int L>
void check_batched(const char* name, int groups, unsigned seed, double tol) {
  static typename Def::template Workspace<T> ws;  // (large: static storage)
  const auto prob = Def::problem(ws);
  using P = std::remove_cvref_t<decltype(prob)>;
  using Qp = ocp::QpOf<P, T>;
  auto gen = ocp::with_generated_stage<Def>(prob);
  constexpr int nx = P::nx, nw = P::nu + P::ns, np = P::np, ng = ocp::qp_rows(P::ng);
  std::mt19937 rng(seed);
  double worst = 0;
  for (int g = 0; g < groups; ++g) {
    struct Lane {
      VecN<T, nx> x, xn, lam;
      VecN<T, nw> w;
      VecN<T, np> p;
      VecN<T, ng> lg;
    } in[L];
    ocp::PathPoint<T> pt[L];
    typename Qp::Stage ref[L], bat[L];
    typename Qp::Stage* st[L];
    for (int l = 0; l < L; ++l) {
      const Point<P> pd(rng);
      in[l] = {pd.x.template cast<T>(), pd.xn.template cast<T>(), pd.lam.template cast<T>(),
               pd.w.template cast<T>(), pd.p.template cast<T>(),  pd.lg.template cast<T>()};
      pt[l] = {in[l].x.data(),  in[l].w.data(),   in[l].p.data(),
               in[l].xn.data(), in[l].lam.data(), in[l].lg.data()};
      st[l] = &bat[l];
      ocp::linearize_path<HessianKind::gauss_newton>(gen, in[l].x, in[l].w, in[l].p, in[l].xn,
                                                     in[l].lam, in[l].lg, ref[l]);
    }
    ASSERT_TRUE(ocp::linearize_paths<L>(gen, pt, st)) << name;
    for (int l = 0; l < L; ++l) {
      const double d = stage_diff(bat[l], ref[l]);
      EXPECT_LE(d, tol) << name << ", group " << g << ", lane " << l << " of " << L;
      worst = std::max(worst, d);
    }
  }
  // switched off (batched = false, or generated = false): false, nothing written
  ocp::PathPoint<T> pt[L];
  typename Qp::Stage off[L], sentinel;
  typename Qp::Stage* st[L];
  const VecN<T, nx> x = VecN<T, nx>::Zero();
  const VecN<T, nw> w = VecN<T, nw>::Zero();
  const VecN<T, np> p = VecN<T, np>::Zero();
  const VecN<T, ng> lg = VecN<T, ng>::Zero();
  auto fill = [](auto&... m) { (m.setConstant(T(7)), ...); };
  fill(sentinel.A, sentinel.B, sentinel.b, sentinel.Q, sentinel.S, sentinel.R, sentinel.q,
       sentinel.r, sentinel.C, sentinel.D, sentinel.lg, sentinel.ug);
  for (int flag = 0; flag < 2; ++flag) {
    gen.batched = flag != 0;
    gen.generated = flag == 0;
    for (int l = 0; l < L; ++l) {
      pt[l] = {x.data(), w.data(), p.data(), x.data(), x.data(), lg.data()};
      off[l] = sentinel;
      st[l] = &off[l];
    }
    EXPECT_FALSE(ocp::linearize_paths<L>(gen, pt, st)) << name << ", flag " << flag;
    for (int l = 0; l < L; ++l)
      EXPECT_TRUE(same_blocks(off[l], sentinel)) << name << ", flag " << flag;
  }
  std::printf(
      "%s, %d lanes of %s: %d groups, largest relative difference to the scalar code %.2e\n", name,
      L, sizeof(T) == 8 ? "double" : "float", groups, worst);
}

TEST(GeneratedStage, BatchedPathsEqualTheScalarCode) {
  check_batched<contour::FdStage, double, 4>("contour OCP-FD", 5, 11, 1e-12);
  check_batched<contour::FdStage, float, 8>("contour OCP-FD", 3, 12, 1e-4);
  check_batched<contour::IdStage, double, 2>("contour OCP-ID", 10, 13, 1e-12);
  check_batched<ocp_test::RandomSoftStage, double, 4>("random 3-joint robot", 10, 14, 1e-12);
}

// The controller on generated stages: the same real-time-iteration loop (random 3-joint robot,
// soft tunnel) with the expression layer and with the generated code, the plant the controller's
// own model with a perturbation: the same statuses, QP iteration counts and controls to
// round-off over 30 samples. On a SIMD host the generated controller linearises its N = 7 path
// stages ocp::path_lanes at a time and the rest one by one (2 lanes: 3 groups and 1; 4 lanes: 1
// and 3); a third controller of the same type with batched = false runs every stage one by one:
// the same statuses and iterations, its QP blocks the batched one's to round-off.
TEST(GeneratedStage, RtiLoopMatchesTheExpressionLayer) {
  using Def = ocp_test::RandomSoftStage;
  using Task = ocp_test::Task3;
  static Def::Workspace<double> ws;
  const auto prob = Def::problem(ws);
  const auto gprob = ocp::with_generated_stage<Def>(prob);
  using Ce = nmpc::Nmpc<std::remove_cvref_t<decltype(prob)>>;
  using Cg = nmpc::Nmpc<std::remove_cvref_t<decltype(gprob)>>;
  static Ce ce(prob);
  static Cg cg(gprob);
  auto sprob = gprob;
  sprob.batched = false;
  static Cg cs(sprob);
  constexpr int lanes = ocp::path_lanes<std::remove_cvref_t<decltype(gprob)>, double>;
  static_assert(lanes == (arbor::simd_bytes > 0 ? arbor::simd_bytes / 8 : 0));
  constexpr int nv = Task::nv;
  VecN<double, Task::nx> x0 = VecN<double, Task::nx>::Zero();
  const VecN<double, nv> qs = Task::q_start();
  for (int i = 0; i < nv; ++i)  // (not a comma initializer: GCC 12's -Warray-bounds misreads
    x0[i] = qs[i];              // its AVX load of the 3-vector at -O3 -march=native)
  const VecN<double, nv> u0 = VecN<double, nv>::Zero();
  ASSERT_EQ(ce.set_initial_guess(x0, u0), nmpc::NmpcStatus::accepted);
  ASSERT_EQ(cg.set_initial_guess(x0, u0), nmpc::NmpcStatus::accepted);
  ASSERT_EQ(cs.set_initial_guess(x0, u0), nmpc::NmpcStatus::accepted);
  const auto se = ce.solve(x0), sg = cg.solve(x0);
  EXPECT_EQ(se, sg);
  EXPECT_EQ(cs.solve(x0), sg);
  EXPECT_LE((ce.control() - cg.control()).cwiseAbs().maxCoeff(),
            1e-9 * (1 + ce.control().cwiseAbs().maxCoeff()));
  VecN<double, Task::nx> x = x0;
  double worst = 0, worst_qp = 0, worst_batch = 0, max_mu = 0;
  int stages_with_mu = 0;  // stage-samples whose tunnel multiplier is positive
  for (int k = 0; k < 30; ++k) {
    const VecN<double, nv> u = ce.control();
    x = ad::evaluate(prob.dynamics, x, u, VecN<double, 1>::Zero().eval());
    x[0] += 1e-3 * std::sin(0.7 * k);  // a perturbation the model does not predict
    if (k % 10 == 5)     // a kick of joint 1's velocity: the tunnel active on stages 0 to 4 for a
      x[nv + 1] -= 1.5;  // few samples, its multipliers (the Gauss-Newton term) stage by stage
    ce.shift();
    cg.shift();
    cs.shift();
    ASSERT_EQ(ce.prepare(), cg.prepare()) << k;
    ASSERT_EQ(cs.prepare(), cg.prepare()) << k;
    const auto fe = ce.feedback(x), fg = cg.feedback(x);
    ASSERT_EQ(fe, fg) << k;
    ASSERT_EQ(cs.feedback(x), fg) << k;
    EXPECT_EQ(ce.info().qp_iterations, cg.info().qp_iterations) << k;
    EXPECT_EQ(cs.info().qp_iterations, cg.info().qp_iterations) << k;
    const double d = (ce.control() - cg.control()).cwiseAbs().maxCoeff() /
                     (1 + ce.control().cwiseAbs().maxCoeff());
    EXPECT_LE(d, 1e-9) << k;
    worst = std::max(worst, d);
    for (int i = 0; i < Ce::N; ++i) {  // the controllers' QPs: the same to round-off
      const auto& a = ce.qp().stage[std::size_t(i)];
      const auto& b = cg.qp().stage[std::size_t(i)];
      const double db = stage_diff(b, a);
      EXPECT_LE(db, 1e-11) << k << " stage " << i;
      worst_qp = std::max(worst_qp, db);
      const auto& c = cs.qp().stage[std::size_t(i)];
      const double dc = stage_diff(b, c);
      EXPECT_LE(dc, 1e-12) << k << " stage " << i;
      worst_batch = std::max(worst_batch, dc);
      const double mu = cg.constraint_multiplier(i).maxCoeff();
      max_mu = std::max(max_mu, mu);
      stages_with_mu += mu > 0;
    }
  }
  // The generated controller ran the generated code: other arithmetic, so its QP blocks differ
  // from the expression layer's by round-off somewhere over the run (were they bitwise equal
  // everywhere, the expression layer would have run twice).
  EXPECT_GT(worst_qp, 0.0);
  // the tunnel was active on several stages (its multipliers enter the blocks: a stage that read
  // another stage's multiplier would differ)
  EXPECT_GT(stages_with_mu, 3);
  std::printf(
      "RTI loop, 30 samples: largest relative control difference %.2e, QP blocks %.2e; %d lanes: "
      "batched against one by one %.2e; tunnel multipliers positive on %d stage-samples (largest "
      "%.2e)\n",
      worst, worst_qp, lanes, worst_batch, stages_with_mu, max_mu);
}

}  // namespace
