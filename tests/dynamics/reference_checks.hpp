// Test body: a generated robot against the Pinocchio reference values (tests/data/reference).
// Tolerances (relative to max(1, largest |entry|) of the reference quantity):
//   rnea, gravity, nle, crba: 1e-9;  frame placements: 1e-9;
//   aba, minv: 1e-9 for the arms, 1e-8 scaled by cond(M) bound for Atlas (long chains, badly
//   conditioned M^-1, as the reference README warns).
#pragma once

#include <gtest/gtest.h>

#include <arbor/dynamics/dynamics.hpp>
#include <memory>
#include <string>

#include "alloc_guard.hpp"
#include "check_helpers.hpp"
#include "reference.hpp"

namespace arbor::test {

template <class R>
void check_reference(const std::string& file_name, double tol_fd) {
  constexpr int n = R::nv;
  using Vec = Eigen::Matrix<double, n, 1>;
  const ReferenceFile ref = load_reference(file_name);
  ASSERT_EQ(ref.nv, n);
  const std::vector<int> perm = joint_permutation<R>(ref);
  auto d = std::make_unique<Data<R, double>>();
  ASSERT_FALSE(ref.samples.empty());
  for (const ReferenceSample& s : ref.samples) {
    const Vec q = permute_vector(s.values.at("q"), perm);
    const Vec v = permute_vector(s.values.at("v"), perm);
    const Vec a = permute_vector(s.values.at("a"), perm);
    const Vec tau = permute_vector(s.values.at("tau"), perm);
    {
      NoAllocScope guard;
      rnea<R>(*d, q, v, a);
    }
    ARBOR_EXPECT_REL(d->tau, permute_vector(s.values.at("rnea"), perm), 1e-9);
    {
      NoAllocScope guard;
      gravity<R>(*d, q);
    }
    ARBOR_EXPECT_REL(d->tau, permute_vector(s.values.at("gravity"), perm), 1e-9);
    {
      NoAllocScope guard;
      nle<R>(*d, q, v);
    }
    ARBOR_EXPECT_REL(d->tau, permute_vector(s.values.at("nle"), perm), 1e-9);
    {
      NoAllocScope guard;
      crba<R>(*d, q);
    }
    ARBOR_EXPECT_REL(d->M, permute_matrix(s.values.at("crba"), perm), 1e-9);
    {
      NoAllocScope guard;
      aba<R>(*d, q, v, tau);
    }
    ARBOR_EXPECT_REL(d->ddq, permute_vector(s.values.at("aba"), perm), tol_fd);
    {
      NoAllocScope guard;
      minverse<R>(*d, q);
    }
    ARBOR_EXPECT_REL(d->Minv, permute_matrix(s.values.at("minv"), perm), tol_fd);
    {
      NoAllocScope guard;
      forward_kinematics<R>(*d, q);
      update_frame_placements<R>(*d);
    }
    int matched = 0;
    for (const auto& [link, X] : s.frames) {
      const int f = model::frame_index<R>(link);
      if (f < 0)
        continue;  // a link the generator dropped (none expected)
      ++matched;
      ARBOR_EXPECT_REL(d->oMf[f].matrix3x4(), X, 1e-9) << " frame " << link;
    }
    EXPECT_EQ(matched, int(s.frames.size())) << "every URDF link of the reference has a frame";
    EXPECT_EQ(matched, R::nf);
  }
}

}  // namespace arbor::test
