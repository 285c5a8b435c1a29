// arbor-gen: locks and the kept links (see selection.hpp).
#include "selection.hpp"

#include <cmath>
#include <sstream>

#include "mimic.hpp"
#include "text.hpp"
#include "urdf_input.hpp"

namespace arbor::gen {

Locks::Locks(const urdf::ModelInterface& model, const Options& opt, std::vector<std::string>& notes)
    : model_(model) {
  for (const auto& [joint, value] : opt.locks) {
    if (!std::isfinite(value))
      throw GenError("--lock " + joint + ": value is not finite");
    if (!model_.getJoint(joint))
      throw GenError("--lock " + joint + ": no joint of that name");
    if (!values_.emplace(joint, value).second)
      throw GenError("--lock " + joint + ": given more than once");
  }
  if (opt.lock_mimic)
    lock_mimic_groups(notes);
}

void Locks::lock_mimic_groups(std::vector<std::string>& notes) {
  for (const auto& [master, members] : mimic_groups(model_)) {
    std::string list;
    for (const auto& m : members)
      list += (list.empty() ? "" : ", ") + m;
    const urdf::Joint& j = *model_.getJoint(master);
    if (j.type == urdf::Joint::FIXED) {
      notes.push_back("--lock-mimic: " + list + " follow fixed joint " + master +
                      " (at 0): locked");
      continue;
    }
    auto given = values_.find(master);
    if (given != values_.end()) {
      notes.push_back("--lock-mimic: " + master + " locked at " + fmt(given->second) +
                      " by --lock, with its mimic joints " + list);
      continue;
    }
    double value = 0;
    std::string why = "its zero";
    if (j.type != urdf::Joint::CONTINUOUS && j.limits &&
        !(j.limits->lower == 0 && j.limits->upper == 0) &&
        (j.limits->lower > 0 || j.limits->upper < 0)) {
      value = 0.5 * (j.limits->lower + j.limits->upper);
      why = "the middle of its range [" + fmt(j.limits->lower) + ", " + fmt(j.limits->upper) + "]";
    }
    values_.emplace(master, value);
    used_.insert(master);  // a master outside the selection is no user error
    notes.push_back("--lock-mimic: locked " + master + " at " + fmt(value) + " (" + why +
                    ") with its mimic joints " + list);
  }
}

bool Locks::rigid(const urdf::JointConstSharedPtr& j) const {
  const MimicChain chain = walk_mimic_chain(model_, j, [&](const urdf::Joint& k, std::size_t) {
    return k.type == urdf::Joint::FIXED || values_.count(k.name) > 0;
  });
  return chain.end == MimicEnd::stop;
}

std::optional<double> Locks::locked_value(const urdf::JointConstSharedPtr& j,
                                          std::vector<std::string>& notes) {
  const MimicChain chain =
      walk_mimic_chain(model_, j, [&](const urdf::Joint& k, std::size_t depth) {
        return values_.count(k.name) > 0 || (k.type == urdf::Joint::FIXED && depth > 0);
      });
  if (chain.end == MimicEnd::cycle || chain.end == MimicEnd::missing)
    throw_mimic_error(chain);
  if (chain.end != MimicEnd::stop)
    return std::nullopt;
  const urdf::Joint& held = *chain.joints.back();
  double value = 0;  // a fixed joint's position
  if (auto it = values_.find(held.name); it != values_.end()) {
    used_.insert(held.name);
    value = it->second;
  }
  for (std::size_t k = chain.joints.size() - 1; k-- > 0;)
    value = chain.joints[k]->mimic->multiplier * value + chain.joints[k]->mimic->offset;
  if (chain.joints.size() > 1)
    notes.push_back("joint " + j->name + " mimics locked joint " + chain.joints[1]->name +
                    ": locked at " + std::to_string(value));
  return value;
}

void Locks::report_unused(std::vector<std::string>& notes) const {
  for (const auto& [joint, value] : values_) {
    if (!used_.count(joint))
      notes.push_back("--lock " + joint + ": joint is outside the selected tree; ignored");
  }
}

void check_lock_range(const urdf::Joint& j, double value) {
  if (j.type == urdf::Joint::CONTINUOUS || !j.limits)
    return;
  const double lo = j.limits->lower, hi = j.limits->upper;
  if (lo == 0 && hi == 0)
    return;  // exporters' "no limits"
  if (value < lo || value > hi) {
    std::ostringstream s;
    s << "--lock " << j.name << "=" << value << ": outside the joint's limits [" << lo << ", " << hi
      << "]";
    throw GenError(s.str());
  }
}

std::set<std::string> select_links(const urdf::ModelInterface& model,
                                   const urdf::LinkConstSharedPtr& root, const Options& opt,
                                   const Locks& locks) {
  std::set<std::string> selected;
  if (opt.tips.empty()) {
    std::vector<urdf::LinkConstSharedPtr> stack{root};
    while (!stack.empty()) {
      auto l = stack.back();
      stack.pop_back();
      selected.insert(l->name);
      for (const auto& child : l->child_links)
        stack.push_back(child);
    }
    return selected;
  }
  for (const std::string& tip : opt.tips) {
    urdf::LinkConstSharedPtr l = model.getLink(tip);
    if (!l)
      throw GenError("--tip " + tip + ": no link of that name");
    std::vector<std::string> chain;
    for (; l && l->name != root->name; l = l->getParent())
      chain.push_back(l->name);
    if (!l)
      throw GenError("--tip " + tip + ": link is not below the root link " + quote(root->name));
    selected.insert(root->name);
    selected.insert(chain.begin(), chain.end());
  }
  std::vector<std::string> stack(selected.begin(), selected.end());
  while (!stack.empty()) {
    const auto l = model.getLink(stack.back());
    stack.pop_back();
    for (const auto& j : l->child_joints)
      if (locks.rigid(j) && selected.insert(j->child_link_name).second)
        stack.push_back(j->child_link_name);
  }
  return selected;
}

void report_dropped(const UrdfModel& urdf, const urdf::Joint& j, const urdf::Link& parent,
                    const Body* moving, RobotDesc& out) {
  const urdf::ModelInterface& model = urdf.model();
  double mass = 0;
  std::string massive;
  std::vector<urdf::LinkConstSharedPtr> stack{model.getLink(j.child_link_name)};
  while (!stack.empty()) {
    const auto l = stack.back();
    stack.pop_back();
    if (l->inertial && l->inertial->mass > 0) {
      mass += l->inertial->mass;
      massive += (massive.empty() ? "" : ", ") + l->name + " " + fmt(l->inertial->mass) + " kg";
    }
    const auto kids = urdf.ordered_children(*l);  // pushed last first: listed in document order
    for (auto k = kids.rbegin(); k != kids.rend(); ++k)
      stack.push_back(model.getLink((*k)->child_link_name));
  }
  const std::string what = "--tip: " + joint_what(j) + " below link " + quote(parent.name) +
                           " is not on a chain to a tip: its subtree is dropped";
  if (mass == 0) {
    out.notes.push_back(what + " (0 kg: no link below it has mass)");
  } else if (!moving) {
    out.notes.push_back(what + " with " + fmt(mass) + " kg (" + massive +
                        "), which hung from the fixed base: the dynamics are unchanged");
  } else {
    const std::string lock =
        j.mimic ? j.mimic->joint_name + "=VALUE (it mimics that joint) or --lock-mimic"
                : j.name + "=VALUE";
    out.warnings.push_back(what + ", and moving body " + quote(moving->link) + " (joint " +
                           quote(moving->joint) + ") loses " + fmt(mass) + " kg (" + massive +
                           "). Keep the mass with --lock " + lock +
                           ", or name a link below it with --tip");
  }
}

}  // namespace arbor::gen
