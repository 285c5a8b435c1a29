// arbor-gen: URDF text -> urdfdom model, with every parser complaint turned into a GenError
// (see urdf_input.hpp). Cost: one TinyXML parse and one urdfdom parse of the text.
#include "urdf_input.hpp"

#include <tinyxml.h>

#include <console_bridge/console.h>
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "math3.hpp"
#include "text.hpp"

namespace arbor::gen {
namespace {

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

}  // namespace

UrdfModel::UrdfModel(const std::string& text) {
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
  std::set<std::string> link_names;
  for (const TiXmlElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const char* name = e->Attribute("name");
    if (e->ValueStr() == "joint" && name)
      doc_order_.emplace(name, doc_order_.size());
    if (e->ValueStr() == "link" && name && !link_names.insert(name).second)
      throw GenError("link " + quote(name) + " is defined more than once");
  }
  std::vector<std::string> errors;
  {
    Capture capture;
    model_.ptr = urdf::parseURDF(text);
    errors = capture.errors;
  }
  // urdfdom sometimes logs an error and carries on with the element dropped (e.g. a mass that
  // is not a number leaves the link massless): any logged error rejects the file.
  if (!model_.ptr || !errors.empty()) {
    std::string msg = "urdfdom rejected the file";
    for (const auto& e : errors)
      msg += "\n  " + e;
    throw GenError(msg);
  }
}

UrdfModel::Owner::~Owner() {
  if (!ptr)
    return;
  for (auto& [name, link] : ptr->links_) {
    link->child_links.clear();
    link->child_joints.clear();
  }
}

std::vector<urdf::JointSharedPtr> UrdfModel::ordered_children(const urdf::Link& link) const {
  std::vector<urdf::JointSharedPtr> kids = link.child_joints;
  std::stable_sort(kids.begin(), kids.end(), [&](const auto& a, const auto& b) {
    return order_of(a->name) < order_of(b->name);
  });
  return kids;
}

std::size_t UrdfModel::order_of(const std::string& joint) const {
  auto it = doc_order_.find(joint);
  return it == doc_order_.end() ? doc_order_.size() : it->second;
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

std::string joint_what(const urdf::Joint& j) {
  return std::string(type_name(j.type)) + " joint " + quote(j.name);
}

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

}  // namespace arbor::gen
