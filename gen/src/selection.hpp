// arbor-gen: which joints are locked (--lock, --lock-mimic, mimics of locked or fixed joints)
// and which links are kept (--root/--tip). Each query is O(mimic chain); the selection
// O(links).
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "generator.hpp"

namespace arbor::gen {

class UrdfModel;

/// The joints made rigid at given positions.
class Locks {
 public:
  /// Validates --lock (finite, existing, given once) and applies --lock-mimic: every master of
  /// a mimic group not locked by --lock is locked at 0 when 0 is within its limits (or it has
  /// none), else at the middle of its range; one note per group.
  Locks(const urdf::ModelInterface& model, const Options& opt, std::vector<std::string>& notes);

  /// True when a joint moves nothing: fixed, locked, or a mimic of such a joint (chains
  /// followed). Side-effect free; a chain with a cycle or a missing joint is not rigid (so a
  /// --tip can leave it out; locked_value() reports it for a joint that is kept).
  bool rigid(const urdf::JointConstSharedPtr& j) const;

  /// The position a joint is locked at, if it is: directly, or as a mimic of a locked joint (or
  /// of a fixed one, at 0) through a chain of mimic joints (each step multiplier * q + offset).
  /// A mimic locked that way gets a note; the lock used is marked used. GenError for a cycle or
  /// a missing joint on the chain.
  std::optional<double> locked_value(const urdf::JointConstSharedPtr& j,
                                     std::vector<std::string>& notes);

  /// Locked by --lock or --lock-mimic itself (not as the mimic of a locked joint).
  bool locked_directly(const std::string& joint) const { return values_.count(joint) > 0; }
  /// One note per --lock that locked nothing in the selected tree.
  void report_unused(std::vector<std::string>& notes) const;

 private:
  void lock_mimic_groups(std::vector<std::string>& notes);

  const urdf::ModelInterface& model_;
  std::map<std::string, double> values_;  ///< joint -> position
  std::set<std::string> used_;            ///< locks that applied (or need no report)
};

/// A locked value must lie within the joint's limits (none for continuous joints or the
/// exporters' "no limits" [0, 0]).
void check_lock_range(const urdf::Joint& j, double value);

/// The links kept: the whole subtree of `root` without --tip; with --tip the root -> tip
/// chains together with every link rigidly attached to a kept link (their mass and frames
/// merge into it). Only movable subtrees are left out.
std::set<std::string> select_links(const urdf::ModelInterface& model,
                                   const urdf::LinkConstSharedPtr& root, const Options& opt,
                                   const Locks& locks);

/// Reports the movable subtree below `j` that the selection left out, with its mass in kg: a
/// warning when it hung from a moving body `moving` (the dynamics of the kept joints change), a
/// note when it hung from the fixed base (`moving` null: they do not) or has no mass.
void report_dropped(const UrdfModel& urdf, const urdf::Joint& j, const urdf::Link& parent,
                    const Body* moving, RobotDesc& out);

}  // namespace arbor::gen
