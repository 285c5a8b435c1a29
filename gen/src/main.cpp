// arbor-gen: command-line front end. See `arbor-gen --help`.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "generator.hpp"
#include "sha256.hpp"

namespace {

constexpr const char* kUsage = R"(usage: arbor-gen ROBOT.urdf -o HEADER.hpp [options]

Turns a URDF into a C++ header of constexpr data for the arbor library.

options:
  -o, --output FILE      header to write ("-" for standard output)
  --name NAME            C++ struct name (default: the URDF robot name in PascalCase)
  --namespace NS         namespace of the struct (default: arbor::robots)
  --root LINK            use LINK as the fixed base (links above it are dropped)
  --tip LINK             keep only the chain from the root to LINK (repeatable), with every
                         link rigidly attached to it (fixed or locked joints, merged); movable
                         subtrees are dropped, with a warning giving the kg a moving body loses
  --lock JOINT=VALUE     make a movable joint fixed at VALUE [rad or m] (repeatable);
                         joints that mimic it follow; floating/planar joints lock at 0
  --lock-mimic           lock every mimic group: its master at 0 if within its limits, else
                         at mid-range (a --lock of the master wins); lists what it locked
  --strict-inertia       reject inertias accepted with a warning (round-off, triangle inequality)
  --fix-inertia          replace each inconsistent inertia by the nearest consistent one
  --snap TOL             make joint rotations and axes within TOL [rad] of axis-aligned exact
  --summary              print bodies, DoF, joint kinds, masses, limits, rounded angles and
                         warnings (-o is then optional)
  --quiet                do not print notes
  -h, --help             this text
  --version              the generator version

Fixed joints are merged into their parent body; every URDF link remains an operational frame.
On any error nothing is written and the exit status is 1 (2 for usage errors).
)";

[[noreturn]] void usage_error(const std::string& msg) {
  std::cerr << "arbor-gen: error: " << msg << "\n(see arbor-gen --help)\n";
  std::exit(2);
}

bool parse_double(const std::string& s, double& out) {
  if (s.empty())
    return false;
  errno = 0;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return errno == 0 && end == s.c_str() + s.size();
}

arbor::gen::Options parse_args(int argc, char** argv, bool& quiet) {
  arbor::gen::Options opt;
  auto value = [&](int& i, const std::string& flag) -> std::string {
    if (i + 1 >= argc)
      usage_error(flag + " needs a value");
    return argv[++i];
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << kUsage;
      std::exit(0);
    } else if (a == "--version") {
      std::cout << "arbor-gen " << arbor::gen::kVersion << "\n";
      std::exit(0);
    } else if (a == "-o" || a == "--output") {
      opt.output = value(i, a);
    } else if (a == "--name") {
      opt.name = value(i, a);
      if (!arbor::gen::is_identifier(opt.name))
        usage_error("--name " + opt.name + ": not a valid C++ identifier");
    } else if (a == "--namespace") {
      opt.ns = value(i, a);
      std::string part;
      std::istringstream in(opt.ns);
      std::string rest = opt.ns;
      std::size_t pos = 0;
      while (true) {
        std::size_t next = rest.find("::", pos);
        part = rest.substr(pos, next == std::string::npos ? std::string::npos : next - pos);
        if (!arbor::gen::is_identifier(part))
          usage_error("--namespace " + opt.ns + ": not a valid C++ namespace");
        if (next == std::string::npos)
          break;
        pos = next + 2;
      }
    } else if (a == "--root") {
      opt.root = value(i, a);
    } else if (a == "--tip") {
      opt.tips.push_back(value(i, a));
    } else if (a == "--lock") {
      const std::string v = value(i, a);
      const auto eq = v.find('=');
      double x = 0;
      if (eq == std::string::npos || eq == 0 || !parse_double(v.substr(eq + 1), x))
        usage_error("--lock " + v + ": expected JOINT=VALUE with a number");
      opt.locks.emplace_back(v.substr(0, eq), x);
    } else if (a == "--lock-mimic") {
      opt.lock_mimic = true;
    } else if (a == "--strict-inertia") {
      opt.strict_inertia = true;
    } else if (a == "--fix-inertia") {
      opt.fix_inertia = true;
    } else if (a == "--snap") {
      const std::string v = value(i, a);
      if (!parse_double(v, opt.snap) || !(opt.snap > 0) || !(opt.snap < 0.1))
        usage_error("--snap " + v + ": expected a tolerance in (0, 0.1) rad");
    } else if (a == "--summary") {
      opt.summary = true;
    } else if (a == "--quiet") {
      quiet = true;
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      usage_error("unknown option " + a);
    } else if (opt.input.empty()) {
      opt.input = a;
    } else {
      usage_error("more than one input file: " + opt.input + ", " + a);
    }
  }
  if (opt.input.empty())
    usage_error("no input URDF");
  if (opt.output.empty() && !opt.summary)
    usage_error("no output file (-o FILE)");
  if (opt.strict_inertia && opt.fix_inertia)
    usage_error("--strict-inertia and --fix-inertia exclude each other");
  return opt;
}

/// Writes `text` to `path` through a temporary file in the same folder and a rename, so that a
/// failure never leaves a partial header behind.
void write_atomically(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  if (target.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec)
      throw arbor::gen::GenError(path + ": cannot create folder: " + ec.message());
  }
  const fs::path tmp = target.string() + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw arbor::gen::GenError(path + ": cannot write: " + std::strerror(errno));
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw arbor::gen::GenError(path + ": cannot write: " + ec.message());
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool quiet = false;
  const arbor::gen::Options opt = parse_args(argc, argv, quiet);
  try {
    std::ifstream in(opt.input, std::ios::binary);
    if (!in) {
      throw arbor::gen::GenError(opt.input + ": cannot read: " + std::strerror(errno));
    }
    std::ostringstream buf;
    buf << in.rdbuf();
    if (in.bad())
      throw arbor::gen::GenError(opt.input + ": read error");
    const std::string text = buf.str();
    if (std::filesystem::is_directory(opt.input))
      throw arbor::gen::GenError(opt.input + ": is a folder, not a URDF file");

    const arbor::gen::RobotDesc robot = arbor::gen::build_robot(text, opt, opt.input);
    const arbor::gen::Provenance prov{std::filesystem::path(opt.input).filename().string(),
                                      arbor::gen::sha256_hex(text)};
    const std::string header = arbor::gen::emit_header(robot, opt, prov);
    if (opt.summary) {
      std::cout << arbor::gen::summary_text(robot, opt, prov);
    } else {
      if (!quiet)
        for (const auto& note : robot.notes)
          std::cerr << "arbor-gen: note: " << note << "\n";
      for (const auto& w : robot.warnings)
        std::cerr << "arbor-gen: warning: " << opt.input << ": " << w << "\n";
      if (!quiet && opt.snap > 0) {
        std::cerr << "arbor-gen: note: --snap " << opt.snap << " made " << robot.snapped
                  << " joint rotations and axes exact: largest change " << robot.snap_max_angle
                  << " rad; frames at q = 0 moved by at most " << robot.snap_max_position
                  << " m and " << robot.snap_max_rotation << " rad\n";
      }
      if (!quiet && opt.snap == 0) {
        int near = 0;
        double worst = 0;
        for (double a : robot.misalignment)
          if (a <= arbor::gen::kRoundedAngleMax) {
            ++near;
            worst = std::max(worst, a);
          }
        if (near > 0)
          std::cerr << "arbor-gen: note: " << near << " joint rotations or axes are within "
                    << worst << " rad of axis-aligned (rounded angles?): --snap makes them exact\n";
      }
    }
    if (opt.output == "-") {
      if (!opt.summary)
        std::cout << header;
    } else if (!opt.output.empty()) {
      write_atomically(opt.output, header);
    }
  } catch (const arbor::gen::GenError& e) {
    std::cerr << "arbor-gen: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
