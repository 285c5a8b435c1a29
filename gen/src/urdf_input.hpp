// arbor-gen: the URDF as urdfdom reads it, and the few conversions from its types that the
// tree builder needs. The only header besides mimic.hpp and selection.hpp that sees urdfdom.
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "generator.hpp"

namespace arbor::gen {

/// A parsed URDF: urdfdom's model and the document order of its joints.
class UrdfModel {
 public:
  /// Checks the XML (TinyXML reports line and column), rejects duplicate links, and builds the
  /// model with urdfdom; any error urdfdom logs rejects the file (GenError with its messages).
  explicit UrdfModel(const std::string& text);
  UrdfModel(const UrdfModel&) = delete;
  UrdfModel& operator=(const UrdfModel&) = delete;

  const urdf::ModelInterface& model() const { return *model_.ptr; }
  /// A link's child joints in the order the author wrote them.
  std::vector<urdf::JointSharedPtr> ordered_children(const urdf::Link& link) const;

 private:
  std::size_t order_of(const std::string& joint) const;
  /// urdfdom links own their children through shared_ptr; on a cyclic input that is a
  /// reference cycle that never frees. This owner clears the child lists when destroyed (also
  /// when the constructor throws after parsing), which releases every link.
  struct Owner {
    urdf::ModelInterfaceSharedPtr ptr;
    Owner() = default;
    Owner(const Owner&) = delete;
    Owner& operator=(const Owner&) = delete;
    ~Owner();
  };
  Owner model_;
  std::map<std::string, std::size_t> doc_order_;  ///< joint -> position in the document
};

/// "revolute", "fixed", ... for a urdf::Joint type.
const char* type_name(int type);
/// "<type> joint '<name>'", the way messages name a joint.
std::string joint_what(const urdf::Joint& j);
/// An <origin> as a rigid transform (its quaternion normalised); GenError naming `what` if it
/// is not finite or degenerate.
Transform to_transform(const urdf::Pose& pose, const std::string& what);

}  // namespace arbor::gen
