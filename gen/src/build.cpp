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

  /// Marks the links kept: the whole subtree of the root, or only the root -> tip chains.
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
    const Mat3 I{{{in.ixx, in.ixy, in.ixz}, {in.ixy, in.iyy, in.iyz}, {in.ixz, in.iyz, in.izz}}};
    for (const auto& row : I)
      if (!finite3(row))
        throw GenError(what + ": inertia is not finite");
    // Positive semi-definite with the triangle inequality (physical rotational inertia).
    const double tol = 1e-9 * (std::abs(in.ixx) + std::abs(in.iyy) + std::abs(in.izz)) + 1e-300;
    if (in.ixx < -tol || in.iyy < -tol || in.izz < -tol || in.ixx + in.iyy < in.izz - tol ||
        in.ixx + in.izz < in.iyy - tol || in.iyy + in.izz < in.ixx - tol) {
      throw GenError(what + ": inertia is not physical (negative moment or triangle inequality)");
    }
    const Transform T = compose(X, to_transform(in.origin, what + " <inertial>"));
    MassProps part;
    part.mass = in.mass;
    part.com = T.p;
    part.I = mul(mul(T.R, I), transpose(T.R));
    MassProps& target = body < 0 ? out_.base : out_.bodies[body].inertia;
    target = combine(target, part);
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

  /// The position a joint is locked at, if it is (directly, or as a mimic of a locked joint).
  bool locked_value(const urdf::Joint& j, double& value) {
    auto it = locks_.find(j.name);
    if (it != locks_.end()) {
      used_locks_.insert(j.name);
      value = it->second;
      return true;
    }
    if (j.mimic) {
      auto m = locks_.find(j.mimic->joint_name);
      if (m != locks_.end()) {
        value = j.mimic->multiplier * m->second + j.mimic->offset;
        out_.notes.push_back("joint " + j.name + " mimics locked joint " + m->first +
                             ": locked at " + std::to_string(value));
        return true;
      }
    }
    return false;
  }

  Vec3 movable_axis(const urdf::Joint& j) const {
    const Vec3 a{j.axis.x, j.axis.y, j.axis.z};
    const std::string what = std::string(type_name(j.type)) + " joint " + quote(j.name);
    if (!finite3(a))
      throw GenError(what + ": axis is not finite");
    const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(n > 1e-12))
      throw GenError(what + ": axis is the zero vector");
    return Vec3{a[0] / n, a[1] / n, a[2] / n};
  }

  void visit(const urdf::LinkConstSharedPtr& link, int body, const Transform& X) {
    out_.frames.push_back(FrameDesc{link->name, body, X});
    add_inertial(body, X, *link);
    for (const auto& j : ordered_children(*link)) {
      auto child = model_.getLink(j->child_link_name);
      if (!selected_.count(child->name)) {
        note_dropped(*j);
        continue;
      }
      const std::string what = std::string(type_name(j->type)) + " joint " + quote(j->name);
      const Transform origin = compose(X, to_transform(j->parent_to_joint_origin_transform, what));
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
                           ": mimic joints are not supported. Lock the pair with --lock " +
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

  void note_dropped(const urdf::Joint& j) {
    out_.notes.push_back("joint " + j.name + " (" + type_name(j.type) +
                         ") and the links below it are not on a selected chain: dropped");
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

  void check_subtree_masses() const {
    std::vector<double> m(out_.bodies.size(), 0.0);
    for (int i = int(m.size()) - 1; i >= 0; --i) {
      m[i] += out_.bodies[i].inertia.mass;
      if (!(m[i] > 0)) {
        throw GenError("joint " + quote(out_.bodies[i].joint) +
                       " moves no mass (every link below it is massless): its mass matrix "
                       "row would be singular. Lock it with --lock " +
                       out_.bodies[i].joint + "=VALUE or drop it with --tip");
      }
      if (out_.bodies[i].parent >= 0)
        m[out_.bodies[i].parent] += m[i];
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
    return Builder(*model, opt, std::move(doc_order)).run();
  } catch (const GenError& e) {
    throw GenError(source + ": " + e.what());
  } catch (const std::exception& e) {
    throw GenError(source + ": " + e.what());
  }
}

}  // namespace arbor::gen
