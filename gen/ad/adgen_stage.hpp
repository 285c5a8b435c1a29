// arbor-adgen for OCP stages (host program): traces ocp::linearize_path and
// ocp::linearize_terminal (Gauss-Newton) of each listed problem definition (see
// arbor/ocp/generated_stage.hpp: a Workspace<T> alias and a static problem(ws)) once with the
// symbolic scalar (adgen.hpp), through the library's own code (the expression layer, the RBD
// providers, the Gauss-Newton products), and writes a header of GeneratedStage specialisations:
// path() and terminal(), straight-line code generic over the scalar. Inputs are symbolic
// (states, inputs with slacks, parameters, successor, multipliers); every constant of the
// definition is folded in. A comparison of traced values (a branch the code would freeze at the
// trace point) stops the generator with a message (ARBOR_ADGEN_TRAP_BRANCH=1 aborts there, for
// a debugger). Instantiated by adgen_stage.cpp.in (ArborAddStageAd.cmake).
#pragma once

#include <arbor/ocp/generated_stage.hpp>
#include <arbor/ocp/linearize.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "adgen.hpp"
#include "adgen_function.hpp"

namespace arbor::adgen {

/// Statistics of one generated stage.
struct StageStats {
  std::string name;
  long path_ops = 0, dynamics_ops = 0, terminal_ops = 0;
};

/// Node ids of a matrix's entries, column major (Eigen's storage order of the QP blocks).
template <class M>
std::vector<int> stage_ids(const M& m) {
  std::vector<int> v;
  for (int j = 0; j < int(m.cols()); ++j)
    for (int i = 0; i < int(m.rows()); ++i)
      v.push_back(m(i, j).id());
  return v;
}

/// Symbolic inputs numbered from k (trace-point values: function_trace_point).
template <int n>
VecN<Sym, n> stage_inputs(Graph& g, int& k) {
  VecN<Sym, n> v;
  for (int i = 0; i < n; ++i, ++k)
    v[i] = Sym::node(g.input(k, function_trace_point(k)));
  return v;
}

inline bool stage_branch_check(const Graph& g, const std::string& name, const char* part) {
  if (!g.value_branch)
    return true;
  std::fprintf(stderr,
               "arbor-adgen: the %s stage of %s compares traced values (a branch on the point): "
               "not generated; run with ARBOR_ADGEN_TRAP_BRANCH=1 under a debugger to find it\n",
               part, name.c_str());
  return false;
}

/// GeneratedStage<Def> (as text) for the definition named `name` (fully qualified); empty on a
/// value branch.
template <class Def>
std::string generate_stage(const std::string& name, StageStats& st) {
  using P = ocp::DefinedProblem<Def, Sym>;
  using Qp = ocp::QpOf<P, Sym>;
  constexpr int nx = P::nx, nw = P::nu + P::ns, np = P::np;
  constexpr int ng = Qp::ng, ngn = Qp::ngn;
  st.name = name;
  std::string body;
  // One graph for the workspace and both traces: the workspace's constants are nodes of it.
  Graph g;
  current = &g;
  const auto ws = std::make_unique<typename Def::template Workspace<Sym>>();  // (large)
  const P prob = Def::problem(*ws);
  {
    int k = 0;
    const auto x = stage_inputs<nx>(g, k);
    const auto w = stage_inputs<nw>(g, k);
    const auto p = stage_inputs<np>(g, k);
    const auto xn = stage_inputs<nx>(g, k);
    const auto lam = stage_inputs<nx>(g, k);
    const auto lg = stage_inputs<ng>(g, k);
    typename Qp::Stage s;
    ocp::linearize_path<ocp::HessianKind::gauss_newton>(prob, x, w, p, xn, lam, lg, s);
    if (!stage_branch_check(g, name, "path")) {
      current = nullptr;
      return {};
    }
    const std::vector<Output> out = {
        {"A", stage_ids(s.A)}, {"B", stage_ids(s.B)},   {"b", stage_ids(s.b)},
        {"Q", stage_ids(s.Q)}, {"Sm", stage_ids(s.S)},  {"R", stage_ids(s.R)},
        {"q", stage_ids(s.q)}, {"r", stage_ids(s.r)},   {"C", stage_ids(s.C)},
        {"D", stage_ids(s.D)}, {"lg", stage_ids(s.lg)}, {"ug", stage_ids(s.ug)}};
    std::vector<int> dyn = stage_ids(s.A);
    for (const auto& o : {stage_ids(s.B), stage_ids(s.b)})
      dyn.insert(dyn.end(), o.begin(), o.end());
    st.dynamics_ops = count_ops(g, dyn);
    st.path_ops = emit_function(
        body, g, "path",
        {{"x", nx}, {"wu", nw}, {"p", np}, {"x_next", nx}, {"lam_dyn", nx}, {"lam_g", ng}}, out);
  }
  {
    int k = 0;  // (the terminal's own input nodes, numbered from 0 for its function)
    const int first = int(g.nodes.size());
    const auto x = stage_inputs<nx>(g, k);
    const auto p = stage_inputs<np>(g, k);
    const auto lg = stage_inputs<ngn>(g, k);
    typename Qp::Terminal t;
    ocp::linearize_terminal<ocp::HessianKind::gauss_newton>(prob, x, p, lg, t);
    if (!stage_branch_check(g, name, "terminal")) {
      current = nullptr;
      return {};
    }
    const std::vector<Output> out = {{"Q", stage_ids(t.Q)},
                                     {"q", stage_ids(t.q)},
                                     {"C", stage_ids(t.C)},
                                     {"lg", stage_ids(t.lg)},
                                     {"ug", stage_ids(t.ug)}};
    // the emitter maps an input node by its index: the terminal's code must read its own inputs
    // only, not the path's (which a workspace could carry from one trace to the next)
    std::vector<int> all;
    for (const auto& o : out)
      all.insert(all.end(), o.ids.begin(), o.ids.end());
    const auto live = live_set(g, all, int(g.nodes.size()));
    for (int i = 0; i < first; ++i)
      if (live[std::size_t(i)] && g.nodes[std::size_t(i)].op == Op::input) {
        std::fprintf(stderr,
                     "arbor-adgen: the terminal stage of %s reads an input of the path "
                     "stage (state kept in the workspace): not generated\n",
                     name.c_str());
        current = nullptr;
        return {};
      }
    st.terminal_ops =
        emit_function(body, g, "terminal", {{"x", nx}, {"p", np}, {"lam_g", ngn}}, out);
  }
  current = nullptr;
  std::string code = "template <>\nstruct GeneratedStage<" + name + "> {\n";
  code += "  static constexpr bool available = true;\n";
  code += "  static constexpr int nx = " + std::to_string(nx) + ", nw = " + std::to_string(nw) +
          ", np = " + std::to_string(np) + ", ng = " + std::to_string(ng) +
          ", ngn = " + std::to_string(ngn) + ";\n";
  code += "  /// Emitted operations of path() (of which the dynamics A, B, b: " +
          std::to_string(st.dynamics_ops) + ") and terminal().\n";
  code += "  static constexpr long path_ops = " + std::to_string(st.path_ops) + ";\n";
  code += "  static constexpr long terminal_ops = " + std::to_string(st.terminal_ops) + ";\n";
  code += body + "};\n\n";
  return code;
}

/// Writes the header argv[1] with the generated stages of every Def... (names: their qualified
/// names, in order; include: the header that declares them).
template <class... Def>
int generate_stages(int argc, char** argv, const std::vector<std::string>& names,
                    const std::string& include) {
  if (!generator_arguments(argc, argv))
    return 2;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<StageStats> stats(sizeof...(Def));
  std::string code;
  std::size_t i = 0;
  bool ok = true;
  (
      [&] {
        const std::string c = generate_stage<Def>(names[i], stats[i]);
        ok = ok && !c.empty();
        code += c;
        ++i;
      }(),
      ...);
  if (!ok)
    return 1;
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string text = generated_header_text(
      "arbor_add_stage_ad",
      "Gauss-Newton stage linearisations of OCP definitions, generic over the scalar\n// "
      "(arbor/ocp/generated_stage.hpp).",
      secs, include, {"arbor/core/math.hpp", "arbor/ocp/generated_stage.hpp"}, "arbor::ocp", code);
  if (!write_text(argv[1], text))
    return 1;
  for (const auto& s : stats)
    std::printf("arbor-adgen %s: path stage %ld operations (dynamics %ld), terminal %ld\n",
                s.name.c_str(), s.path_ops, s.dynamics_ops, s.terminal_ops);
  std::printf("arbor-adgen: %s, %zu bytes, generation %.3f s\n", argv[1], text.size(), secs);
  return 0;
}

}  // namespace arbor::adgen
