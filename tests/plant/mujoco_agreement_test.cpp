// MuJoCo (Debian's libmujoco-dev, its own URDF parser and its own dynamics) against arbor's
// generated robots at random states: forward dynamics qdd = aba(q, qd, tau) against mj_forward's
// qacc, the joint-space inertia crba(q) against mj_fullM, and the world placement of every moving
// link (arbor's operational frame of that name against MuJoCo's body). Armature, damping,
// frictionloss zero, contacts and limits off (examples/contour/mujoco_model.hpp). Independent
// parser, independent dynamics: a disagreement here is a finding about one of them.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <robots/atlas.hpp>
#include <robots/iiwa7.hpp>
#include <robots/kinova_gen3.hpp>
#include <robots/yumi_no_grippers.hpp>
#include "arbor/dynamics/aba.hpp"
#include "arbor/dynamics/crba.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "mujoco_model.hpp"

namespace {

namespace mj = contour::mujoco;

struct Errors {
  double qdd = 0, M = 0, pos = 0, rot = 0;  // relative (qdd, M), absolute (pos [m], rot)
  int links = 0;                            // moving links compared
};

/// Random states of robot R: q in [-pi, pi], qd in [-2, 2] rad/s, tau in [-20, 20] N m.
template <class R>
Errors compare(const char* urdf, int samples, unsigned seed) {
  mj::MujocoModel<R> m;
  std::string err;
  Errors e;
  const bool ok = m.load_file(std::string(ARBOR_ROBOTS_DIR) + "/" + urdf, {}, {}, err);
  EXPECT_TRUE(ok) << err;
  if (!ok)
    return e;
  static arbor::Data<R, double> d;
  using Vec = Eigen::Matrix<double, R::nv, 1>;
  using Mat = Eigen::Matrix<double, R::nv, R::nv>;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uq(-3.14159, 3.14159), uv(-2, 2), ut(-20, 20);
  for (int k = 0; k < samples; ++k) {
    Vec q, v, tau;
    for (int i = 0; i < R::nv; ++i) {
      q[i] = uq(rng);
      v[i] = uv(rng);
      tau[i] = ut(rng);
    }
    m.set_state(q, v);
    m.set_torque(tau);
    mj_forward(m.m, m.d);
    Vec a_mj;
    for (int i = 0; i < R::nv; ++i)
      a_mj[i] = m.a(i);
    const Vec a = arbor::aba<R>(d, q, v, tau);
    e.qdd = std::max(e.qdd, (a - a_mj).cwiseAbs().maxCoeff() / a.cwiseAbs().maxCoeff());
    Mat M_mj;
    m.mass_matrix(M_mj);
    const Mat M = arbor::crba<R>(d, q);
    e.M = std::max(e.M, (M - M_mj).cwiseAbs().maxCoeff() / M.cwiseAbs().maxCoeff());
    arbor::forward_kinematics<R>(d, q);
    e.links = 0;
    for (int f = 0; f < R::nf; ++f) {
      const std::string name(R::frames[std::size_t(f)].name);
      const int b = mj_name2id(m.m, mjOBJ_BODY, name.c_str());
      if (b <= 0 || R::frames[std::size_t(f)].body < 0)
        continue;  // fused into its parent by MuJoCo, or the fixed base
      ++e.links;
      const auto& X = arbor::frame_placement<R>(d, f);
      for (int i = 0; i < 3; ++i) {
        e.pos = std::max(e.pos, std::fabs(X.p[i] - m.d->xpos[3 * b + i]));
        for (int j = 0; j < 3; ++j)
          e.rot = std::max(e.rot, std::fabs(X.R(i, j) - m.d->xmat[9 * b + 3 * i + j]));
      }
    }
  }
  return e;
}

template <class R>
void check(const char* robot, const char* urdf) {
  const Errors e = compare<R>(urdf, 200, 36);
  std::printf(
      "%-18s nv %2d: max rel. error qdd %.2e, M %.2e; %d moving links: position %.2e m, "
      "rotation %.2e\n",
      robot, R::nv, e.qdd, e.M, e.links, e.pos, e.rot);
  EXPECT_LT(e.qdd, 1e-6) << robot;
  EXPECT_LT(e.M, 1e-6) << robot;
  EXPECT_EQ(e.links, R::nb) << robot;
  EXPECT_LT(e.pos, 1e-9) << robot;
  EXPECT_LT(e.rot, 1e-9) << robot;
}

TEST(MujocoAgreement, KinovaGen3) {
  check<arbor::robots::KinovaGen3>("kinova_gen3", "kinova_gen3.urdf");
}
TEST(MujocoAgreement, Iiwa7) {
  check<arbor::robots::Iiwa7>("iiwa7", "iiwa7.urdf");
}
TEST(MujocoAgreement, YumiNoGrippers) {
  check<arbor::robots::YumiNoGrippers>("yumi_no_grippers", "yumi_no_grippers.urdf");
}
TEST(MujocoAgreement, Atlas) {
  check<arbor::robots::Atlas>("atlas", "atlas.urdf");
}

}  // namespace
