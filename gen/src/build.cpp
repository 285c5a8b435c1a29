// arbor-gen: URDF -> tree of one-DoF bodies (fixed joints merged, locks applied, frames kept).
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <console_bridge/console.h>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "generator.hpp"

namespace arbor::gen {
namespace {

// ---- small linear algebra on std::array ------------------------------------------------------
Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        c[i][j] += a[i][k] * b[k][j];
  return c;
}
Vec3 mul(const Mat3& a, const Vec3& v) {
  Vec3 r{};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      r[i] += a[i][k] * v[k];
  return r;
}
Mat3 transpose(const Mat3& a) {
  Mat3 t{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      t[i][j] = a[j][i];
  return t;
}
Transform compose(const Transform& a, const Transform& b) {
  Transform c;
  c.R = mul(a.R, b.R);
  const Vec3 rp = mul(a.R, b.p);
  for (int i = 0; i < 3; ++i)
    c.p[i] = a.p[i] + rp[i];
  return c;
}
/// Rotation by angle about a unit axis (Rodrigues).
Mat3 axis_angle(const Vec3& u, double q) {
  const double c = std::cos(q), s = std::sin(q), t = 1 - c;
  return Mat3{{{t * u[0] * u[0] + c, t * u[0] * u[1] - s * u[2], t * u[0] * u[2] + s * u[1]},
               {t * u[0] * u[1] + s * u[2], t * u[1] * u[1] + c, t * u[1] * u[2] - s * u[0]},
               {t * u[0] * u[2] - s * u[1], t * u[1] * u[2] + s * u[0], t * u[2] * u[2] + c}}};
}

/// Sum of two mass distributions expressed in the same frame (parallel-axis theorem).
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

/// Eigen-decomposition of a symmetric 3x3 matrix (cyclic Jacobi): A = V diag(values) V^T,
/// values ascending, eigenvectors in the columns of V. A diagonal A gives V = identity exactly.
struct SymEigen {
  Vec3 values;
  Mat3 V;
};
SymEigen eigen_sym(Mat3 A) {
  Mat3 V{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int sweep = 0; sweep < 64; ++sweep) {
    const double off = std::abs(A[0][1]) + std::abs(A[0][2]) + std::abs(A[1][2]);
    if (off == 0)
      break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (A[p][q] == 0)
          continue;
        const double theta = (A[q][q] - A[p][p]) / (2 * A[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          const double akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - s * akq;
          A[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          const double apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - s * aqk;
          A[q][k] = s * apk + c * aqk;
        }
        A[p][q] = A[q][p] = 0;
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = V[k][p], vkq = V[k][q];
          V[k][p] = c * vkp - s * vkq;
          V[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return A[a][a] < A[b][b]; });
  SymEigen e;
  for (int j = 0; j < 3; ++j) {
    e.values[j] = A[order[j]][order[j]];
    for (int i = 0; i < 3; ++i)
      e.V[i][j] = V[i][order[j]];
  }
  return e;
}
/// V diag(values) V^T, exactly symmetric.
Mat3 from_eigen(const Mat3& V, const Vec3& values) {
  Mat3 A{};
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      for (int k = 0; k < 3; ++k)
        A[i][j] += V[i][k] * values[k] * V[j][k];
      A[j][i] = A[i][j];
    }
  return A;
}

/// The nearest point (Euclidean) to `l` in the cone of physically consistent principal moments
/// {l_a + l_b >= l_c for every permutation} (which implies l >= 0). With the eigenvectors kept,
/// this gives the nearest consistent inertia in the Frobenius norm (the set is spectral and
/// convex). The cone is polyhedral: the projection is the feasible one of the projections onto
/// the spans of its faces that is closest to `l`.
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
      feasible = feasible && dot(n[k], x) >= -1e-14 * scale;
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

/// Nearest signed permutation matrix (axis-aligned rotation) to R; false if R is not near one.
bool nearest_aligned(const Mat3& R, Mat3& P) {
  P = Mat3{};
  std::array<bool, 3> used{};
  for (int i = 0; i < 3; ++i) {
    int c = 0;
    for (int j = 1; j < 3; ++j)
      if (std::abs(R[i][j]) > std::abs(R[i][c]))
        c = j;
    if (used[c])
      return false;
    used[c] = true;
    P[i][c] = R[i][c] > 0 ? 1.0 : -1.0;
  }
  const double det = P[0][0] * (P[1][1] * P[2][2] - P[1][2] * P[2][1]) -
                     P[0][1] * (P[1][0] * P[2][2] - P[1][2] * P[2][0]) +
                     P[0][2] * (P[1][0] * P[2][1] - P[1][1] * P[2][0]);
  return det > 0;
}
/// Rotation angle between two rotations from their Frobenius distance (accurate when small).
double rotation_distance(const Mat3& A, const Mat3& B) {
  double f = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      f += (A[i][j] - B[i][j]) * (A[i][j] - B[i][j]);
  return 2 * std::asin(std::min(1.0, std::sqrt(f) / (2 * std::sqrt(2.0))));
}

/// Deviations below this [rad] are already exact in the header (entries within 1e-14 of 0/+-1).
constexpr double kAlignedRoundOff = 1e-13;

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

bool finite3(const Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// ---- urdfdom interface ----------------------------------------------------------------------

/// Collects urdfdom's console_bridge messages instead of printing them.
class Capture : public console_bridge::OutputHandler {
 public:
  Capture() {
    console_bridge::useOutputHandler(this);
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);
  }
  ~Capture() override { console_bridge::restorePreviousOutputHandler(); }
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR)
      errors.push_back(text);
  }
  std::vector<std::string> errors;
};

Transform to_transform(const urdf::Pose& pose, const std::string& what) {
  const Vec3 p{pose.position.x, pose.position.y, pose.position.z};
  double x, y, z, w;
  pose.rotation.getQuaternion(x, y, z, w);
  if (!finite3(p) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) ||
      !std::isfinite(w)) {
    throw GenError(what + ": non-finite number in <origin>");
  }
  const double n = std::sqrt(x * x + y * y + z * z + w * w);
  if (!(n > 0))
    throw GenError(what + ": degenerate rotation in <origin>");
  x /= n;
  y /= n;
  z /= n;
  w /= n;
  Transform t;
  t.R = Mat3{{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
              {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
              {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
  t.p = p;
  return t;
}

std::string quote(const std::string& s) {
  return "'" + s + "'";
}

const char* type_name(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE:
      return "revolute";
    case urdf::Joint::CONTINUOUS:
      return "continuous";
    case urdf::Joint::PRISMATIC:
      return "prismatic";
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    case urdf::Joint::FIXED:
      return "fixed";
    default:
      return "unknown";
  }
}

/// The depth-first walk that builds the tree.
class Builder {
 public:
  Builder(const urdf::ModelInterface& model, const Options& opt,
          std::map<std::string, std::size_t> doc_order)
      : model_(model), opt_(opt), doc_order_(std::move(doc_order)) {
    for (const auto& [joint, value] : opt.locks) {
      if (!std::isfinite(value))
        throw GenError("--lock " + joint + ": value is not finite");
      if (!model_.getJoint(joint))
        throw GenError("--lock " + joint + ": no joint of that name");
      if (!locks_.emplace(joint, value).second)
        throw GenError("--lock " + joint + ": given more than once");
    }
    if (opt.lock_mimic)
      lock_mimic_groups();
  }

  RobotDesc run() {
    check_tree();
    urdf::LinkConstSharedPtr root = model_.getRoot();
    if (!opt_.root.empty()) {
      root = model_.getLink(opt_.root);
      if (!root)
        throw GenError("--root " + opt_.root + ": no link of that name");
    }
    out_.urdf_name = model_.getName();
    out_.root_link = root->name;
    select(root);
    visit(root, -1, Transform{});
    for (const auto& [joint, value] : locks_) {
      if (!used_locks_.count(joint))
        out_.notes.push_back("--lock " + joint + ": joint is outside the selected tree; ignored");
    }
    if (out_.bodies.empty())
      throw GenError("no movable joint below root link " + quote(root->name) +
                     ": nothing to generate");
    check_subtree_masses();
    return out_;
  }

 private:
  /// The joint a mimic joint follows, checked to exist.
  urdf::JointConstSharedPtr mimic_master(const urdf::Joint& j) const {
    auto m = model_.getJoint(j.mimic->joint_name);
    if (!m)
      throw GenError(std::string(type_name(j.type)) + " joint " + quote(j.name) + " mimics joint " +
                     quote(j.mimic->joint_name) + ", which does not exist");
    return m;
  }
  /// The first joint of a mimic chain (j mimics k mimics ... master), or a cycle error.
  urdf::JointConstSharedPtr group_master(const urdf::JointConstSharedPtr& j) const {
    urdf::JointConstSharedPtr m = j;
    std::set<std::string> seen;
    while (m->mimic) {
      if (!seen.insert(m->name).second)
        throw GenError("joint " + quote(j->name) + ": its mimic joints form a cycle through " +
                       quote(m->name));
      m = mimic_master(*m);
    }
    return m;
  }

  /// --lock-mimic: every master of a mimic group not locked by --lock is locked at 0 when 0 is
  /// within its limits (or it has none), else at the middle of its range.
  void lock_mimic_groups() {
    std::map<std::string, std::vector<std::string>> groups;  // master -> mimic joints
    for (const auto& [name, joint] : model_.joints_) {
      if (joint->mimic)
        groups[group_master(joint)->name].push_back(name);
    }
    for (const auto& [master, members] : groups) {
      std::string list;
      for (const auto& m : members)
        list += (list.empty() ? "" : ", ") + m;
      const urdf::Joint& j = *model_.getJoint(master);
      if (j.type == urdf::Joint::FIXED) {
        out_.notes.push_back("--lock-mimic: " + list + " follow fixed joint " + master +
                             " (at 0): locked");
        continue;
      }
      auto given = locks_.find(master);
      if (given != locks_.end()) {
        out_.notes.push_back("--lock-mimic: " + master + " locked at " + fmt(given->second) +
                             " by --lock, with its mimic joints " + list);
        continue;
      }
      double value = 0;
      std::string why = "its zero";
      if (j.type != urdf::Joint::CONTINUOUS && j.limits &&
          !(j.limits->lower == 0 && j.limits->upper == 0) &&
          (j.limits->lower > 0 || j.limits->upper < 0)) {
        value = 0.5 * (j.limits->lower + j.limits->upper);
        why =
            "the middle of its range [" + fmt(j.limits->lower) + ", " + fmt(j.limits->upper) + "]";
      }
      locks_.emplace(master, value);
      used_locks_.insert(master);  // a master outside the selection is no user error
      out_.notes.push_back("--lock-mimic: locked " + master + " at " + fmt(value) + " (" + why +
                           ") with its mimic joints " + list);
    }
  }

  /// Every link must hang below the root: a link that does not is on a cycle.
  void check_tree() {
    std::vector<urdf::LinkSharedPtr> links;
    model_.getLinks(links);
    for (const auto& link : links) {
      std::set<std::string> seen;
      std::vector<std::string> path;
      for (urdf::LinkConstSharedPtr l = link; l; l = l->getParent()) {
        if (!seen.insert(l->name).second) {
          std::string cycle;
          auto it = std::find(path.begin(), path.end(), l->name);
          for (; it != path.end(); ++it)
            cycle += *it + " <- ";
          throw GenError("the kinematic graph has a cycle: " + cycle + l->name +
                         " (a URDF must be a tree)");
        }
        path.push_back(l->name);
      }
    }
  }

  std::vector<urdf::JointSharedPtr> ordered_children(const urdf::Link& link) const {
    std::vector<urdf::JointSharedPtr> kids = link.child_joints;
    std::stable_sort(kids.begin(), kids.end(), [&](const auto& a, const auto& b) {
      return order_of(a->name) < order_of(b->name);
    });
    return kids;
  }
  std::size_t order_of(const std::string& joint) const {
    auto it = doc_order_.find(joint);
    return it == doc_order_.end() ? doc_order_.size() : it->second;
  }

  /// True when a joint moves nothing: fixed, locked by --lock or --lock-mimic, or a mimic of
  /// such a joint (chains of mimics followed). Side-effect free; cycles and missing masters are
  /// reported by visit().
  bool rigid(const urdf::Joint& j, std::size_t depth = 0) const {
    if (j.type == urdf::Joint::FIXED || locks_.count(j.name))
      return true;
    if (!j.mimic || depth > model_.joints_.size())
      return false;
    const auto m = model_.getJoint(j.mimic->joint_name);
    return m && rigid(*m, depth + 1);
  }

  /// Marks the links kept: the whole subtree of the root, or the root -> tip chains together
  /// with every link rigidly attached to a kept link (through fixed or locked joints, as fixed
  /// links are merged elsewhere). Only movable subtrees are left out.
  void select(const urdf::LinkConstSharedPtr& root) {
    if (opt_.tips.empty()) {
      std::vector<urdf::LinkConstSharedPtr> stack{root};
      while (!stack.empty()) {
        auto l = stack.back();
        stack.pop_back();
        selected_.insert(l->name);
        for (const auto& child : l->child_links)
          stack.push_back(child);
      }
      return;
    }
    for (const std::string& tip : opt_.tips) {
      urdf::LinkConstSharedPtr l = model_.getLink(tip);
      if (!l)
        throw GenError("--tip " + tip + ": no link of that name");
      std::vector<std::string> chain;
      for (; l && l->name != root->name; l = l->getParent())
        chain.push_back(l->name);
      if (!l)
        throw GenError("--tip " + tip + ": link is not below the root link " + quote(root->name));
      selected_.insert(root->name);
      selected_.insert(chain.begin(), chain.end());
    }
    std::vector<std::string> stack(selected_.begin(), selected_.end());
    while (!stack.empty()) {
      const auto l = model_.getLink(stack.back());
      stack.pop_back();
      for (const auto& j : l->child_joints)
        if (rigid(*j) && selected_.insert(j->child_link_name).second)
          stack.push_back(j->child_link_name);
    }
  }

  void add_inertial(int body, const Transform& X, const urdf::Link& link) {
    if (!link.inertial)
      return;
    const urdf::Inertial& in = *link.inertial;
    const std::string what = "link " + quote(link.name);
    if (!std::isfinite(in.mass))
      throw GenError(what + ": mass is not finite");
    if (in.mass < 0) {
      std::ostringstream s;
      s << what << ": negative mass " << in.mass << " kg";
      throw GenError(s.str());
    }
    Mat3 I{{{in.ixx, in.ixy, in.ixz}, {in.ixy, in.iyy, in.iyz}, {in.ixz, in.iyz, in.izz}}};
    for (const auto& row : I)
      if (!finite3(row))
        throw GenError(what + ": inertia is not finite");
    I = checked_inertia(what, I);
    const Transform T = compose(X, to_transform(in.origin, what + " <inertial>"));
    MassProps part;
    part.mass = in.mass;
    part.com = T.p;
    part.I = mul(mul(T.R, I), transpose(T.R));
    MassProps& target = body < 0 ? out_.base : out_.bodies[body].inertia;
    target = combine(target, part);
  }

  /// The inertia policy (README, "The generator"): a clearly negative principal moment is an
  /// error; a round-off negative one is clamped to zero, and a violated triangle inequality is
  /// kept, each with a warning (errors with --strict-inertia; --fix-inertia projects onto the
  /// nearest consistent inertia).
  Mat3 checked_inertia(const std::string& what, Mat3 I) {
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
    const bool negative = I[0][0] < 0 || I[1][1] < 0 || I[2][2] < 0 || l[0] < -1e-14 * trace;
    if (negative) {
      const std::string msg = what + ": inertia has a round-off negative principal moment " +
                              fmt(l[0]) + " kg m^2 (exporter's zero?)";
      if (opt_.strict_inertia)
        throw GenError(msg + " [--strict-inertia]");
      for (double& v : e.values)
        v = std::max(v, 0.0);
      I = from_eigen(e.V, e.values);
      out_.warnings.push_back(msg + ": clamped to zero");
    }
    for (double& v : e.values)  // the eigen solver's round-off
      if (std::abs(v) <= 1e-14 * trace)
        v = 0;
    const Vec3& c = e.values;
    if (c[2] > c[0] + c[1] + tol) {
      const std::string msg = what + ": inertia violates the triangle inequality (principal " +
                              "moments " + fmt(c[0]) + ", " + fmt(c[1]) + ", " + fmt(c[2]) +
                              " kg m^2): physically inconsistent";
      if (opt_.strict_inertia)
        throw GenError(msg + " [--strict-inertia]");
      if (opt_.fix_inertia) {
        const Vec3 f = project_consistent(c);
        const Mat3 F = from_eigen(e.V, f);
        double change = 0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            change += (F[i][j] - I[i][j]) * (F[i][j] - I[i][j]);
        change = std::sqrt(change);
        out_.warnings.push_back(msg + "; --fix-inertia: replaced by the nearest consistent " +
                                "inertia, principal moments " + fmt(f[0]) + ", " + fmt(f[1]) +
                                ", " + fmt(f[2]) + " kg m^2 (change " + fmt(change) +
                                " kg m^2, Frobenius)");
        I = F;
      } else {
        out_.warnings.push_back(msg + "; kept as given (--fix-inertia repairs it, " +
                                "--strict-inertia rejects it)");
      }
    }
    return I;
  }

  /// A joint's <origin>, with --snap applied to its rotation; records its misalignment.
  Transform joint_origin(const urdf::Joint& j, const std::string& what) {
    Transform t = to_transform(j.parent_to_joint_origin_transform, what);
    Mat3 P;
    if (!nearest_aligned(t.R, P))
      return t;
    const double angle = rotation_distance(t.R, P);
    if (angle < kAlignedRoundOff)
      return t;
    if (opt_.snap > 0 && angle <= opt_.snap) {
      t.R = P;
      ++out_.snapped;
      out_.snap_max_angle = std::max(out_.snap_max_angle, angle);
    } else {
      out_.misalignment.push_back(angle);
    }
    return t;
  }

  static Transform joint_motion(const urdf::Joint& j, const Vec3& axis, double q) {
    Transform m;
    if (j.type == urdf::Joint::PRISMATIC) {
      m.p = Vec3{axis[0] * q, axis[1] * q, axis[2] * q};
    } else if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS) {
      m.R = axis_angle(axis, q);
    }
    return m;
  }

  /// The position a joint is locked at, if it is: directly, or as a mimic of a locked joint (or
  /// of a fixed one, at 0), following chains of mimic joints.
  bool locked_value(const urdf::Joint& j, double& value, int depth = 0) {
    auto it = locks_.find(j.name);
    if (it != locks_.end()) {
      used_locks_.insert(j.name);
      value = it->second;
      return true;
    }
    if (j.type == urdf::Joint::FIXED && depth > 0) {
      value = 0;
      return true;
    }
    if (j.mimic) {
      if (depth > int(model_.joints_.size()))
        throw GenError("joint " + quote(j.name) + ": its mimic joints form a cycle");
      auto m = mimic_master(j);
      double master_value = 0;
      if (locked_value(*m, master_value, depth + 1)) {
        value = j.mimic->multiplier * master_value + j.mimic->offset;
        if (depth == 0)
          out_.notes.push_back("joint " + j.name + " mimics locked joint " + m->name +
                               ": locked at " + std::to_string(value));
        return true;
      }
    }
    return false;
  }

  /// The unit axis of a movable joint, with --snap applied; records its misalignment. Only
  /// called once per joint (locked joints included).
  Vec3 movable_axis(const urdf::Joint& j) {
    const Vec3 a{j.axis.x, j.axis.y, j.axis.z};
    const std::string what = std::string(type_name(j.type)) + " joint " + quote(j.name);
    if (!finite3(a))
      throw GenError(what + ": axis is not finite");
    const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(n > 1e-12))
      throw GenError(what + ": axis is the zero vector");
    Vec3 u{a[0] / n, a[1] / n, a[2] / n};
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(u[i]) > std::abs(u[k]))
        k = i;
    const double side = std::hypot(u[(k + 1) % 3], u[(k + 2) % 3]);
    const double angle = std::atan2(side, std::abs(u[k]));
    if (angle < kAlignedRoundOff)
      return u;
    if (opt_.snap > 0 && angle <= opt_.snap) {
      const double sign = u[k] > 0 ? 1.0 : -1.0;
      u = Vec3{0, 0, 0};
      u[k] = sign;
      ++out_.snapped;
      out_.snap_max_angle = std::max(out_.snap_max_angle, angle);
    } else {
      out_.misalignment.push_back(angle);
    }
    return u;
  }

  void visit(const urdf::LinkConstSharedPtr& link, int body, const Transform& X) {
    out_.frames.push_back(FrameDesc{link->name, body, X});
    add_inertial(body, X, *link);
    for (const auto& j : ordered_children(*link)) {
      auto child = model_.getLink(j->child_link_name);
      if (!selected_.count(child->name)) {
        report_dropped(*j, *link, body);
        continue;
      }
      const std::string what = std::string(type_name(j->type)) + " joint " + quote(j->name);
      const Transform origin = compose(X, joint_origin(*j, what));
      double value = 0;
      const bool locked = locked_value(*j, value);
      switch (j->type) {
        case urdf::Joint::FIXED:
          if (locks_.count(j->name))
            throw GenError("--lock " + j->name + ": joint is already fixed");
          visit(child, body, origin);
          break;
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC: {
          const Vec3 axis = movable_axis(*j);
          if (locked) {
            check_lock_range(*j, value);
            visit(child, body, compose(origin, joint_motion(*j, axis, value)));
          } else if (j->mimic) {
            throw GenError(what + " mimics joint " + quote(j->mimic->joint_name) +
                           ": mimic joints are not supported. Lock every mimic group with "
                           "--lock-mimic, this pair with --lock " +
                           j->mimic->joint_name + "=VALUE, or leave the branch out with --tip");
          } else {
            add_body(*j, child->name, body, origin, axis);
            visit(child, int(out_.bodies.size()) - 1, Transform{});
          }
          break;
        }
        case urdf::Joint::FLOATING:
        case urdf::Joint::PLANAR:
          if (!locked) {
            throw GenError(what + ": " + type_name(j->type) +
                           " joints are not supported (fixed-base trees of one-DoF joints "
                           "only). Fix it in place with --lock " +
                           j->name + "=0, or leave the branch out with --tip/--root");
          }
          if (value != 0.0)
            throw GenError("--lock " + j->name + ": a " + type_name(j->type) +
                           " joint can only be locked at its origin (value 0)");
          visit(child, body, origin);
          break;
        default:
          throw GenError(what + ": unsupported joint type");
      }
    }
  }

  /// A movable subtree left out by --tip. Its mass is reported in kg: a warning when it hung
  /// from a moving body (the dynamics of the kept joints change), a note when it hung from the
  /// fixed base (they do not) or had none.
  void report_dropped(const urdf::Joint& j, const urdf::Link& parent, int body) {
    double mass = 0;
    std::string massive;
    std::vector<urdf::LinkConstSharedPtr> stack{model_.getLink(j.child_link_name)};
    while (!stack.empty()) {
      const auto l = stack.back();
      stack.pop_back();
      if (l->inertial && l->inertial->mass > 0) {
        mass += l->inertial->mass;
        massive += (massive.empty() ? "" : ", ") + l->name + " " + fmt(l->inertial->mass) + " kg";
      }
      const auto kids = ordered_children(*l);  // pushed last first: listed in document order
      for (auto k = kids.rbegin(); k != kids.rend(); ++k)
        stack.push_back(model_.getLink((*k)->child_link_name));
    }
    const std::string what = "--tip: " + std::string(type_name(j.type)) + " joint " +
                             quote(j.name) + " below link " + quote(parent.name) +
                             " is not on a chain to a tip: its subtree is dropped";
    if (mass == 0) {
      out_.notes.push_back(what + " (0 kg: no link below it has mass)");
    } else if (body < 0) {
      out_.notes.push_back(what + " with " + fmt(mass) + " kg (" + massive +
                           "), which hung from the fixed base: the dynamics are unchanged");
    } else {
      const Body& b = out_.bodies[std::size_t(body)];
      const std::string lock =
          j.mimic ? j.mimic->joint_name + "=VALUE (it mimics that joint) or --lock-mimic"
                  : j.name + "=VALUE";
      out_.warnings.push_back(what + ", and moving body " + quote(b.link) + " (joint " +
                              quote(b.joint) + ") loses " + fmt(mass) + " kg (" + massive +
                              "). Keep the mass with --lock " + lock +
                              ", or name a link below it with --tip");
    }
  }

  void check_lock_range(const urdf::Joint& j, double value) const {
    if (j.type == urdf::Joint::CONTINUOUS || !j.limits)
      return;
    const double lo = j.limits->lower, hi = j.limits->upper;
    if (lo == 0 && hi == 0)
      return;  // exporters' "no limits"
    if (value < lo || value > hi) {
      std::ostringstream s;
      s << "--lock " << j.name << "=" << value << ": outside the joint's limits [" << lo << ", "
        << hi << "]";
      throw GenError(s.str());
    }
  }

  void add_body(const urdf::Joint& j, const std::string& child, int parent, const Transform& X,
                const Vec3& axis) {
    Body b;
    b.joint = j.name;
    b.link = child;
    b.parent = parent;
    b.placement = X;
    b.axis = axis;
    const bool prismatic = j.type == urdf::Joint::PRISMATIC;
    int aligned = -1;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(std::abs(axis[k]) - 1.0) < 1e-12 && std::abs(axis[(k + 1) % 3]) < 1e-12 &&
          std::abs(axis[(k + 2) % 3]) < 1e-12) {
        aligned = k;
      }
    }
    if (aligned >= 0) {
      const double sign = axis[aligned] > 0 ? 1.0 : -1.0;
      b.axis = Vec3{0, 0, 0};
      b.axis[aligned] = sign;
      b.kind = prismatic ? Kind(int(Kind::PX) + aligned) : Kind(int(Kind::RX) + aligned);
    } else {
      b.kind = prismatic ? Kind::PU : Kind::RU;
    }
    const double inf = std::numeric_limits<double>::infinity();
    b.continuous = j.type == urdf::Joint::CONTINUOUS;
    b.lower = -inf;
    b.upper = inf;
    b.velocity = inf;
    b.effort = inf;
    if (j.limits) {
      const urdf::JointLimits& l = *j.limits;
      const std::string what = "joint " + quote(j.name) + " <limit>";
      for (double x : {l.lower, l.upper, l.velocity, l.effort})
        if (!std::isfinite(x))
          throw GenError(what + ": non-finite value");
      if (!b.continuous && !(l.lower == 0 && l.upper == 0)) {
        if (l.lower > l.upper)
          throw GenError(what + ": lower > upper");
        b.lower = l.lower;
        b.upper = l.upper;
      }
      if (l.velocity < 0 || l.effort < 0)
        throw GenError(what + ": negative velocity or effort");
      if (l.velocity > 0)
        b.velocity = l.velocity;
      if (l.effort > 0)
        b.effort = l.effort;
    }
    out_.bodies.push_back(b);
  }

  /// Every DoF must move mass, and a revolute one must move inertia about its axis (at q = 0):
  /// otherwise its row of the joint-space inertia matrix is zero.
  void check_subtree_masses() const {
    std::vector<MassProps> sub(out_.bodies.size());  // composite of each subtree, body frame
    for (int i = int(sub.size()) - 1; i >= 0; --i) {
      const Body& b = out_.bodies[i];
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
        if (!(axial > kAbsInertiaTol)) {
          throw GenError("joint " + quote(b.joint) + " moves no inertia about its axis at q = 0 " +
                         "(the mass below it lies on the axis): its mass matrix row would be " +
                         "singular. Lock it with --lock " + b.joint +
                         "=VALUE or drop it with --tip");
        }
      }
      if (b.parent >= 0) {
        MassProps moved;
        moved.mass = sub[i].mass;
        const Vec3 rc = mul(b.placement.R, sub[i].com);
        for (int k = 0; k < 3; ++k)
          moved.com[k] = rc[k] + b.placement.p[k];
        moved.I = mul(mul(b.placement.R, sub[i].I), transpose(b.placement.R));
        sub[b.parent] = combine(sub[b.parent], moved);
      }
    }
  }

  const urdf::ModelInterface& model_;
  const Options& opt_;
  std::map<std::string, std::size_t> doc_order_;
  std::map<std::string, double> locks_;
  std::set<std::string> used_locks_;
  std::set<std::string> selected_;
  RobotDesc out_;
};

/// World placements at q = 0 of every frame of a built robot.
std::vector<Transform> world_frames(const RobotDesc& r) {
  std::vector<Transform> body(r.bodies.size());
  for (std::size_t i = 0; i < r.bodies.size(); ++i) {
    const int p = r.bodies[i].parent;
    body[i] = p < 0 ? r.bodies[i].placement : compose(body[std::size_t(p)], r.bodies[i].placement);
  }
  std::vector<Transform> out;
  for (const auto& f : r.frames)
    out.push_back(f.body < 0 ? f.placement : compose(body[std::size_t(f.body)], f.placement));
  return out;
}

void compare_frames(RobotDesc& snapped, const RobotDesc& plain) {
  const auto a = world_frames(snapped), b = world_frames(plain);
  if (a.size() != b.size())
    return;
  for (std::size_t i = 0; i < a.size(); ++i) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k)
      d2 += (a[i].p[k] - b[i].p[k]) * (a[i].p[k] - b[i].p[k]);
    snapped.snap_max_position = std::max(snapped.snap_max_position, std::sqrt(d2));
    snapped.snap_max_rotation =
        std::max(snapped.snap_max_rotation, rotation_distance(a[i].R, b[i].R));
  }
}

/// urdfdom links own their children through shared_ptr; on a cyclic input that is a reference
/// cycle that never frees. Clearing the child lists when we are done releases every link.
struct ReleaseLinks {
  urdf::ModelInterfaceSharedPtr model;
  ~ReleaseLinks() {
    if (!model)
      return;
    for (auto& [name, link] : model->links_) {
      link->child_links.clear();
      link->child_joints.clear();
    }
  }
};

}  // namespace

RobotDesc build_robot(const std::string& text, const Options& opt, const std::string& source) {
  try {
    // 1. Well-formed XML (TinyXML is urdfdom's own parser; it reports line and column).
    TiXmlDocument doc;
    doc.Parse(text.c_str());
    if (doc.Error()) {
      std::ostringstream s;
      s << "XML syntax error at line " << doc.ErrorRow() << ", column " << doc.ErrorCol() << ": "
        << doc.ErrorDesc();
      throw GenError(s.str());
    }
    const TiXmlElement* robot = doc.FirstChildElement("robot");
    if (!robot)
      throw GenError("no <robot> element: not a URDF file");
    // Document order of the joints, to walk children in the order the author wrote them.
    std::map<std::string, std::size_t> doc_order;
    std::set<std::string> link_names;
    for (const TiXmlElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const char* name = e->Attribute("name");
      if (e->ValueStr() == "joint" && name)
        doc_order.emplace(name, doc_order.size());
      if (e->ValueStr() == "link" && name && !link_names.insert(name).second)
        throw GenError("link " + quote(name) + " is defined more than once");
    }
    // 2. urdfdom builds the model; its error messages are collected and passed on.
    urdf::ModelInterfaceSharedPtr model;
    std::vector<std::string> errors;
    {
      Capture capture;
      model = urdf::parseURDF(text);
      errors = capture.errors;
    }
    // urdfdom sometimes logs an error and carries on with the element dropped (e.g. a mass that
    // is not a number leaves the link massless): any logged error rejects the file.
    const ReleaseLinks release{model};
    if (!model || !errors.empty()) {
      std::string msg = "urdfdom rejected the file";
      for (const auto& e : errors)
        msg += "\n  " + e;
      throw GenError(msg);
    }
    RobotDesc desc = Builder(*model, opt, doc_order).run();
    if (desc.snapped > 0) {
      // What --snap changed: every frame's world placement at q = 0, against the model without.
      Options plain = opt;
      plain.snap = 0;
      const RobotDesc ref = Builder(*model, plain, doc_order).run();
      compare_frames(desc, ref);
    }
    return desc;
  } catch (const GenError& e) {
    throw GenError(source + ": " + e.what());
  } catch (const std::exception& e) {
    throw GenError(source + ": " + e.what());
  }
}

}  // namespace arbor::gen
