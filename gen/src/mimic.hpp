// arbor-gen: mimic chains (joint j mimics k, which mimics ... a master). Every place that follows
// such a chain uses walk_mimic_chain, so a chain that loops or names a missing joint is detected
// in one place and reported with one message. O(chain length) per walk.
#pragma once

#include <urdf_parser/urdf_parser.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace arbor::gen {

/// How a walk along a mimic chain ended.
enum class MimicEnd {
  stop,     ///< the stop predicate held at joints.back()
  master,   ///< joints.back() mimics nothing
  cycle,    ///< joints.back() was met before: the chain loops
  missing,  ///< joints.back() mimics a joint that does not exist
};

struct MimicChain {
  std::vector<urdf::JointConstSharedPtr> joints;  ///< the joints walked, the start first
  MimicEnd end = MimicEnd::master;
};

/// Walks start -> the joint it mimics -> ..., asking stop(joint, depth) of each joint (the start
/// at depth 0) before following its <mimic>. Never throws: callers that cannot ignore a cycle or
/// a missing joint pass the chain to throw_mimic_error.
MimicChain walk_mimic_chain(const urdf::ModelInterface& model,
                            const urdf::JointConstSharedPtr& start,
                            const std::function<bool(const urdf::Joint&, std::size_t)>& stop);

/// The GenError for a chain that ended in a cycle or at a missing joint.
[[noreturn]] void throw_mimic_error(const MimicChain& chain);

/// The mimic groups of a model: each master (a joint mimicking nothing that others mimic,
/// directly or through a chain) with the mimic joints that follow it, in name order. GenError
/// for a cycle or a missing joint anywhere.
std::map<std::string, std::vector<std::string>> mimic_groups(const urdf::ModelInterface& model);

}  // namespace arbor::gen
