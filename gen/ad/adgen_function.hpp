// arbor-adgen for user functions (host program): traces each listed ad::UserFunction
// (arbor/ad/user_function.hpp) with the symbolic scalar (adgen.hpp), its parameters symbolic
// too (run-time values in the generated code, not differentiated), differentiates with respect
// to the inputs by forward or reverse mode, whichever emits fewer operations, and writes a header
// of GeneratedFunction specialisations. Instantiated by adgen_function.cpp.in
// (ArborAddFunctionAd.cmake).
#pragma once

#include <arbor/ad/user_function.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "adgen.hpp"

namespace arbor::adgen {

/// Statistics of one generated user function.
struct FunctionStats {
  std::string name;
  long primal_ops = 0, forward_ops = 0, reverse_ops = 0, jacobian_ops = 0;
  const char* mode = "";
};

/// Input value k of the tracing point (parameters continue the numbering after the inputs).
inline double function_trace_point(int k) {
  return 0.21 + 0.31 * k - 0.04 * (k % 3) * k;
}

/// GeneratedFunction<F> (as text) for the user function named `name` (fully qualified).
template <ad::UserFunction F>
std::string generate_user_function(const std::string& name, FunctionStats& st) {
  constexpr int nin = F::nin, nout = F::nout, np = F::nparam;
  Graph g;
  current = &g;
  std::vector<Sym> x(nin), p(np > 0 ? np : 1), y(nout);
  std::vector<int> ins(nin);
  for (int k = 0; k < nin; ++k) {
    ins[std::size_t(k)] = g.input(k, function_trace_point(k));
    x[std::size_t(k)] = Sym::node(ins[std::size_t(k)]);
  }
  for (int k = 0; k < np; ++k)
    p[std::size_t(k)] = Sym::node(g.input(nin + k, function_trace_point(nin + k)));
  F::template eval<Sym>(x.data(), p.data(), y.data());
  if (g.value_branch) {
    std::fprintf(stderr, "arbor-adgen: %s branches on a traced value (not generated)\n",
                 name.c_str());
    std::exit(1);
  }
  std::vector<int> outs(nout);
  for (int i = 0; i < nout; ++i)
    outs[std::size_t(i)] = y[std::size_t(i)].id();
  st.name = name;
  st.primal_ops = count_ops(g, outs);
  // forward or reverse, the one with fewer live operations together with the values
  Graph gf = g, gr = g;
  current = &gf;
  const auto Jf = jacobian_forward(gf, outs, ins);
  current = &gr;
  const auto Jr = jacobian_reverse(gr, outs, ins);
  auto with = [&](const std::vector<int>& J) {
    std::vector<int> all = outs;
    all.insert(all.end(), J.begin(), J.end());
    return all;
  };
  st.forward_ops = count_ops(gf, with(Jf));
  st.reverse_ops = count_ops(gr, with(Jr));
  const bool forward = st.forward_ops <= st.reverse_ops;
  st.mode = forward ? "forward" : "reverse";
  const Graph& gb = forward ? gf : gr;
  current = nullptr;
  std::string body;
  // (x, p, y, J): p may be empty (no parameters), the signature stays the library's
  st.jacobian_ops = emit_function(body, gb, "jacobian", {{"x", nin}, {"p", np}},
                                  {{"y", outs}, {"J", forward ? Jf : Jr}});
  std::string code = "template <>\nstruct GeneratedFunction<" + name + "> {\n";
  code += "  static constexpr bool available = true;\n";
  code += "  /// Live operations of the traced function and of jacobian() (" +
          std::string(st.mode) + " mode; forward " + std::to_string(st.forward_ops) + ", reverse " +
          std::to_string(st.reverse_ops) + ").\n";
  code += "  static constexpr long primal_ops = " + std::to_string(st.primal_ops) + ";\n";
  code += "  static constexpr long jacobian_ops = " + std::to_string(st.jacobian_ops) + ";\n";
  // entries of J that are not identically zero (column major): call nodes skip the others
  const auto& J = forward ? Jf : Jr;
  code += "  /// J(i, j) (at j * nout + i) is not identically zero.\n";
  code += "  static constexpr bool nonzero[" + std::to_string(J.size()) + "] = {";
  for (std::size_t k = 0; k < J.size(); ++k)
    code += std::string(k ? ", " : "") + (gb.is_c(J[k], 0.0) ? "false" : "true");
  code += "};\n";
  code += body + "};\n\n";
  return code;
}

/// Writes the header argv[1] with the generated code of every F... (names: their qualified
/// names, in order; include: the header that declares them).
template <ad::UserFunction... F>
int generate_functions(int argc, char** argv, const std::vector<std::string>& names,
                       const std::string& include) {
  if (!generator_arguments(argc, argv))
    return 2;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<FunctionStats> stats(sizeof...(F));
  std::string code;
  std::size_t i = 0;
  ((code += generate_user_function<F>(names[i], stats[i]), ++i), ...);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string text = generated_header_text(
      "arbor_add_function_ad",
      "Straight-line Jacobians of user functions, generic over the scalar; selected by the\n// "
      "provider tag arbor::ad::Generated.",
      secs, include, {"arbor/ad/user_function.hpp", "arbor/core/math.hpp"}, "arbor::ad", code);
  if (!write_text(argv[1], text))
    return 1;
  for (const auto& s : stats)
    std::printf("arbor-adgen %s: primal %ld, J forward %ld reverse %ld -> %s %ld\n", s.name.c_str(),
                s.primal_ops, s.forward_ops, s.reverse_ops, s.mode, s.jacobian_ops);
  std::printf("arbor-adgen: %s, %zu bytes, generation %.3f s\n", argv[1], text.size(), secs);
  return 0;
}

}  // namespace arbor::adgen
