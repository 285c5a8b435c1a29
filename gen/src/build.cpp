// arbor-gen: URDF -> tree of one-DoF bodies. A depth-first walk from the root link: fixed and
// locked joints merge their child link into the body above, movable joints start a body, every
// kept link becomes a frame. The concerns it applies live in their own files: urdf_input
// (parsing), selection (locks, --tip), mimic (mimic chains), snap (alignment, --snap), inertia
// (the inertia policy and mass checks), math3. Cost O(links + joints) plus, with --snap, a
// second build without it to measure what snapping moved.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "generator.hpp"
#include "inertia.hpp"
#include "math3.hpp"
#include "selection.hpp"
#include "snap.hpp"
#include "text.hpp"
#include "urdf_input.hpp"

namespace arbor::gen {
namespace {

/// An axis shorter than this (before normalisation) is the zero vector: no direction to move
/// along. URDF axes are written as unit vectors; a deliberate axis is never this short.
constexpr double kMinAxisNorm = 1e-12;

/// The depth-first walk that builds the tree.
class Builder {
 public:
  Builder(const UrdfModel& urdf, const Options& opt)
      : urdf_(urdf), model_(urdf.model()), opt_(opt), locks_(model_, opt, out_.notes) {}

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
    selected_ = select_links(model_, root, opt_, locks_);
    visit(root, -1, Transform{});
    locks_.report_unused(out_.notes);
    if (out_.bodies.empty())
      throw GenError("no movable joint below root link " + quote(root->name) +
                     ": nothing to generate");
    check_moves_inertia(out_);
    return out_;
  }

 private:
  /// Every link must hang below the root: a link that does not is on a cycle.
  void check_tree() const {
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

  /// What a link carries, attached to the body it merges into (-1: the fixed base) at its
  /// placement X in that body's frame. Each per-link concern (its <inertial>) is one call here.
  void add_link(int body, const Transform& X, const urdf::Link& link) {
    out_.frames.push_back(FrameDesc{link.name, body, X});
    add_inertial(body, X, link);
  }

  void add_inertial(int body, const Transform& X, const urdf::Link& link) {
    if (!link.inertial)
      return;
    const urdf::Inertial& in = *link.inertial;
    const std::string what = "link " + quote(link.name);
    MassProps given;
    given.mass = in.mass;
    given.I = Mat3{{{in.ixx, in.ixy, in.ixz}, {in.ixy, in.iyy, in.iyz}, {in.ixz, in.iyz, in.izz}}};
    const MassProps checked =
        apply_inertia_policy(given, inertia_policy(opt_), what, out_.warnings);
    const Transform T = compose(X, to_transform(in.origin, what + " <inertial>"));
    MassProps part;
    part.mass = checked.mass;
    part.com = T.p;
    part.I = rotate_tensor(T.R, checked.I);
    MassProps& target = body < 0 ? out_.base : out_.bodies[body].inertia;
    target = combine(target, part);
  }

  /// A joint's <origin>, with --snap applied to its rotation.
  Transform joint_origin(const urdf::Joint& j, const std::string& what) {
    Transform t = to_transform(j.parent_to_joint_origin_transform, what);
    t.R = snap_rotation(t.R, opt_.snap, out_);
    return t;
  }

  /// The unit axis of a movable joint, with --snap applied. Called once per joint (locked
  /// joints included), so that each axis is counted once.
  Vec3 movable_axis(const urdf::Joint& j) {
    const Vec3 a{j.axis.x, j.axis.y, j.axis.z};
    const std::string what = joint_what(j);
    if (!finite3(a))
      throw GenError(what + ": axis is not finite");
    const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(n > kMinAxisNorm))
      throw GenError(what + ": axis is the zero vector");
    return snap_axis(Vec3{a[0] / n, a[1] / n, a[2] / n}, opt_.snap, out_);
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

  void visit(const urdf::LinkConstSharedPtr& link, int body, const Transform& X) {
    add_link(body, X, *link);
    for (const auto& j : urdf_.ordered_children(*link)) {
      auto child = model_.getLink(j->child_link_name);
      if (!selected_.count(child->name)) {
        report_dropped(urdf_, *j, *link, body < 0 ? nullptr : &out_.bodies[std::size_t(body)],
                       out_);
        continue;
      }
      const std::string what = joint_what(*j);
      const Transform origin = compose(X, joint_origin(*j, what));
      const std::optional<double> lock = locks_.locked_value(j, out_.notes);
      switch (j->type) {
        case urdf::Joint::FIXED:
          if (locks_.locked_directly(j->name))
            throw GenError("--lock " + j->name + ": joint is already fixed");
          visit(child, body, origin);
          break;
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC: {
          const Vec3 axis = movable_axis(*j);
          if (lock) {
            check_lock_range(*j, *lock);
            visit(child, body, compose(origin, joint_motion(*j, axis, *lock)));
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
          if (!lock) {
            throw GenError(what + ": " + type_name(j->type) +
                           " joints are not supported (fixed-base trees of one-DoF joints "
                           "only). Fix it in place with --lock " +
                           j->name + "=0, or leave the branch out with --tip/--root");
          }
          if (*lock != 0.0)
            throw GenError("--lock " + j->name + ": a " + type_name(j->type) +
                           " joint can only be locked at its origin (value 0)");
          visit(child, body, origin);
          break;
        default:
          throw GenError(what + ": unsupported joint type");
      }
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
    const AxisAlignment aligned = nearest_axis(axis);
    if (aligned.angle < kAxisAlignedTol) {
      b.axis = Vec3{0, 0, 0};
      b.axis[aligned.axis] = aligned.sign;
      b.kind = prismatic ? Kind(int(Kind::PX) + aligned.axis) : Kind(int(Kind::RX) + aligned.axis);
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

  const UrdfModel& urdf_;
  const urdf::ModelInterface& model_;
  const Options& opt_;
  RobotDesc out_;  // before locks_: its constructor writes --lock-mimic notes into out_.notes
  Locks locks_;
  std::set<std::string> selected_;
};

}  // namespace

RobotDesc build_robot(const std::string& text, const Options& opt, const std::string& source) {
  try {
    const UrdfModel urdf(text);
    RobotDesc desc = Builder(urdf, opt).run();
    if (desc.snapped > 0) {
      Options plain = opt;
      plain.snap = 0;
      snap_frame_change(desc, Builder(urdf, plain).run());
    }
    return desc;
  } catch (const GenError& e) {
    throw GenError(source + ": " + e.what());
  } catch (const std::exception& e) {
    throw GenError(source + ": " + e.what());
  }
}

}  // namespace arbor::gen
