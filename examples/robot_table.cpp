// Demo: the generated robot headers of examples/robots, summarized as one table per robot.
// Every number printed here comes from the constexpr data of a generated header.
#include <cmath>
#include <cstdio>
#include <string>

#include <robots/atlas.hpp>
#include <robots/double_pendulum.hpp>
#include <robots/iiwa7.hpp>
#include <robots/kinova_gen3.hpp>
#include <robots/yumi.hpp>
#include <robots/yumi_no_grippers.hpp>

namespace {

std::string limit(double x, const char* fmt) {
  if (std::isinf(x))
    return x > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

/// Kind with the axis sign, e.g. "RZ", "-RX", "R*" (unaligned).
template <class R>
std::string kind_label(int i) {
  using namespace arbor::model;
  const JointKind k = R::joint_kind[i];
  const int axis = axis_index(k);
  const bool negative = axis >= 0 && R::joint_axis[i][axis] < 0;
  return std::string(negative ? "-" : "") + short_name(k);
}

template <arbor::Robot R>
void print_robot(const char* struct_name) {
  using namespace arbor::model;
  int kinds[8] = {};
  for (JointKind k : R::joint_kind)
    ++kinds[int(k)];
  std::printf("\n== %s  (URDF '%.*s' from %.*s)\n", struct_name, int(R::name.size()),
              R::name.data(), int(R::source_file.size()), R::source_file.data());
  std::printf("   bodies %d, DoF %d, operational frames %d, fixed base '%.*s'\n", R::nb, R::nv,
              R::nf, int(R::root_link.size()), R::root_link.data());
  std::printf("   total mass %.4f kg (moving bodies %.4f kg)\n", total_mass<R>(),
              total_mass<R>() - R::base_inertia.mass);
  std::printf("   joint kinds:");
  for (int k = 0; k < 8; ++k)
    if (kinds[k])
      std::printf(" %s x%d", short_name(JointKind(k)), kinds[k]);
  std::printf("\n");
  std::printf("   %3s  %-22s %-24s %-4s %6s %10s %10s %9s %9s %9s\n", "#", "joint", "body", "kind",
              "parent", "lower", "upper", "vel", "effort", "mass");
  for (int i = 0; i < R::nb; ++i) {
    const Limits& l = R::limits[i];
    std::printf("   %3d  %-22.*s %-24.*s %-4s %6d %10s %10s %9s %9s %9.4f\n", i,
                int(R::joint_names[i].size()), R::joint_names[i].data(),
                int(R::body_names[i].size()), R::body_names[i].data(), kind_label<R>(i).c_str(),
                R::parent[i], limit(l.lower, "%.4f").c_str(), limit(l.upper, "%.4f").c_str(),
                limit(l.velocity, "%.3g").c_str(), limit(l.effort, "%.4g").c_str(),
                R::body_inertia[i].mass);
  }
}

}  // namespace

int main() {
  std::printf("arbor robot headers generated from examples/robots/*.urdf\n");
  print_robot<arbor::robots::DoublePendulum>("arbor::robots::DoublePendulum");
  print_robot<arbor::robots::Iiwa7>("arbor::robots::Iiwa7");
  print_robot<arbor::robots::KinovaGen3>("arbor::robots::KinovaGen3");
  print_robot<arbor::robots::YumiNoGrippers>("arbor::robots::YumiNoGrippers");
  print_robot<arbor::robots::Yumi>("arbor::robots::Yumi (grippers locked)");
  print_robot<arbor::robots::Atlas>("arbor::robots::Atlas");
  return 0;
}
