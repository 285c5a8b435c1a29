// arbor-gen: the inertia policy and the tree's mass checks (see inertia.hpp). Each link costs
// one 3x3 eigen-decomposition; the tree check one pass over the bodies.
#include "inertia.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "math3.hpp"
#include "text.hpp"

namespace arbor::gen {

InertiaPolicy inertia_policy(const Options& opt) {
  if (opt.strict_inertia)
    return InertiaPolicy::strict;
  return opt.fix_inertia ? InertiaPolicy::fix : InertiaPolicy::warn;
}

MassProps combine(const MassProps& a, const MassProps& b) {
  MassProps r;
  r.mass = a.mass + b.mass;
  if (r.mass > 0) {
    for (int i = 0; i < 3; ++i)
      r.com[i] = (a.mass * a.com[i] + b.mass * b.com[i]) / r.mass;
  }
  for (const MassProps* part : {&a, &b}) {
    const Vec3 d{part->com[0] - r.com[0], part->com[1] - r.com[1], part->com[2] - r.com[2]};
    const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.I[i][j] += part->I[i][j] + part->mass * ((i == j ? d2 : 0.0) - d[i] * d[j]);
  }
  return r;
}

/// Relative to |l|_1: the round-off of projecting onto a face (a few ulps); a projection this
/// far outside the cone is on its face.
constexpr double kProjectionSlack = 1e-14;

// The cone is polyhedral: the projection is the feasible one of the projections onto the spans
// of its faces (each subset of the three active) that is closest to `l`.
Vec3 project_consistent(const Vec3& l) {
  const std::array<Vec3, 3> n{{{-1, 1, 1}, {1, -1, 1}, {1, 1, -1}}};  // n_k . l >= 0
  auto dot = [](const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const double scale = std::abs(l[0]) + std::abs(l[1]) + std::abs(l[2]);
  Vec3 best{0, 0, 0};  // all three faces active: the apex
  double best_d = dot(l, l);
  for (int mask = 0; mask < 7; ++mask) {
    std::vector<int> S;
    for (int k = 0; k < 3; ++k)
      if (mask & (1 << k))
        S.push_back(k);
    Vec3 x = l;
    if (S.size() == 1) {
      const double a = dot(n[S[0]], l) / 3;
      for (int i = 0; i < 3; ++i)
        x[i] -= a * n[S[0]][i];
    } else if (S.size() == 2) {
      // Gram matrix [[3, -1], [-1, 3]]; its inverse is [[3, 1], [1, 3]] / 8.
      const double r0 = dot(n[S[0]], l), r1 = dot(n[S[1]], l);
      const double y0 = (3 * r0 + r1) / 8, y1 = (r0 + 3 * r1) / 8;
      for (int i = 0; i < 3; ++i)
        x[i] -= y0 * n[S[0]][i] + y1 * n[S[1]][i];
    }
    bool feasible = true;
    for (int k = 0; k < 3; ++k)
      feasible = feasible && dot(n[k], x) >= -kProjectionSlack * scale;
    const Vec3 d{x[0] - l[0], x[1] - l[1], x[2] - l[2]};
    if (feasible && dot(d, d) < best_d) {
      best = x;
      best_d = dot(d, d);
    }
  }
  for (double& v : best)
    v = std::max(v, 0.0);
  return best;
}

MassProps apply_inertia_policy(const MassProps& link, InertiaPolicy policy, const std::string& what,
                               std::vector<std::string>& warnings) {
  if (!std::isfinite(link.mass))
    throw GenError(what + ": mass is not finite");
  if (link.mass < 0) {
    std::ostringstream s;
    s << what << ": negative mass " << link.mass << " kg";
    throw GenError(s.str());
  }
  for (const auto& row : link.I)
    if (!finite3(row))
      throw GenError(what + ": inertia is not finite");
  MassProps out = link;
  Mat3& I = out.I;
  const double trace = std::abs(I[0][0]) + std::abs(I[1][1]) + std::abs(I[2][2]);
  const double tol = kRelInertiaTol * trace + kAbsInertiaTol;
  SymEigen e = eigen_sym(I);
  const Vec3 l = e.values;
  if (l[0] < -tol) {
    throw GenError(what + ": inertia has a negative principal moment " + fmt(l[0]) +
                   " kg m^2 (trace " + fmt(trace) + "): not a rotational inertia");
  }
  // A negative diagonal entry is in the data as written (e.g. -5e-20, an exporter's zero); a
  // negative eigenvalue of the order of the solver's round-off alone is not reported.
  const bool negative = I[0][0] < 0 || I[1][1] < 0 || I[2][2] < 0 || l[0] < -kEigenRoundOff * trace;
  if (negative) {
    const std::string msg = what + ": inertia has a round-off negative principal moment " +
                            fmt(l[0]) + " kg m^2 (exporter's zero?)";
    if (policy == InertiaPolicy::strict)
      throw GenError(msg + " [--strict-inertia]");
    for (double& v : e.values)
      v = std::max(v, 0.0);
    I = from_eigen(e.V, e.values);
    warnings.push_back(msg + ": clamped to zero");
  }
  for (double& v : e.values)
    if (std::abs(v) <= kEigenRoundOff * trace)
      v = 0;
  const Vec3& c = e.values;
  if (c[2] > c[0] + c[1] + tol) {
    const std::string msg = what + ": inertia violates the triangle inequality (principal " +
                            "moments " + fmt(c[0]) + ", " + fmt(c[1]) + ", " + fmt(c[2]) +
                            " kg m^2): physically inconsistent";
    if (policy == InertiaPolicy::strict)
      throw GenError(msg + " [--strict-inertia]");
    if (policy == InertiaPolicy::fix) {
      const Vec3 f = project_consistent(c);
      const Mat3 F = from_eigen(e.V, f);
      double change = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          change += (F[i][j] - I[i][j]) * (F[i][j] - I[i][j]);
      change = std::sqrt(change);
      warnings.push_back(msg + "; --fix-inertia: replaced by the nearest consistent " +
                         "inertia, principal moments " + fmt(f[0]) + ", " + fmt(f[1]) + ", " +
                         fmt(f[2]) + " kg m^2 (change " + fmt(change) + " kg m^2, Frobenius)");
      I = F;
    } else {
      warnings.push_back(msg + "; kept as given (--fix-inertia repairs it, " +
                         "--strict-inertia rejects it)");
    }
  }
  return out;
}

void check_moves_inertia(const RobotDesc& robot) {
  std::vector<MassProps> sub(robot.bodies.size());  // composite of each subtree, body frame
  for (int i = int(sub.size()) - 1; i >= 0; --i) {
    const Body& b = robot.bodies[i];
    sub[i] = combine(sub[i], b.inertia);
    if (!(sub[i].mass > 0)) {
      throw GenError("joint " + quote(b.joint) +
                     " moves no mass (every link below it is massless): its mass matrix "
                     "row would be singular. Lock it with --lock " +
                     b.joint + "=VALUE or drop it with --tip");
    }
    if (b.kind == Kind::RX || b.kind == Kind::RY || b.kind == Kind::RZ || b.kind == Kind::RU) {
      const Vec3& u = b.axis;
      const Vec3& c = sub[i].com;
      const double uc = u[0] * c[0] + u[1] * c[1] + u[2] * c[2];
      double axial = sub[i].mass * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] - uc * uc);
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k)
          axial += u[r] * sub[i].I[r][k] * u[k];
      if (!(axial > kMinAxialInertia)) {
        throw GenError("joint " + quote(b.joint) + " moves no inertia about its axis at q = 0 " +
                       "(the mass below it lies on the axis): its mass matrix row would be " +
                       "singular. Lock it with --lock " + b.joint + "=VALUE or drop it with --tip");
      }
    }
    if (b.parent >= 0) {
      MassProps moved;
      moved.mass = sub[i].mass;
      const Vec3 rc = mul(b.placement.R, sub[i].com);
      for (int k = 0; k < 3; ++k)
        moved.com[k] = rc[k] + b.placement.p[k];
      moved.I = rotate_tensor(b.placement.R, sub[i].I);
      sub[b.parent] = combine(sub[b.parent], moved);
    }
  }
}

}  // namespace arbor::gen
