// arbor-adgen's driver (host program): traces ForwardDynamics, InverseDynamics and every
// FramePosition of robot R with the symbolic scalar (adgen.hpp), differentiates, and writes the
// header of generated straight-line code (GeneratedCode specialisations, arbor/ad/generated.hpp).
// Instantiated per robot by adgen_robot.cpp.in (ArborAddRobotAd.cmake).
#pragma once

#include <arbor/dynamics/aba.hpp>
#include <arbor/dynamics/kinematics.hpp>
#include <arbor/dynamics/rnea.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "adgen.hpp"

namespace arbor::adgen {

/// Statistics of one generated function (reported in the header and on stdout).
struct Stats {
  long primal_ops = 0, forward_ops = 0, reverse_ops = 0, jacobian_ops = 0, hessian_ops = 0;
  long direct_ops = 0;  ///< FD: the traced function's own Jacobian (when an alternative was tried)
  const char* mode = "";
  const char* hessian_mode = "";
};

/// Input value k of the tracing point (the same for every traced function).
inline double trace_point(int k) {
  return 0.3 + 0.37 * k - 0.05 * (k % 5) * k;
}

/// The Jacobian of outs w.r.t. ins, forward or reverse, whichever has fewer live operations
/// together with the values `keep` (on a copy of g: the loser's nodes are dropped).
inline std::vector<int> best_jacobian(Graph& g, const std::vector<int>& outs,
                                      const std::vector<int>& ins, const std::vector<int>& keep,
                                      long& fwd_ops, long& rev_ops, const char*& mode) {
  Graph gf = g, gr = g;
  current = &gf;
  auto Jf = jacobian_forward(gf, outs, ins);
  current = &gr;
  auto Jr = jacobian_reverse(gr, outs, ins);
  auto with = [&](const std::vector<int>& J) {
    std::vector<int> all = keep;
    all.insert(all.end(), J.begin(), J.end());
    return all;
  };
  fwd_ops = count_ops(gf, with(Jf));
  rev_ops = count_ops(gr, with(Jr));
  if (fwd_ops <= rev_ops) {
    g = std::move(gf);
    mode = "forward";
    current = &g;
    return Jf;
  }
  g = std::move(gr);
  mode = "reverse";
  current = &g;
  return Jr;
}

/// Emits GeneratedCode<Function> with jacobian(x, y, J) (and, if hessian_code is given,
/// GeneratedHessian<Function> with hessian(x, lambda, y, H) into it) for a function traced by
/// `trace(xs, ys)` with nin inputs and nout outputs.
/// `alternative` (optional) emits another body of jacobian() into its argument and returns its
/// operations; it replaces the traced function's Jacobian when it needs fewer.
template <class Trace, class Alternative = std::nullptr_t>
std::string generate_function(const std::string& function, int nin, int nout,
                              std::string* hessian_code, Trace&& trace, Stats& st,
                              Alternative&& alternative = nullptr) {
  const bool hessian = hessian_code != nullptr;
  std::string code;
  std::string body;
  std::string hbody;
  // Records the function into a fresh graph g: ins are its input nodes, y its outputs.
  auto record = [&](Graph& g, std::vector<int>& ins, std::vector<Sym>& y) {
    current = &g;
    std::vector<Sym> x(nin);
    ins.assign(nin, 0);
    y.assign(nout, Sym());
    for (int k = 0; k < nin; ++k) {
      ins[k] = g.input(k, trace_point(k));
      x[k] = Sym::node(ins[k]);
    }
    trace(x, y);
  };
  // Jacobian.
  {
    Graph g;
    std::vector<int> ins;
    std::vector<Sym> y;
    record(g, ins, y);
    if (g.value_branch) {
      std::fprintf(stderr, "arbor-adgen: %s branches on a traced value\n", function.c_str());
      std::exit(1);
    }
    std::vector<int> outs(nout);
    for (int i = 0; i < nout; ++i)
      outs[i] = y[i].id();
    st.primal_ops = count_ops(g, outs);
    const auto J = best_jacobian(g, outs, ins, outs, st.forward_ops, st.reverse_ops, st.mode);
    st.jacobian_ops = emit_function(body, g, "jacobian", {{"x", nin}}, {{"y", outs}, {"J", J}});
    if constexpr (!std::is_same_v<std::remove_cvref_t<Alternative>, std::nullptr_t>) {
      std::string other;
      const long ops = alternative(other);
      st.direct_ops = st.jacobian_ops;
      if (ops > 0 && ops < st.jacobian_ops) {
        body = std::move(other);
        st.jacobian_ops = ops;
        st.mode = "implicit";
      }
    }
  }
  if (hessian) {
    Graph g;
    std::vector<int> ins;
    std::vector<Sym> y;
    record(g, ins, y);
    Sym s(0.0);
    for (int i = 0; i < nout; ++i)
      s += Sym::node(g.input(nin + i, 0.1 + 0.3 * i)) * y[i];
    std::vector<int> outs(nout);
    for (int i = 0; i < nout; ++i)
      outs[i] = y[i].id();
    const auto grad = jacobian_reverse(g, {s.id()}, ins);  // 1 x nin
    long f = 0, r = 0;
    const auto H = best_jacobian(g, grad, ins, outs, f, r, st.hessian_mode);
    // H is symmetric: the upper triangle from the lower (one set of nodes, either mode).
    std::vector<int> Hs(H);
    for (int c = 0; c < nin; ++c)
      for (int rr = 0; rr < c; ++rr)
        Hs[c * nin + rr] = H[rr * nin + c];
    st.hessian_ops = emit_function(hbody, g, "hessian", {{"x", nin}, {"lambda", nout}},
                                   {{"y", outs}, {"H", Hs}});
  }
  code += "template <>\nstruct GeneratedCode<" + function + "> {\n";
  code += "  static constexpr bool available = true;\n";
  code += "  /// Operations of the traced function (live) and of jacobian() (" +
          std::string(st.mode) + " mode; forward " + std::to_string(st.forward_ops) + ", reverse " +
          std::to_string(st.reverse_ops) +
          (st.direct_ops > 0 ? ", the traced function's best " + std::to_string(st.direct_ops)
                             : std::string()) +
          ").\n";
  code += "  static constexpr long primal_ops = " + std::to_string(st.primal_ops) + ";\n";
  code += "  static constexpr long jacobian_ops = " + std::to_string(st.jacobian_ops) + ";\n";
  code += body + "};\n\n";
  if (hessian) {
    *hessian_code += "template <>\nstruct GeneratedHessian<" + function + "> {\n";
    *hessian_code += "  static constexpr bool available = true;\n";
    *hessian_code += "  /// Operations of hessian() (the gradient by reverse mode, then " +
                     std::string(st.hessian_mode) + " mode).\n";
    *hessian_code +=
        "  static constexpr long hessian_ops = " + std::to_string(st.hessian_ops) + ";\n";
    *hessian_code += hbody + "};\n\n";
  }
  return code;
}

/// FD's Jacobian through ID (implicit function theorem, the analytical route's identity):
/// ddq = aba(q, v, tau) by its value code (`fd_value`), then J_ID = d rnea / d(q, v, a) at
/// (q, v, ddq) by the cheaper mode, and d ddq / d(q, v, tau) = M^-1 [-J_q, -J_v, I] with
/// M = J_a by a straight-line L' D L factorisation along the tree (Featherstone's LTDL: no fill-in,
/// no square roots) and its solves (`jacobian_at`). Emits both and jacobian(x, y, J) calling them;
/// returns their operations (0 if R has multi-DoF joints: not handled).
template <class R>
long fd_jacobian_through_id(std::string& body) {
  constexpr int n = R::nv;
  if constexpr (R::nb != R::nv) {
    return 0;
  } else {
    auto inputs = [](Graph& g, int count, int first) {
      std::vector<Sym> x(static_cast<std::size_t>(count));
      for (int k = 0; k < count; ++k)
        x[std::size_t(k)] = Sym::node(g.input(first + k, trace_point(first + k)));
      return x;
    };
    // the output ids of algorithm(q, v, u) traced with q, v = x[0, 2n) and u = x[u0, u0 + n)
    auto trace = [&](const std::vector<Sym>& x, int u0, auto algorithm) {
      VecN<Sym, n> q, v, u;
      for (int k = 0; k < n; ++k) {
        q[k] = x[std::size_t(k)];
        v[k] = x[std::size_t(n + k)];
        u[k] = x[std::size_t(u0 + k)];
      }
      auto d = std::make_unique<Data<R, Sym>>();
      const auto& y = algorithm(*d, q, v, u);
      std::vector<int> ids(n);
      for (int i = 0; i < n; ++i)
        ids[std::size_t(i)] = y[i].id();
      return ids;
    };
    // value
    Graph gv;
    current = &gv;
    const auto ddq = trace(
        inputs(gv, 3 * n, 0), 2 * n,
        [](auto& d, const auto& q, const auto& v, const auto& tau) -> const auto& {
          return aba<R>(d, q, v, tau);
        });
    if (gv.value_branch)
      return 0;
    long ops = emit_function(body, gv, "fd_value", {{"x", 3 * n}}, {{"y", ddq}});
    // J_ID at (q, v, a), a the inputs 3n..4n-1 (bound to ddq by jacobian())
    Graph g;
    current = &g;
    const auto x = inputs(g, 4 * n, 0);
    std::vector<int> ins;
    for (int k = 0; k < 4 * n; ++k)
      if (k < 2 * n || k >= 3 * n)
        ins.push_back(x[std::size_t(k)].id());
    const auto tau_ids = trace(
        x, 3 * n, [](auto& d, const auto& q, const auto& v, const auto& a) -> const auto& {
          return rnea<R>(d, q, v, a);
        });
    if (g.value_branch)
      return 0;
    long f = 0, r = 0;
    const char* mode = "";
    const auto J = best_jacobian(g, tau_ids, ins, {}, f, r, mode);  // n x 3n, column major
    auto Jid = [&](int row, int col) { return Sym::node(J[std::size_t(col * n + row)]); };
    // H = M, factorised in place: M = L' D L (L unit lower, nonzero only at (k, ancestor of k))
    std::vector<Sym> H(std::size_t(n * n));
    auto h = [&](int i, int j) -> Sym& { return H[std::size_t(i * n + j)]; };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        h(i, j) = Jid(i, 2 * n + j);
    for (int k = n - 1; k >= 0; --k) {
      const Sym inv = Sym(1.0) / h(k, k);
      for (int i = R::parent[k]; i >= 0; i = R::parent[i]) {
        const Sym a = h(k, i) * inv;
        for (int j = i; j >= 0; j = R::parent[j])
          h(i, j) -= a * h(k, j);
        h(k, i) = a;
      }
    }
    std::vector<Sym> invd(n);
    for (int k = 0; k < n; ++k)
      invd[std::size_t(k)] = Sym(1.0) / h(k, k);
    // columns of M^-1 [-J_q, -J_v, I]
    std::vector<int> out(std::size_t(3 * n * n));
    std::vector<Sym> b(n);
    for (int c = 0; c < 3 * n; ++c) {
      for (int i = 0; i < n; ++i)
        b[std::size_t(i)] = c < 2 * n ? -Jid(i, c) : Sym(c - 2 * n == i ? 1.0 : 0.0);
      for (int k = n - 1; k >= 0; --k)  // L' y = b
        for (int i = R::parent[k]; i >= 0; i = R::parent[i])
          b[std::size_t(i)] -= h(k, i) * b[std::size_t(k)];
      for (int k = 0; k < n; ++k)  // z = D^-1 y
        b[std::size_t(k)] *= invd[std::size_t(k)];
      for (int k = 0; k < n; ++k)  // L x = z
        for (int i = R::parent[k]; i >= 0; i = R::parent[i])
          b[std::size_t(k)] -= h(k, i) * b[std::size_t(i)];
      for (int i = 0; i < n; ++i)
        out[std::size_t(c * n + i)] = b[std::size_t(i)].id();
    }
    ops += emit_function(body, g, "jacobian_at", {{"x", 3 * n}, {"a", n}}, {{"J", out}});
    body += "  /// y = FD(x), J its Jacobian through ID (fd_value, then jacobian_at(x, y)).\n";
    body += "  template <class S>\n  static void jacobian(const S* x, S* y, S* J) {\n";
    body += "    fd_value(x, y);\n    jacobian_at(x, y, J);\n  }\n";
    return ops;
  }
}

template <class R, int F>
void frame_function(std::string& code, const std::string& robot, std::vector<Stats>& stats) {
  stats.emplace_back();
  code += generate_function(
      "FramePosition<" + robot + ", " + std::to_string(F) + ">", R::nv, 3, nullptr,
      [&](const std::vector<Sym>& x, std::vector<Sym>& y) {
        VecN<Sym, R::nv> q;
        for (int k = 0; k < R::nv; ++k)
          q[k] = x[k];
        auto d = std::make_unique<Data<R, Sym>>();  // fresh: its constants in this graph
        forward_kinematics<R>(*d, q);
        const auto p = frame_placement<R>(*d, F).p;
        for (int i = 0; i < 3; ++i)
          y[i] = p[i];
      },
      stats.back());
}

/// The header for robot R (struct name `robot`, fully qualified; header `robot_header`).
template <class R>
int generate(int argc, char** argv, const std::string& robot, const std::string& robot_header) {
  take_chunk_ops_option(argc, argv);
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s [--chunk-ops=N] <jacobians.hpp> [<hessians.hpp>]\n", argv[0]);
    return 2;
  }
  const bool hessians = argc > 2;
  std::string hcode;
  std::string* h = hessians ? &hcode : nullptr;
  const auto t0 = std::chrono::steady_clock::now();
  constexpr int nv = R::nv;
  auto split = [](const std::vector<Sym>& x, VecN<Sym, nv>& a, VecN<Sym, nv>& b, VecN<Sym, nv>& c) {
    for (int k = 0; k < nv; ++k) {
      a[k] = x[k];
      b[k] = x[nv + k];
      c[k] = x[2 * nv + k];
    }
  };
  std::vector<Stats> stats(2);
  std::string code;
  // FD (q, v, tau) -> qdd and ID (q, v, a) -> tau: the same shape, x = (q, v, u).
  auto dynamics = [&](const char* name, auto algorithm, Stats& st, auto&& alternative) {
    code += generate_function(
        std::string(name) + "<" + robot + ">", 3 * nv, nv, h,
        [&](const std::vector<Sym>& x, std::vector<Sym>& y) {
          VecN<Sym, nv> q, v, u;
          split(x, q, v, u);
          auto d = std::make_unique<Data<R, Sym>>();
          const auto& r = algorithm(*d, q, v, u);
          for (int i = 0; i < nv; ++i)
            y[i] = r[i];
        },
        st, alternative);
  };
  dynamics(
      "ForwardDynamics", [](auto& d, const auto& q, const auto& v, const auto& u) -> const auto& {
        return aba<R>(d, q, v, u);
      },
      stats[0], [](std::string& body) { return fd_jacobian_through_id<R>(body); });
  dynamics(
      "InverseDynamics", [](auto& d, const auto& q, const auto& v, const auto& u) -> const auto& {
        return rnea<R>(d, q, v, u);
      },
      stats[1], nullptr);
  [&]<int... F>(std::integer_sequence<int, F...>) {
    (frame_function<R, F>(code, robot, stats), ...);
  }
  (std::make_integer_sequence<int, R::nf>{});
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  auto write = [&](const char* path, const std::string& what, const std::string& body) {
    const std::string text =
        "// Generated by arbor-adgen (gen/ad) for " + robot + ": do not edit.\n// Straight-line " +
        what +
        ", generic over the scalar;\n// selected by the provider tag arbor::ad::Generated. "
        "Generation of this robot's code took " +
        std::to_string(secs) + " s.\n#pragma once\n\n#include <" + robot_header +
        ">\n\n#include \"arbor/ad/generated.hpp\"\n\nnamespace arbor::ad {\n\n" + body +
        "}  // namespace arbor::ad\n";
    if (!write_text(path, text))
      return false;
    std::printf("arbor-adgen %s: %s, %zu bytes\n", robot.c_str(), path, text.size());
    return true;
  };
  if (!write(argv[1], "Jacobians of ForwardDynamics, InverseDynamics and FramePosition", code))
    return 1;
  if (hessians && !write(argv[2],
                         "Hessians of lambda^T ForwardDynamics and lambda^T "
                         "InverseDynamics",
                         hcode))
    return 1;
  const char* names[] = {"FD", "ID"};
  for (std::size_t i = 0; i < stats.size(); ++i)
    std::printf("arbor-adgen %s %s%s: primal %ld, J forward %ld reverse %ld -> %s %ld, H %ld\n",
                robot.c_str(), i < 2 ? names[i] : "frame",
                i < 2 ? "" : std::to_string(i - 2).c_str(), stats[i].primal_ops,
                stats[i].forward_ops, stats[i].reverse_ops, stats[i].mode, stats[i].jacobian_ops,
                stats[i].hessian_ops);
  std::printf("arbor-adgen %s: generation %.2f s\n", robot.c_str(), secs);
  return 0;
}

}  // namespace arbor::adgen
