// arbor-gen --summary: what the generator made of a URDF, as text for a person (the tables the
// demo printed from the generated headers).
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "generator.hpp"

namespace arbor::gen {
namespace {

const char* short_kind(Kind k) {
  switch (k) {
    case Kind::RX:
      return "RX";
    case Kind::RY:
      return "RY";
    case Kind::RZ:
      return "RZ";
    case Kind::RU:
      return "R*";
    case Kind::PX:
      return "PX";
    case Kind::PY:
      return "PY";
    case Kind::PZ:
      return "PZ";
    case Kind::PU:
      return "P*";
  }
  return "?";
}

std::string limit(double x, const char* fmt) {
  if (std::isinf(x))
    return x > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

std::string printf_line(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

}  // namespace

std::string summary_text(const RobotDesc& robot, const Options& opt, const Provenance& prov) {
  std::ostringstream o;
  const int nb = int(robot.bodies.size());
  double moving = 0;
  for (const auto& b : robot.bodies)
    moving += b.inertia.mass;
  o << "robot '" << robot.urdf_name << "' from " << prov.file_name << " (sha256 " << prov.sha256
    << ")\n";
  o << printf_line("  bodies %d, DoF %d, operational frames %d, fixed base '%s'\n", nb, nb,
                   int(robot.frames.size()), robot.root_link.c_str());
  o << printf_line("  total mass %.4f kg (moving bodies %.4f kg)\n", moving + robot.base.mass,
                   moving);
  int kinds[8] = {};
  for (const auto& b : robot.bodies)
    ++kinds[int(b.kind)];
  o << "  joint kinds:";
  for (int k = 0; k < 8; ++k)
    if (kinds[k])
      o << " " << short_kind(Kind(k)) << " x" << kinds[k];
  o << "\n";
  o << printf_line("  %3s  %-22s %-24s %-4s %6s %10s %10s %9s %9s %9s\n", "#", "joint", "body",
                   "kind", "parent", "lower", "upper", "vel", "effort", "mass");
  for (int i = 0; i < nb; ++i) {
    const Body& b = robot.bodies[std::size_t(i)];
    const int axis = int(b.kind) % 4;
    const bool negative = axis < 3 && b.axis[std::size_t(axis)] < 0;
    const std::string kind = std::string(negative ? "-" : "") + short_kind(b.kind);
    o << printf_line("  %3d  %-22s %-24s %-4s %6d %10s %10s %9s %9s %9.4f\n", i, b.joint.c_str(),
                     b.link.c_str(), kind.c_str(), b.parent, limit(b.lower, "%.4f").c_str(),
                     limit(b.upper, "%.4f").c_str(), limit(b.velocity, "%.3g").c_str(),
                     limit(b.effort, "%.4g").c_str(), b.inertia.mass);
  }
  // Rounded angles: how many joint rotations and axes each tolerance would make exact.
  const std::size_t off = robot.misalignment.size();
  o << "  rotations and axes not axis-aligned: " << off;
  if (off > 0) {
    o << "; --snap TOL would make exact:";
    for (double tol : kSnapLadder) {
      int n = 0;
      for (double a : robot.misalignment)
        n += a <= tol ? 1 : 0;
      o << printf_line(" %g: %d,", tol, n);
    }
    o.seekp(-1, std::ios_base::cur);
  }
  o << "\n";
  if (opt.snap > 0)
    o << printf_line(
        "  --snap %g made %d exact: largest change %.3g rad; frames at q = 0 moved "
        "by at most %.3g m and %.3g rad\n",
        opt.snap, robot.snapped, robot.snap_max_angle, robot.snap_max_position,
        robot.snap_max_rotation);
  for (const auto& n : robot.notes)
    o << "  note: " << n << "\n";
  for (const auto& w : robot.warnings)
    o << "  warning: " << w << "\n";
  if (robot.warnings.empty())
    o << "  no warnings\n";
  return o.str();
}

}  // namespace arbor::gen
