// arbor-gen: the generated header's text. Deterministic: no time stamps, shortest round-trip
// numbers (std::to_chars), fixed layout.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "generator.hpp"

namespace arbor::gen {
namespace {

/// Entries of rotations and translations within this of 0 or +-1 are written exactly: they are
/// round-off of the rpy -> matrix conversion (e.g. cos(pi/2) = 6e-17), far below any physical
/// length or angle, and exact zeros let the dynamics templates skip work at compile time.
constexpr double kSnap = 1e-14;
/// Products of inertia below this fraction of the trace are written as exact zeros.
constexpr double kSnapInertia = 1e-12;

double snap_unit(double x) {
  if (std::abs(x) < kSnap)
    return 0.0;
  if (std::abs(x - 1.0) < kSnap)
    return 1.0;
  if (std::abs(x + 1.0) < kSnap)
    return -1.0;
  return x;
}
double snap_zero(double x, double tol = kSnap) {
  return std::abs(x) < tol ? 0.0 : x;
}

/// A double as a C++ literal that reads back to the same value.
std::string num(double x) {
  if (std::isinf(x))
    return x > 0 ? "inf" : "-inf";
  if (x == 0)
    return "0.0";  // also folds -0.0
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, x);
  std::string s(buf, res.ptr);
  if (s.find_first_of(".e") == std::string::npos)
    s += ".0";
  return s;
}

std::string str(const std::string& s) {
  std::string r = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      r += '\\';
      r += char(c);
    } else if (c < 0x20 || c >= 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", c);
      r += buf;
    } else {
      r += char(c);
    }
  }
  return r + "\"";
}

std::string vec(const Vec3& v) {
  std::string s = "{";
  s += num(v[0]);
  s += ", ";
  s += num(v[1]);
  s += ", ";
  s += num(v[2]);
  s += "}";
  return s;
}
std::string mat(const Mat3& m) {
  std::string s = "{";
  s += vec(m[0]);
  s += ", ";
  s += vec(m[1]);
  s += ", ";
  s += vec(m[2]);
  s += "}";
  return s;
}

/// A placement over four lines (three rotation rows, then the translation), the first line
/// starting at the caller's position and the next ones indented by `indent` spaces.
std::string placement(const Transform& t, int indent) {
  Mat3 R;
  Vec3 p;
  for (int i = 0; i < 3; ++i) {
    p[i] = snap_zero(t.p[i]);
    for (int j = 0; j < 3; ++j)
      R[i][j] = snap_unit(t.R[i][j]);
  }
  const std::string pad(std::size_t(indent), ' ');
  std::string s = "{{" + vec(R[0]) + ",\n" + pad + "  " + vec(R[1]) + ",\n" + pad + "  " +
                  vec(R[2]) + "},\n" + pad + " " + vec(p) + "}";
  return s;
}

std::string inertia(const MassProps& m, int indent) {
  Vec3 c;
  Mat3 I = m.I;
  const double trace = std::abs(I[0][0]) + std::abs(I[1][1]) + std::abs(I[2][2]);
  for (int i = 0; i < 3; ++i) {
    c[i] = snap_zero(m.com[i]);
    for (int j = 0; j < 3; ++j) {
      if (i != j)
        I[i][j] = snap_zero(I[i][j], kSnapInertia * trace);
    }
  }
  // Symmetrize exactly (the parallel-axis sums are symmetric up to round-off).
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      I[j][i] = I[i][j];
  const std::string pad(std::size_t(indent), ' ');
  return "{" + num(m.mass) + ", " + vec(c) + ",\n" + pad + " " + mat(I) + "}";
}

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::RX:
      return "revolute_x";
    case Kind::RY:
      return "revolute_y";
    case Kind::RZ:
      return "revolute_z";
    case Kind::RU:
      return "revolute_unaligned";
    case Kind::PX:
      return "prismatic_x";
    case Kind::PY:
      return "prismatic_y";
    case Kind::PZ:
      return "prismatic_z";
    case Kind::PU:
      return "prismatic_unaligned";
  }
  return "?";
}

const std::set<std::string>& keywords() {
  static const std::set<std::string> k = {"alignas",       "alignof",     "and",
                                          "and_eq",        "asm",         "auto",
                                          "bitand",        "bitor",       "bool",
                                          "break",         "case",        "catch",
                                          "char",          "char8_t",     "char16_t",
                                          "char32_t",      "class",       "compl",
                                          "concept",       "const",       "consteval",
                                          "constexpr",     "constinit",   "const_cast",
                                          "continue",      "co_await",    "co_return",
                                          "co_yield",      "decltype",    "default",
                                          "delete",        "do",          "double",
                                          "dynamic_cast",  "else",        "enum",
                                          "explicit",      "export",      "extern",
                                          "false",         "float",       "for",
                                          "friend",        "goto",        "if",
                                          "inline",        "int",         "long",
                                          "mutable",       "namespace",   "new",
                                          "noexcept",      "not",         "not_eq",
                                          "nullptr",       "operator",    "or",
                                          "or_eq",         "private",     "protected",
                                          "public",        "register",    "reinterpret_cast",
                                          "requires",      "return",      "short",
                                          "signed",        "sizeof",      "static",
                                          "static_assert", "static_cast", "struct",
                                          "switch",        "template",    "this",
                                          "thread_local",  "throw",       "true",
                                          "try",           "typedef",     "typeid",
                                          "typename",      "union",       "unsigned",
                                          "using",         "virtual",     "void",
                                          "volatile",      "wchar_t",     "while",
                                          "xor",           "xor_eq",      "final",
                                          "override",      "import",      "module"};
  return k;
}

bool alnum(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

/// Unique identifiers for a list of names (sanitized; clashes get _2, _3...).
std::vector<std::string> unique_identifiers(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  std::set<std::string> used;
  for (const auto& n : names) {
    std::string id = sanitize_identifier(n, false);
    std::string candidate = id;
    for (int k = 2; used.count(candidate); ++k)
      candidate = id + "_" + std::to_string(k);
    used.insert(candidate);
    out.push_back(candidate);
  }
  return out;
}

}  // namespace

bool is_identifier(const std::string& s) {
  if (s.empty() || (s[0] >= '0' && s[0] <= '9'))
    return false;
  for (char c : s)
    if (!alnum(c) && c != '_')
      return false;
  if (s.find("__") != std::string::npos)
    return false;
  if (s[0] == '_' && s.size() > 1 && s[1] >= 'A' && s[1] <= 'Z')
    return false;
  return !keywords().count(s);
}

std::string sanitize_identifier(const std::string& s, bool pascal) {
  std::string r;
  if (pascal) {
    bool upper_next = true;
    for (char c : s) {
      if (!alnum(c)) {
        upper_next = true;
        continue;
      }
      r += upper_next && c >= 'a' && c <= 'z' ? char(c - 'a' + 'A') : c;
      upper_next = false;
    }
    if (r.empty() || (r[0] >= '0' && r[0] <= '9'))
      r.insert(0, "Robot");
  } else {
    for (char c : s) {
      const char o = alnum(c) ? c : '_';
      if (o == '_' && !r.empty() && r.back() == '_')
        continue;  // no "__" (reserved)
      r += o;
    }
    if (r.empty())
      r = "unnamed";
    if (r[0] >= '0' && r[0] <= '9')
      r.insert(0, "_");
    if (r[0] == '_' && r.size() > 1 && r[1] >= 'A' && r[1] <= 'Z')
      r.insert(0, "n");
  }
  if (keywords().count(r))
    r += "_";
  return r;
}

std::string emit_header(const RobotDesc& robot, const Options& opt, const Provenance& prov) {
  const std::string name = opt.name.empty() ? sanitize_identifier(robot.urdf_name, true) : opt.name;
  const int nb = int(robot.bodies.size());
  const int nf = int(robot.frames.size());
  std::ostringstream o;
  o << "// Generated by arbor-gen " << kVersion << " from " << prov.file_name
    << ". Do not edit; regenerate.\n"
    << "// Source sha256: " << prov.sha256 << "\n"
    << "// Robot " << str(robot.urdf_name) << ": " << nb << " bodies, " << nb << " DoF, " << nf
    << " frames, fixed base " << str(robot.root_link) << ".\n";
  if (!opt.root.empty())
    o << "// Option: --root " << opt.root << "\n";
  for (const auto& t : opt.tips)
    o << "// Option: --tip " << t << "\n";
  for (const auto& [j, v] : opt.locks)
    o << "// Option: --lock " << j << "=" << num(v) << "\n";
  if (opt.lock_mimic)
    o << "// Option: --lock-mimic\n";
  if (opt.strict_inertia)
    o << "// Option: --strict-inertia\n";
  if (opt.fix_inertia)
    o << "// Option: --fix-inertia\n";
  if (opt.snap > 0)
    o << "// Option: --snap " << num(opt.snap) << " (" << robot.snapped
      << " rotations and axes made exact)\n";
  if (!robot.warnings.empty())
    o << "// Accepted with " << robot.warnings.size() << " warning(s): see arbor-gen --summary.\n";
  o << "// Placement entries within 1e-14 of 0 or +-1, and products of inertia below 1e-12 of\n"
    << "// the trace, are written exactly (round-off of the rpy conversion and of the exporter).\n"
    << "#pragma once\n\n"
    << "#include <array>\n#include <limits>\n#include <string_view>\n\n"
    << "#include \"arbor/model/robot.hpp\"\n\n"
    << "namespace " << opt.ns << " {\n\n"
    << "/// Robot " << str(robot.urdf_name) << " from " << prov.file_name << ".\n"
    << "struct " << name << " {\n"
    << "  static constexpr std::string_view name = " << str(robot.urdf_name) << ";\n"
    << "  static constexpr std::string_view source_file = " << str(prov.file_name) << ";\n"
    << "  static constexpr std::string_view source_sha256 =\n      " << str(prov.sha256) << ";\n"
    << "  static constexpr std::string_view root_link = " << str(robot.root_link) << ";\n"
    << "  static constexpr int nq = " << nb << ";\n"
    << "  static constexpr int nv = " << nb << ";\n"
    << "  static constexpr int nb = " << nb << ";\n"
    << "  static constexpr int nf = " << nf << ";\n"
    << "  /// Limit value meaning \"none\".\n"
    << "  static constexpr double inf = std::numeric_limits<double>::infinity();\n\n";

  // Tables: one entry per line, with the element's name; clang-format would bin-pack them.
  o << "  // clang-format off\n  static constexpr std::array<int, nb> parent = {";
  for (int i = 0; i < nb; ++i)
    o << (i ? ", " : "") << robot.bodies[i].parent;
  o << "};\n\n  static constexpr std::array<::arbor::model::JointKind, nb> joint_kind = {\n";
  for (const auto& b : robot.bodies)
    o << "      ::arbor::model::JointKind::" << kind_name(b.kind) << ",  // " << b.joint << "\n";
  o << "  };\n\n  static constexpr std::array<::arbor::model::Vec3, nb> joint_axis = {{\n";
  for (const auto& b : robot.bodies)
    o << "      {" << vec(b.axis) << "},  // " << b.joint << "\n";
  o << "  }};\n\n  static constexpr std::array<::arbor::model::Placement, nb> joint_placement = "
       "{{\n";
  for (const auto& b : robot.bodies)
    o << "      // " << b.joint << "\n      " << placement(b.placement, 6) << ",\n";
  o << "  }};\n\n  static constexpr std::array<::arbor::model::Inertia, nb> body_inertia = {{\n";
  for (const auto& b : robot.bodies)
    o << "      // " << b.link << "\n      " << inertia(b.inertia, 6) << ",\n";
  o << "  }};\n\n  static constexpr ::arbor::model::Inertia base_inertia =\n      "
    << inertia(robot.base, 6)
    << ";\n\n  static constexpr std::array<::arbor::model::Limits, nv> limits = {{\n";
  for (const auto& b : robot.bodies)
    o << "      {" << num(b.lower) << ", " << num(b.upper) << ", " << num(b.velocity) << ", "
      << num(b.effort) << "},  // " << b.joint << (b.continuous ? " (continuous)" : "") << "\n";
  o << "  }};\n\n  static constexpr std::array<std::string_view, nb> joint_names = {\n";
  for (const auto& b : robot.bodies)
    o << "      " << str(b.joint) << ",\n";
  o << "  };\n\n  static constexpr std::array<std::string_view, nb> body_names = {\n";
  for (const auto& b : robot.bodies)
    o << "      " << str(b.link) << ",\n";
  o << "  };\n\n  static constexpr std::array<::arbor::model::Frame, nf> frames = {{\n";
  for (const auto& f : robot.frames)
    o << "      {" << str(f.link) << ", " << f.body << ",\n       " << placement(f.placement, 7)
      << "},\n";
  o << "  }};\n  // clang-format on\n\n";

  std::vector<std::string> jn, fn;
  for (const auto& b : robot.bodies)
    jn.push_back(b.joint);
  for (const auto& f : robot.frames)
    fn.push_back(f.link);
  const auto jid = unique_identifiers(jn);
  const auto fid = unique_identifiers(fn);
  o << "  /// Joint (= body = DoF) indices by sanitized joint name.\n  struct joint_id {\n";
  for (int i = 0; i < nb; ++i)
    o << "    static constexpr int " << jid[i] << " = " << i << ";\n";
  o << "  };\n\n  /// Operational frame indices by sanitized link name.\n  struct frame_id {\n";
  for (int i = 0; i < nf; ++i)
    o << "    static constexpr int " << fid[i] << " = " << i << ";\n";
  o << "  };\n};\n\n"
    << "static_assert(::arbor::model::validate<" << name << ">());\n\n"
    << "}  // namespace " << opt.ns << "\n";
  return o.str();
}

}  // namespace arbor::gen
