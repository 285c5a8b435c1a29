// arbor: compile-time tables of a robot's tree topology, computed once per robot type from its
// parent array (constexpr, O(nb^2) at compile time, nothing at run time): which bodies support
// which, each body's subtree range, and which joint pairs share a branch.
#pragma once

#include <array>
#include <cstddef>

namespace arbor::model {

namespace detail {
template <class R>
constexpr std::array<std::array<bool, R::nb>, R::nb> support_table() {
  std::array<std::array<bool, R::nb>, R::nb> t{};
  for (int i = 0; i < R::nb; ++i)
    for (int j = i; j >= 0; j = R::parent[j])
      t[i][j] = true;
  return t;
}
template <class R>
constexpr std::array<std::array<bool, R::nv>, R::nv> on_branch_table() {
  const auto s = support_table<R>();
  std::array<std::array<bool, R::nv>, R::nv> t{};
  for (int k = 0; k < R::nv; ++k)
    for (int j = 0; j < R::nv; ++j)
      t[k][j] = s[j][k] || s[k][j];
  return t;
}
}  // namespace detail

/// support<R>[i][j]: body j is body i or one of its ancestors (joint j moves body i).
template <class R>
inline constexpr std::array<std::array<bool, R::nb>, R::nb> support = detail::support_table<R>();

/// on_branch<R>[k][j]: joints k and j lie on one branch (one is an ancestor of the other, or
/// k == j). Inverse-dynamics derivatives are structurally zero for the other pairs.
template <class R>
inline constexpr std::array<std::array<bool, R::nv>, R::nv> on_branch =
    detail::on_branch_table<R>();

/// Largest body index in the subtree of body i (subtree members are all in [i, last]).
template <class R>
constexpr int subtree_last(int i) {
  int last = i;
  for (int j = i + 1; j < R::nb; ++j) {
    int p = R::parent[j];
    while (p > i)
      p = R::parent[p];
    if (p == i)
      last = j;
  }
  return last;
}

/// True when the subtree of body i is exactly the bodies [i, subtree_last(i)] (always so for
/// the generator's depth-first numbering; any topological order is allowed by the model).
template <class R>
constexpr bool subtree_contiguous(int i) {
  const int last = subtree_last<R>(i);
  for (int j = i + 1; j <= last; ++j) {
    int p = R::parent[j];
    while (p > i)
      p = R::parent[p];
    if (p != i)
      return false;
  }
  return true;
}

/// Bodies in the tree of body i: the bodies below the same root joint as i.
template <class R>
constexpr int root_tree_size(int i) {
  auto root = [](int j) {
    while (R::parent[j] >= 0)
      j = R::parent[j];
    return j;
  };
  int count = 0;
  for (int j = 0; j < R::nb; ++j)
    count += root(j) == root(i) ? 1 : 0;
  return count;
}

/// Bodies in the largest tree of the forest (the bodies below one root joint): the depth of work
/// an algorithm that carries a column up the tree can face (YuMi: 7 of 14, two arms; Atlas: 18).
template <class R>
constexpr int largest_root_tree() {
  int largest = 0;
  for (int i = 0; i < R::nb; ++i)
    largest = root_tree_size<R>(i) > largest ? root_tree_size<R>(i) : largest;
  return largest;
}

}  // namespace arbor::model
