// arbor-gen: the one mimic-chain walker (see mimic.hpp).
#include "mimic.hpp"

#include <set>

#include "generator.hpp"
#include "text.hpp"
#include "urdf_input.hpp"

namespace arbor::gen {

MimicChain walk_mimic_chain(const urdf::ModelInterface& model,
                            const urdf::JointConstSharedPtr& start,
                            const std::function<bool(const urdf::Joint&, std::size_t)>& stop) {
  MimicChain chain;
  std::set<std::string> seen;
  for (urdf::JointConstSharedPtr j = start;;) {
    const bool repeated = !seen.insert(j->name).second;
    chain.joints.push_back(j);
    if (repeated) {
      chain.end = MimicEnd::cycle;
      return chain;
    }
    if (stop(*j, chain.joints.size() - 1)) {
      chain.end = MimicEnd::stop;
      return chain;
    }
    if (!j->mimic) {
      chain.end = MimicEnd::master;
      return chain;
    }
    urdf::JointConstSharedPtr next = model.getJoint(j->mimic->joint_name);
    if (!next) {
      chain.end = MimicEnd::missing;
      return chain;
    }
    j = next;
  }
}

void throw_mimic_error(const MimicChain& chain) {
  const urdf::Joint& last = *chain.joints.back();
  if (chain.end == MimicEnd::cycle)
    throw GenError("joint " + quote(chain.joints.front()->name) +
                   ": its mimic joints form a cycle through " + quote(last.name));
  throw GenError(joint_what(last) + " mimics joint " + quote(last.mimic->joint_name) +
                 ", which does not exist");
}

std::map<std::string, std::vector<std::string>> mimic_groups(const urdf::ModelInterface& model) {
  std::map<std::string, std::vector<std::string>> groups;
  for (const auto& [name, joint] : model.joints_) {
    if (!joint->mimic)
      continue;
    const MimicChain chain =
        walk_mimic_chain(model, joint, [](const urdf::Joint&, std::size_t) { return false; });
    if (chain.end != MimicEnd::master)
      throw_mimic_error(chain);
    groups[chain.joints.back()->name].push_back(name);
  }
  return groups;
}

}  // namespace arbor::gen
