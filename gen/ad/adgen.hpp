// arbor-adgen (host program, not part of the library): symbolic differentiation of the RBD
// templates into straight-line code, the way the paper's CasADi code generation works.
//
// 1. Trace. `Sym` is a scalar whose every operation appends a node to one expression graph
//    (Graph): constants and inputs are nodes too. Instantiating aba / rnea / forward kinematics
//    with Sym records the whole function as a DAG. While recording, the graph
//      - folds constants (c op c, x * 0, x * 1, x * -1, x + 0, x - x, x / x, -(-x), a + (-b)),
//      - hash-conses: an operation on the same operands returns the existing node (common
//        subexpressions are found, across the primal and the derivative sweeps alike).
//    Comparisons of non-constant values would make the code value dependent: the graph records
//    them and the generator refuses to emit (aba and rnea have no such branch).
// 2. Differentiate on the graph, symbolically: forward mode (one tangent sweep per input
//    direction) or reverse mode (one adjoint sweep per output); a derivative that is zero by
//    structure stays the constant 0 and costs nothing (sparsity for free). Both are built, the
//    one with fewer live operations is kept (per function).
//    Hessians of lambda^T F: one reverse sweep for the gradient (lambda symbolic), then the
//    Jacobian of that gradient (forward over reverse, or reverse over reverse, the cheaper).
// 3. Dead-code elimination: only nodes the requested outputs depend on are emitted, as
//    `const S t<i> = t<j> op t<k>;` in a function template over the scalar S (the sine and the
//    cosine of one value as `S t<i>, t<j>; sincos(t<k>, t<i>, t<j>);` at the first of the two,
//    when both are computed in the same function or part); a function longer
//    than chunk_ops_setting operations (default 2000) is split into parts that pass the values
//    they share through an array on the entry function's stack (emit_function), which keeps
//    the compiler's time and memory linear in the length.
//
// Host code: uses the heap and one global graph pointer (like the URDF generator, it never runs
// on a target). The emitted code has neither.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

namespace arbor::adgen {

// pos: max(x, 0); step: x > 0 ? 1 : 0 (pos's derivative)
enum class Op : std::uint8_t {
  constant,
  input,
  add,
  sub,
  mul,
  div,
  neg,
  sqrt,
  sin,
  cos,
  pos,
  step
};

struct Node {
  Op op;
  int a, b;  // operands (-1: none)
  double c;  // constant value, or input index
};

/// The expression graph: nodes in creation order (a topological order), hash-consed.
class Graph {
 public:
  std::vector<Node> nodes;
  std::vector<double> val;  // value of every node at the tracing point (branch checks)
  bool value_branch = false;

  Graph() {
    constant(0.0);  // node 0
    constant(1.0);  // node 1
  }

  int constant(double c) {
    if (c == 0.0)
      c = 0.0;  // -0 and 0 are one node
    std::uint64_t bits;
    std::memcpy(&bits, &c, sizeof bits);
    auto it = consts_.find(bits);
    if (it != consts_.end())
      return it->second;
    const int id = push(Node{Op::constant, -1, -1, c}, c);
    consts_.emplace(bits, id);
    return id;
  }
  int input(int k, double value) { return push(Node{Op::input, -1, -1, double(k)}, value); }

  bool is_const(int i) const { return nodes[i].op == Op::constant; }
  bool is_c(int i, double c) const { return is_const(i) && nodes[i].c == c; }

  /// A new operation, folded and hash-consed.
  int make(Op op, int a, int b = -1) {
    const bool unary = b < 0;
    if (is_const(a) && (unary || is_const(b)))
      return constant(eval(op, nodes[a].c, unary ? 0.0 : nodes[b].c));
    switch (op) {
      case Op::add:
        if (is_c(a, 0.0))
          return b;
        if (is_c(b, 0.0))
          return a;
        if (nodes[b].op == Op::neg)
          return make(Op::sub, a, nodes[b].a);
        if (nodes[a].op == Op::neg)
          return make(Op::sub, b, nodes[a].a);
        if (a > b)
          std::swap(a, b);
        break;
      case Op::sub:
        if (is_c(b, 0.0))
          return a;
        if (is_c(a, 0.0))
          return make(Op::neg, b);
        if (a == b)
          return 0;
        if (nodes[b].op == Op::neg)
          return make(Op::add, a, nodes[b].a);
        break;
      case Op::mul:
        if (is_c(a, 0.0) || is_c(b, 0.0))
          return 0;
        if (is_c(a, 1.0))
          return b;
        if (is_c(b, 1.0))
          return a;
        if (is_c(a, -1.0))
          return make(Op::neg, b);
        if (is_c(b, -1.0))
          return make(Op::neg, a);
        if (is_const(b))
          std::swap(a, b);                          // a constant first
        if (is_const(a) && nodes[b].op == Op::neg)  // c (-x) = (-c) x
          return make(Op::mul, constant(-nodes[a].c), nodes[b].a);
        if (!is_const(a) && a > b)
          std::swap(a, b);
        break;
      case Op::div:
        if (is_c(a, 0.0))
          return 0;
        if (is_c(b, 1.0))
          return a;
        if (is_c(b, -1.0))
          return make(Op::neg, a);
        if (a == b)
          return 1;
        break;
      case Op::neg:
        if (nodes[a].op == Op::neg)
          return nodes[a].a;
        if (nodes[a].op == Op::mul && is_const(nodes[a].a))  // -(c x) = (-c) x
          return make(Op::mul, constant(-nodes[nodes[a].a].c), nodes[a].b);
        if (nodes[a].op == Op::sub)  // -(x - y) = y - x
          return make(Op::sub, nodes[a].b, nodes[a].a);
        break;
      default:
        break;
    }
    const std::uint64_t key = (std::uint64_t(op) << 58) | (std::uint64_t(std::uint32_t(a)) << 29) |
                              std::uint64_t(std::uint32_t(b + 1));
    auto it = table_.find(key);
    if (it != table_.end())
      return it->second;
    const int id = push(Node{op, a, b, 0.0}, eval(op, val[a], unary ? 0.0 : val[b]));
    table_.emplace(key, id);
    return id;
  }

  static double eval(Op op, double x, double y) {
    switch (op) {
      case Op::add:
        return x + y;
      case Op::sub:
        return x - y;
      case Op::mul:
        return x * y;
      case Op::div:
        return x / y;
      case Op::neg:
        return -x;
      case Op::sqrt:
        return std::sqrt(x);
      case Op::sin:
        return std::sin(x);
      case Op::cos:
        return std::cos(x);
      case Op::pos:
        return x > 0.0 ? x : 0.0;
      case Op::step:
        return x > 0.0 ? 1.0 : 0.0;
      default:
        return 0.0;
    }
  }

 private:
  int push(const Node& n, double v) {
    nodes.push_back(n);
    val.push_back(v);
    return int(nodes.size()) - 1;
  }
  std::unordered_map<std::uint64_t, int> consts_;
  std::unordered_map<std::uint64_t, int> table_;
};

/// The graph Sym records into (one at a time; host program only).
inline Graph* current = nullptr;

/// The tracing scalar: a node of *current.
class Sym {
 public:
  Sym() : id_(0) {}
  Sym(double c) : id_(current->constant(c)) {}  // NOLINT(google-explicit-constructor)
  static Sym node(int id) {
    Sym s;
    s.id_ = id;
    return s;
  }
  int id() const { return id_; }

  friend Sym operator+(const Sym& a) { return a; }
  friend Sym operator-(const Sym& a) { return node(current->make(Op::neg, a.id_)); }
  friend Sym operator+(const Sym& a, const Sym& b) {
    return node(current->make(Op::add, a.id_, b.id_));
  }
  friend Sym operator-(const Sym& a, const Sym& b) {
    return node(current->make(Op::sub, a.id_, b.id_));
  }
  friend Sym operator*(const Sym& a, const Sym& b) {
    return node(current->make(Op::mul, a.id_, b.id_));
  }
  friend Sym operator/(const Sym& a, const Sym& b) {
    return node(current->make(Op::div, a.id_, b.id_));
  }
  Sym& operator+=(const Sym& b) { return *this = *this + b; }
  Sym& operator-=(const Sym& b) { return *this = *this - b; }
  Sym& operator*=(const Sym& b) { return *this = *this * b; }
  Sym& operator/=(const Sym& b) { return *this = *this / b; }
  friend Sym sqrt(const Sym& a) { return node(current->make(Op::sqrt, a.id_)); }
  friend Sym sin(const Sym& a) { return node(current->make(Op::sin, a.id_)); }
  friend Sym cos(const Sym& a) { return node(current->make(Op::cos, a.id_)); }
  /// max(a, 0) as an operation (arbor::positive_part's customisation: no value branch).
  friend Sym positive_part(const Sym& a) { return node(current->make(Op::pos, a.id_)); }
  /// a > 0 ? 1 : 0 as an operation (arbor::unit_step's customisation).
  friend Sym unit_step(const Sym& a) { return node(current->make(Op::step, a.id_)); }
  /// a is the constant zero (arbor::known_zero's customisation: structure, not value).
  friend bool known_zero(const Sym& a) { return current->is_c(a.id_, 0.0); }
  /// a and b are one node (arbor::known_equal's customisation: structure, not value).
  friend bool known_equal(const Sym& a, const Sym& b) { return a.id_ == b.id_; }

  friend bool operator==(const Sym& a, const Sym& b) { return cmp(a, b) == 0; }
  friend bool operator!=(const Sym& a, const Sym& b) { return cmp(a, b) != 0; }
  friend bool operator<(const Sym& a, const Sym& b) { return cmp(a, b) < 0; }
  friend bool operator>(const Sym& a, const Sym& b) { return cmp(a, b) > 0; }
  friend bool operator<=(const Sym& a, const Sym& b) { return cmp(a, b) <= 0; }
  friend bool operator>=(const Sym& a, const Sym& b) { return cmp(a, b) >= 0; }
  friend Sym abs(const Sym& a) { return a < Sym(0.0) ? -a : a; }

 private:
  static int cmp(const Sym& a, const Sym& b) {
    Graph& g = *current;
    if (!(g.is_const(a.id_) && g.is_const(b.id_))) {
      g.value_branch = true;
      if (std::getenv("ARBOR_ADGEN_TRAP_BRANCH"))  // debugging: stop where the trace branches
        std::abort();
    }
    const double x = g.val[a.id_], y = g.val[b.id_];
    return x < y ? -1 : (x > y ? 1 : 0);
  }
  int id_;
};

/// Nodes the outputs depend on.
inline std::vector<char> live_set(const Graph& g, const std::vector<int>& outs, int n) {
  std::vector<char> live(n, 0);
  for (int o : outs)
    live[o] = 1;
  for (int i = n; i-- > 0;) {
    if (!live[i])
      continue;
    const Node& nd = g.nodes[i];
    if (nd.a >= 0)
      live[nd.a] = 1;
    if (nd.b >= 0)
      live[nd.b] = 1;
  }
  return live;
}

/// Operations (non-constant, non-input nodes) the outputs depend on.
inline long count_ops(const Graph& g, const std::vector<int>& outs) {
  const auto live = live_set(g, outs, int(g.nodes.size()));
  long n = 0;
  for (std::size_t i = 0; i < live.size(); ++i)
    n += live[i] && g.nodes[i].op != Op::constant && g.nodes[i].op != Op::input;
  return n;
}

/// Forward mode: J (outs.size() x ins.size(), column major) of node ids.
inline std::vector<int> jacobian_forward(Graph& g, const std::vector<int>& outs,
                                         const std::vector<int>& ins) {
  const int n0 = int(g.nodes.size());
  const auto live = live_set(g, outs, n0);
  std::vector<int> order;
  for (int i = 0; i < n0; ++i)
    if (live[i] && g.nodes[i].op != Op::constant && g.nodes[i].op != Op::input)
      order.push_back(i);
  const int m = int(outs.size());
  std::vector<int> J(std::size_t(m) * ins.size(), 0);
  std::vector<int> t(n0, -1);
  for (std::size_t k = 0; k < ins.size(); ++k) {
    std::fill(t.begin(), t.end(), -1);
    t[ins[k]] = 1;
    for (int i : order) {
      const Node nd = g.nodes[i];
      const int ta = nd.a >= 0 ? t[nd.a] : -1;
      const int tb = nd.b >= 0 ? t[nd.b] : -1;
      if (ta < 0 && tb < 0)
        continue;
      int r = -1;
      switch (nd.op) {
        case Op::add:
          r = ta < 0 ? tb : (tb < 0 ? ta : g.make(Op::add, ta, tb));
          break;
        case Op::sub:
          r = ta < 0 ? g.make(Op::neg, tb) : (tb < 0 ? ta : g.make(Op::sub, ta, tb));
          break;
        case Op::mul: {
          const int x = ta < 0 ? -1 : g.make(Op::mul, ta, nd.b);
          const int y = tb < 0 ? -1 : g.make(Op::mul, nd.a, tb);
          r = x < 0 ? y : (y < 0 ? x : g.make(Op::add, x, y));
          break;
        }
        case Op::div: {
          const int inv = g.make(Op::div, 1, nd.b);
          const int x = ta < 0 ? -1 : g.make(Op::mul, ta, inv);
          const int y = tb < 0 ? -1 : g.make(Op::mul, tb, g.make(Op::mul, i, inv));
          r = x < 0 ? g.make(Op::neg, y) : (y < 0 ? x : g.make(Op::sub, x, y));
          break;
        }
        case Op::neg:
          r = g.make(Op::neg, ta);
          break;
        case Op::sqrt:
          r = g.make(Op::mul, ta, g.make(Op::div, g.constant(0.5), i));
          break;
        case Op::sin:
          r = g.make(Op::mul, ta, g.make(Op::cos, nd.a));
          break;
        case Op::cos:
          r = g.make(Op::mul, ta, g.make(Op::neg, g.make(Op::sin, nd.a)));
          break;
        case Op::pos:
          r = g.make(Op::mul, ta, g.make(Op::step, nd.a));
          break;
        default:  // (step: derivative zero)
          break;
      }
      t[i] = (r >= 0 && g.is_c(r, 0.0)) ? -1 : r;
    }
    for (int o = 0; o < m; ++o)
      J[k * m + o] = t[outs[o]] < 0 ? 0 : t[outs[o]];
  }
  return J;
}

/// Reverse mode: the gradient of every output, one adjoint sweep each; J column major.
inline std::vector<int> jacobian_reverse(Graph& g, const std::vector<int>& outs,
                                         const std::vector<int>& ins) {
  const int n0 = int(g.nodes.size());
  const int m = int(outs.size());
  std::vector<int> J(std::size_t(m) * ins.size(), 0);
  std::vector<int> adj(n0, -1);
  for (int o = 0; o < m; ++o) {
    const auto live = live_set(g, {outs[o]}, n0);
    std::fill(adj.begin(), adj.end(), -1);
    auto acc = [&](int x, int w, bool minus) {
      if (g.is_const(x) || w < 0 || g.is_c(w, 0.0))
        return;
      if (adj[x] < 0)
        adj[x] = minus ? g.make(Op::neg, w) : w;
      else
        adj[x] = g.make(minus ? Op::sub : Op::add, adj[x], w);
    };
    adj[outs[o]] = 1;
    for (int i = n0; i-- > 0;) {
      if (!live[i] || adj[i] < 0)
        continue;
      const Node nd = g.nodes[i];
      const int w = adj[i];
      switch (nd.op) {
        case Op::add:
          acc(nd.a, w, false);
          acc(nd.b, w, false);
          break;
        case Op::sub:
          acc(nd.a, w, false);
          acc(nd.b, w, true);
          break;
        case Op::mul:
          acc(nd.a, g.make(Op::mul, w, nd.b), false);
          acc(nd.b, g.make(Op::mul, w, nd.a), false);
          break;
        case Op::div: {
          const int inv = g.make(Op::div, 1, nd.b);
          acc(nd.a, g.make(Op::mul, w, inv), false);
          acc(nd.b, g.make(Op::mul, w, g.make(Op::mul, i, inv)), true);
          break;
        }
        case Op::neg:
          acc(nd.a, w, true);
          break;
        case Op::sqrt:
          acc(nd.a, g.make(Op::mul, w, g.make(Op::div, g.constant(0.5), i)), false);
          break;
        case Op::sin:
          acc(nd.a, g.make(Op::mul, w, g.make(Op::cos, nd.a)), false);
          break;
        case Op::cos:
          acc(nd.a, g.make(Op::mul, w, g.make(Op::sin, nd.a)), true);
          break;
        case Op::pos:
          acc(nd.a, g.make(Op::mul, w, g.make(Op::step, nd.a)), false);
          break;
        default:  // (step: derivative zero)
          break;
      }
    }
    for (std::size_t k = 0; k < ins.size(); ++k)
      J[k * m + o] = adj[ins[k]] < 0 ? 0 : adj[ins[k]];
  }
  return J;
}

/// One output array of an emitted function: a parameter name and its node ids.
struct Output {
  std::string name;
  std::vector<int> ids;
};

/// Operations per emitted function: a longer function is split into chunks of this many
/// operations (see emit_function). GCC's optimiser is superlinear in the length of a
/// straight-line block (register allocation above all); bounded chunks keep the compile time
/// linear in the operation count and the compile memory bounded by the chunk.
inline constexpr int kDefaultChunkOps = 2000;
/// The chunk length emit_function uses by default (the generator's --chunk-ops=N; 0: never split).
inline int chunk_ops_setting = kDefaultChunkOps;

/// Consumes a leading `--chunk-ops=N` of a generator program's command line (chunk_ops_setting).
inline void take_chunk_ops_option(int& argc, char**& argv) {
  if (argc > 1 && std::strncmp(argv[1], "--chunk-ops=", 12) == 0) {
    chunk_ops_setting = std::atoi(argv[1] + 12);
    ++argv;
    --argc;
  }
}

/// The text of a generated header: a banner naming the CMake rule and what the code is (its
/// lines after the first start with "// "), the generation time, the includes (<first>, then
/// "others"), and the code inside namespace ns.
inline std::string generated_header_text(const std::string& rule, const std::string& what,
                                         double secs, const std::string& user_include,
                                         const std::vector<std::string>& includes,
                                         const std::string& ns, const std::string& code) {
  std::string t = "// Generated by arbor-adgen (gen/ad, " + rule + "): do not edit.\n// " + what +
                  " Generation took " + std::to_string(secs) + " s.\n#pragma once\n\n";
  t += "#include <limits>\n#include <" + user_include + ">\n\n";
  for (const auto& i : includes)
    t += "#include \"" + i + "\"\n";
  return t + "\nnamespace " + ns + " {\n\n" + code + "}  // namespace " + ns + "\n";
}

/// The command line of a header generator program, `[--chunk-ops=N] <header.hpp>`: takes the
/// option (chunk_ops_setting); false, with the usage, when the header is missing.
inline bool generator_arguments(int& argc, char**& argv) {
  take_chunk_ops_option(argc, argv);
  if (argc >= 2)
    return true;
  std::fprintf(stderr, "usage: %s [--chunk-ops=N] <header.hpp>\n", argv[0]);
  return false;
}

/// Writes text to the file path; false, with a message, when it cannot.
inline bool write_text(const char* path, const std::string& text) {
  std::FILE* f = std::fopen(path, "w");
  if (!f) {
    std::fprintf(stderr, "arbor-adgen: cannot write %s\n", path);
    return false;
  }
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
  return true;
}

/// Emits `template <class S> static void <name>(const S* <in0>, ..., S* <out0>, ...)` computing
/// the outputs as straight-line code; inputs are the graph's input nodes, input k being element
/// k of the concatenation of the input arrays (names and sizes given). Returns the number of
/// operations emitted.
///
/// A function of more than chunk_ops operations is emitted as chunks `<name>_part<c>` (each at
/// most chunk_ops operations, in the graph's topological order, never inlined into each other)
/// called in sequence by `<name>`, which owns an array `S w[slots]` on its stack: a value used
/// by a later chunk is stored in a slot of w by the chunk that computes it and read from there;
/// a slot is reused once the last chunk that reads its value has run (slots = the most values
/// live across one chunk boundary, not the operation count). No heap, no statics. Outputs are
/// written by the chunk that computes them.
inline long emit_function(std::string& out, const Graph& g, const std::string& name,
                          const std::vector<std::pair<std::string, int>>& inputs,
                          const std::vector<Output>& outputs, int chunk_ops = chunk_ops_setting) {
  std::vector<int> all;
  for (const auto& o : outputs)
    all.insert(all.end(), o.ids.begin(), o.ids.end());
  const int n = int(g.nodes.size());
  const auto live = live_set(g, all, n);
  // sin and cos of one argument: emitted as one sincos call at the first of the two (the scalar
  // computes both at once: one reduction of the argument; SIMD packs in one batch)
  std::vector<int> partner(n, -1);
  {
    std::unordered_map<int, int> sin_of, cos_of;  // argument -> live node
    for (int i = 0; i < n; ++i)
      if (live[i] && (g.nodes[i].op == Op::sin || g.nodes[i].op == Op::cos))
        (g.nodes[i].op == Op::sin ? sin_of : cos_of)[g.nodes[i].a] = i;
    for (const auto& [a, si] : sin_of) {
      auto it = cos_of.find(a);
      if (it != cos_of.end()) {
        partner[si] = it->second;
        partner[it->second] = si;
      }
    }
  }
  // the declaration and call of sin/cos pair (i, j = partner[i]), their locals named by name()
  auto sincos_line = [&](int i, auto&& name, auto&& ref) {
    const int j = partner[i];
    const int s_id = g.nodes[i].op == Op::sin ? i : j, c_id = g.nodes[i].op == Op::sin ? j : i;
    return "    S " + name(s_id) + ", " + name(c_id) + ";\n    sincos(" + ref(g.nodes[i].a) + ", " +
           name(s_id) + ", " + name(c_id) + ");\n";
  };
  char buf[160];
  auto constant = [&](int i) -> std::string {
    // shortest text that reads back as the same double
    const double c = g.nodes[i].c;
    if (std::isinf(c))  // (a row bound's infinity; the emitted file includes <limits>)
      return std::string(c < 0 ? "-" : "") + "std::numeric_limits<S>::infinity()";
    if (std::isnan(c))
      return "std::numeric_limits<S>::quiet_NaN()";
    char num[64];
    const auto r = std::to_chars(num, num + sizeof num, c);
    *r.ptr = '\0';
    std::snprintf(buf, sizeof buf, "S(%s)", num);
    return buf;
  };
  auto input = [&](int i) -> std::string {
    int k = int(g.nodes[i].c);
    for (const auto& [in, size] : inputs) {
      if (k < size)
        return in + "[" + std::to_string(k) + "]";
      k -= size;
    }
    return "";
  };
  auto rhs_of = [&](const Node& nd, auto&& ref) -> std::string {
    const char* bin = nd.op == Op::add   ? " + "
                      : nd.op == Op::sub ? " - "
                      : nd.op == Op::mul ? " * "
                      : nd.op == Op::div ? " / "
                                         : nullptr;
    if (bin)
      return ref(nd.a) + bin + ref(nd.b);
    if (nd.op == Op::neg)
      return "-" + ref(nd.a);
    if (nd.op == Op::pos)
      return "positive_part(" + ref(nd.a) + ")";
    if (nd.op == Op::step)
      return "unit_step(" + ref(nd.a) + ")";
    return std::string(nd.op == Op::sqrt  ? "sqrt("
                       : nd.op == Op::sin ? "sin("
                                          : "cos(") +
           ref(nd.a) + ")";
  };
  std::vector<int> ops_order;  // live operations in topological order
  for (int i = 0; i < n; ++i)
    if (live[i] && g.nodes[i].op != Op::constant && g.nodes[i].op != Op::input)
      ops_order.push_back(i);
  const long ops = long(ops_order.size());
  const std::string usings =
      "    using arbor::sin;\n    using arbor::cos;\n    using arbor::sqrt;\n"
      "    using arbor::sincos;\n    using arbor::positive_part;\n    using arbor::unit_step;\n";
  auto params = [&](bool with_w) {
    std::string p;
    bool first = true;
    for (const auto& [in, size] : inputs) {
      p += std::string(first ? "" : ", ") + "const S* " + in;
      first = false;
    }
    for (const auto& o : outputs)
      p += ", S* " + o.name;
    if (with_w)
      p += ", S* w";
    return p;
  };

  if (chunk_ops <= 0 || ops <= chunk_ops) {
    // One function: every live node a local.
    std::vector<int> local(n, -1);
    int next = 0;
    auto ref = [&](int i) -> std::string {
      if (g.nodes[i].op == Op::constant)
        return constant(i);
      return "t" + std::to_string(local[i]);
    };
    std::string body;
    for (int i = 0; i < n; ++i) {
      if (!live[i] || g.nodes[i].op == Op::constant || local[i] >= 0)
        continue;  // (a sincos pair's second: declared with the first)
      const Node& nd = g.nodes[i];
      local[i] = next++;
      if (const int j = partner[i]; j > i) {
        local[j] = next++;
        body += sincos_line(
            i, [&](int k) { return "t" + std::to_string(local[k]); }, ref);
        continue;
      }
      const std::string rhs = nd.op == Op::input ? input(i) : rhs_of(nd, ref);
      body += "    const S t" + std::to_string(local[i]) + " = " + rhs + ";\n";
    }
    for (const auto& o : outputs)
      for (std::size_t k = 0; k < o.ids.size(); ++k)
        body += "    " + o.name + "[" + std::to_string(k) + "] = " + ref(o.ids[k]) + ";\n";
    out += "  template <class S>\n  static void " + name + "(" + params(false) + ") {\n" + usings;
    for (const auto& in : inputs)
      out += "    (void)" + in.first + ";\n";
    out += body + "  }\n";
    return ops;
  }

  // Chunks.
  const int nchunks = int((ops + chunk_ops - 1) / chunk_ops);
  std::vector<int> chunk_of(n, -1), last_use(n, -1), slot(n, -1);
  for (std::size_t p = 0; p < ops_order.size(); ++p)
    chunk_of[ops_order[p]] = int(p / std::size_t(chunk_ops));
  for (int i : ops_order) {
    const Node& nd = g.nodes[i];
    for (int a : {nd.a, nd.b})
      if (a >= 0 && chunk_of[a] >= 0 && chunk_of[a] != chunk_of[i])
        last_use[a] = std::max(last_use[a], chunk_of[i]);
  }
  // Slots: allocated in the defining chunk, freed after the last reading chunk.
  std::vector<std::vector<int>> defined(nchunks), freed(nchunks);
  for (int i : ops_order)
    if (last_use[i] >= 0) {
      defined[chunk_of[i]].push_back(i);
      freed[last_use[i]].push_back(i);
    }
  std::vector<int> free_slots;
  int nslots = 0;
  for (int c = 0; c < nchunks; ++c) {
    for (int i : defined[c]) {
      if (free_slots.empty()) {
        slot[i] = nslots++;
      } else {
        slot[i] = free_slots.back();
        free_slots.pop_back();
      }
    }
    for (int i : freed[c])
      free_slots.push_back(slot[i]);
  }
  // Output assignments by defining node.
  std::unordered_map<int, std::vector<std::string>> writes;
  std::string tail;  // outputs that are constants or inputs
  for (const auto& o : outputs)
    for (std::size_t k = 0; k < o.ids.size(); ++k) {
      const int id = o.ids[k];
      const std::string lhs = o.name + "[" + std::to_string(k) + "]";
      if (chunk_of[id] >= 0)
        writes[id].push_back(lhs);
      else
        tail += "    " + lhs + " = " + (g.nodes[id].op == Op::constant ? constant(id) : input(id)) +
                ";\n";
    }
  std::string parts;
  int c = 0;
  for (std::size_t p0 = 0; p0 < ops_order.size(); p0 += std::size_t(chunk_ops), ++c) {
    const std::size_t p1 = std::min(ops_order.size(), p0 + std::size_t(chunk_ops));
    auto ref = [&](int i) -> std::string {
      const Node& nd = g.nodes[i];
      if (nd.op == Op::constant)
        return constant(i);
      if (nd.op == Op::input)
        return input(i);
      if (chunk_of[i] == c)
        return "t" + std::to_string(i);
      return "w[" + std::to_string(slot[i]) + "]";
    };
    std::string body;
    for (std::size_t p = p0; p < p1; ++p) {
      const int i = ops_order[p];
      const std::string t = "t" + std::to_string(i);
      const int j = partner[i];
      if (j >= 0 && chunk_of[j] == c) {  // a sincos pair within this chunk: one call at the first
        if (j > i)
          body += sincos_line(
              i, [](int k) { return "t" + std::to_string(k); }, ref);
      } else {
        body += "    const S " + t + " = " + rhs_of(g.nodes[i], ref) + ";\n";
      }
      if (slot[i] >= 0)
        body += "    w[" + std::to_string(slot[i]) + "] = " + t + ";\n";
      auto it = writes.find(i);
      if (it != writes.end())
        for (const auto& lhs : it->second)
          body += "    " + lhs + " = " + t + ";\n";
    }
    parts += "  template <class S>\n  [[gnu::noinline]] static void " + name + "_part" +
             std::to_string(c) + "(" + params(true) + ") {\n" + usings;
    for (const auto& in : inputs)
      parts += "    (void)" + in.first + ";\n";
    for (const auto& o : outputs)
      parts += "    (void)" + o.name + ";\n";
    parts += "    (void)w;\n" + body + "  }\n";
  }
  std::string args;
  for (const auto& in : inputs)
    args += in.first + ", ";
  for (const auto& o : outputs)
    args += o.name + ", ";
  out += parts;
  out += "  /// " + std::to_string(ops) + " operations in " + std::to_string(nchunks) + " parts; " +
         std::to_string(nslots) + " values cross a part boundary (slots of w).\n";
  out += "  template <class S>\n  static void " + name + "(" + params(false) + ") {\n";
  out += "    S w[" + std::to_string(std::max(nslots, 1)) +
         "];  // every slot written before it is read\n";
  for (int k = 0; k < nchunks; ++k)
    out += "    " + name + "_part" + std::to_string(k) + "(" + args + "w);\n";
  out += tail + "  }\n";
  return ops;
}

}  // namespace arbor::adgen

namespace Eigen {
template <>
struct NumTraits<arbor::adgen::Sym> : NumTraits<double> {
  using Real = arbor::adgen::Sym;
  using NonInteger = arbor::adgen::Sym;
  using Nested = arbor::adgen::Sym;
  using Literal = arbor::adgen::Sym;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = 1,
    MulCost = 1
  };
  static inline Real epsilon() { return Real(NumTraits<double>::epsilon()); }
  static inline Real dummy_precision() { return Real(NumTraits<double>::dummy_precision()); }
  static inline Real highest() { return Real(NumTraits<double>::highest()); }
  static inline Real lowest() { return Real(NumTraits<double>::lowest()); }
  static inline int digits10() { return NumTraits<double>::digits10(); }
};
}  // namespace Eigen

/// The limits of the tracing scalar: those of double, as constant nodes of the current graph
/// (the library writes infinite row bounds as numeric_limits<T>::infinity()).
template <>
struct std::numeric_limits<arbor::adgen::Sym> {
  using D = std::numeric_limits<double>;
  using Sym = arbor::adgen::Sym;
  static constexpr bool is_specialized = true;
  static constexpr bool is_signed = true;
  static constexpr bool is_integer = false;
  static constexpr bool is_exact = false;
  static constexpr bool has_infinity = true;
  static constexpr bool has_quiet_NaN = true;
  static constexpr int digits = D::digits;
  static constexpr int digits10 = D::digits10;
  static Sym infinity() { return Sym(D::infinity()); }
  static Sym quiet_NaN() { return Sym(D::quiet_NaN()); }
  static Sym epsilon() { return Sym(D::epsilon()); }
  static Sym max() { return Sym(D::max()); }
  static Sym min() { return Sym(D::min()); }
  static Sym lowest() { return Sym(D::lowest()); }
};
