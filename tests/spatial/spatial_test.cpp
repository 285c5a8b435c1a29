// Spatial algebra: motion/force vectors, SE3 actions, cross products, rigid inertias, constant
// (zero-skipping) products and the per-body sparse actions, each against its 6x6 matrix form.
#include <gtest/gtest.h>

#include <arbor/spatial/body_ops.hpp>
#include <arbor/spatial/constant.hpp>
#include <arbor/spatial/inertia.hpp>
#include <arbor/spatial/motion.hpp>
#include <arbor/spatial/se3.hpp>
#include <random>

#include "../dynamics/random_robot.hpp"
#include "alloc_guard.hpp"

namespace {

using namespace arbor;
using namespace arbor::spatial;
using arbor::test::NoAllocScope;
using M6 = Mat6<double>;
using V6 = Vec6<double>;

std::mt19937 rng(3);
double uni() {
  return std::uniform_real_distribution<double>(-1, 1)(rng);
}
Vec3<double> rv3() {
  return Vec3<double>(uni(), uni(), uni());
}
Motion<double> rm() {
  return {rv3(), rv3()};
}
Force<double> rf() {
  return {rv3(), rv3()};
}
SE3<double> rse3() {
  const Eigen::Quaterniond q = Eigen::Quaterniond(uni(), uni(), uni(), uni()).normalized();
  return {q.toRotationMatrix(), rv3()};
}
Inertia<double> rin() {
  Mat3<double> A = Mat3<double>::Random();
  return Inertia<double>::FromMassComInertia(2.0 + uni(), rv3(),
                                             A * A.transpose() + Mat3<double>::Identity());
}

TEST(Spatial, CrossProductsMatchMatrices) {
  for (int t = 0; t < 20; ++t) {
    const Motion<double> m1 = rm(), m2 = rm();
    const Force<double> f = rf();
    Motion<double> c;
    Force<double> cf;
    double p;
    {
      NoAllocScope guard;
      c = cross(m1, m2);
      cf = cross(m1, f);
      p = dot(f, m2);
    }
    const M6 X = motion_cross_matrix(m1);
    EXPECT_LE((c.vector() - X * m2.vector()).norm(), 1e-14);
    EXPECT_LE((cf.vector() - (-X.transpose()) * f.vector()).norm(), 1e-14);
    EXPECT_NEAR(p, f.vector().dot(m2.vector()), 1e-14);
    // duality: <m x* f, m2> = -<f, m x m2>
    EXPECT_NEAR(dot(cross(m1, f), m2), -dot(f, cross(m1, m2)), 1e-13);
  }
}

TEST(Spatial, Se3ActionsMatchMatrices) {
  for (int t = 0; t < 20; ++t) {
    const SE3<double> X = rse3(), Y = rse3();
    const Motion<double> m = rm();
    const Force<double> f = rf();
    Motion<double> am, aim;
    Force<double> af, aif;
    SE3<double> XY, Xi;
    {
      NoAllocScope guard;
      am = X.act(m);
      aim = X.actInv(m);
      af = X.act(f);
      aif = X.actInv(f);
      XY = X * Y;
      Xi = X.inverse();
    }
    EXPECT_LE((am.vector() - X.toActionMatrix() * m.vector()).norm(), 1e-13);
    EXPECT_LE((af.vector() - X.toDualActionMatrix() * f.vector()).norm(), 1e-13);
    EXPECT_LE((X.act(aim).vector() - m.vector()).norm(), 1e-13);
    EXPECT_LE((X.act(aif).vector() - f.vector()).norm(), 1e-13);
    EXPECT_LE((XY.toActionMatrix() - X.toActionMatrix() * Y.toActionMatrix()).norm(), 1e-13);
    EXPECT_LE((Xi.toActionMatrix() - X.toActionMatrix().inverse()).norm(), 1e-12);
    // power is frame independent
    EXPECT_NEAR(dot(af, am), dot(f, m), 1e-13);
  }
}

TEST(Spatial, InertiaMatchesMatrix) {
  for (int t = 0; t < 20; ++t) {
    const Inertia<double> I = rin(), J = rin();
    const SE3<double> X = rse3();
    const Motion<double> m = rm();
    Force<double> h;
    Inertia<double> IX, IJ;
    {
      NoAllocScope guard;
      h = I * m;
      IX = I.se3Action(X);
      IJ = I + J;
    }
    EXPECT_LE((h.vector() - I.matrix() * m.vector()).norm(), 1e-13);
    // I in the parent frame: X* I X^-1
    const M6 expect = X.toDualActionMatrix() * I.matrix() * X.toActionMatrix().inverse();
    EXPECT_LE((IX.matrix() - expect).norm(), 1e-12);
    EXPECT_LE((IJ.matrix() - I.matrix() - J.matrix()).norm(), 1e-13);
    EXPECT_LE((I.matrix() - I.matrix().transpose()).norm(), 1e-14);
  }
}

struct ConstK {
  static constexpr double at(int r, int c) {
    constexpr double K[3][3] = {{0.0, -1.0, 0.5}, {1.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    return K[r][c];
  }
};

TEST(Spatial, ConstantProductsSkipZeros) {
  Mat3<double> K;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      K(r, c) = ConstK::at(r, c);
  const Vec3<double> x = rv3();
  const Mat3<double> M = Mat3<double>::Random();
  Vec3<double> y;
  Mat3<double> KM, MK;
  {
    NoAllocScope guard;
    y = cst::mul<double, ConstK>(x);
    KM = cst::mul_rows<double, ConstK, 3>(M);
    MK = cst::mul_cols<double, ConstK, 3>(M);
  }
  EXPECT_LE((y - K * x).norm(), 1e-15);
  EXPECT_LE((KM - K * M).norm(), 1e-15);
  EXPECT_LE((MK - M * K).norm(), 1e-15);
  static_assert(!cst::is_zero<ConstK>() && !cst::is_identity<ConstK>());
}

/// Every sparse per-body action of a random robot against the dense 6x6 forms.
template <class R, int i>
void check_body() {
  using B = BodyOps<R, i, double>;
  const double q = 2 * uni();
  const JointState<double> js = B::state(q);
  // dense liMi
  SE3<double> Pl;
  for (int r = 0; r < 3; ++r) {
    Pl.p[r] = R::joint_placement[i].p[r];
    for (int c = 0; c < 3; ++c)
      Pl.R(r, c) = R::joint_placement[i].R[r][c];
  }
  const Vec3<double> axis(R::joint_axis[i][0], R::joint_axis[i][1], R::joint_axis[i][2]);
  SE3<double> J = SE3<double>::Identity();
  if (B::revolute)
    J.R = Eigen::AngleAxisd(q, axis).toRotationMatrix();
  else
    J.p = q * axis;
  const SE3<double> X = Pl * J;
  const Motion<double> m = rm();
  const Force<double> f = rf();
  const Inertia<double> Y = rin();
  M6 A6 = M6::Random();
  A6 = (A6 * A6.transpose()).eval();
  Motion<double> mc;
  Force<double> fp;
  Inertia<double> Yp;
  SE3<double> l;
  {
    NoAllocScope guard;
    mc = B::motion_to_child(js, m);
    fp = B::force_to_parent(js, f);
    Yp = B::inertia_to_parent(js, Y);
    l.R = B::const_rot_jrot(js);
  }
  EXPECT_LE((mc.vector() - X.actInv(m).vector()).norm(), 1e-13) << "body " << i;
  EXPECT_LE((fp.vector() - X.act(f).vector()).norm(), 1e-13) << "body " << i;
  EXPECT_LE((Yp.matrix() - Y.se3Action(X).matrix()).norm(), 1e-12) << "body " << i;
  const M6 Xinv = X.inverse().toActionMatrix();
  EXPECT_LE((l.R - X.R).norm(), 1e-14) << "body " << i;
  // articulated inertia (block form) and its projection Y - U D^-1 U^T
  {
    const ArticulatedInertia<double> Ya = ArticulatedInertia<double>::from(A6);
    ArticulatedInertia<double> Yp2, Yproj;
    Force<double> U;
    {
      NoAllocScope guard;
      Yp2 = B::art_to_parent(js, Ya);
      B::art_S(Ya, U.f, U.n);
      Yproj = B::art_project_to_parent(js, Ya, U, 1.0 / B::ST(U));
    }
    EXPECT_LE((Yp2.matrix() - Xinv.transpose() * A6 * Xinv).norm(), 1e-11) << "body " << i;
    V6 Sv = V6::Zero();
    if (B::revolute)
      Sv.tail<3>() = axis;
    else
      Sv.head<3>() = axis;
    const V6 U6 = A6 * Sv;
    EXPECT_LE((U.vector() - U6).norm(), 1e-13);
    const M6 P = A6 - U6 * U6.transpose() / Sv.dot(U6);
    EXPECT_LE((Yproj.matrix() - Xinv.transpose() * P * Xinv).norm(), 1e-11) << "body " << i;
  }
  // motion subspace and cross_S
  const double x = uni();
  V6 S = V6::Zero();
  if (B::revolute)
    S.tail<3>() = axis;
  else
    S.head<3>() = axis;
  EXPECT_LE((B::S_times(x).vector() - S * x).norm(), 1e-15);
  EXPECT_NEAR(B::ST(f), S.dot(f.vector()), 1e-15);
  EXPECT_LE((B::cross_S(m, x).vector() - motion_cross_matrix(m) * S * x).norm(), 1e-14);
  // constant body inertia
  const Force<double> h = B::inertia_times(m);
  EXPECT_LE((h.vector() - B::inertia().matrix() * m.vector()).norm(), 1e-13);
  // the same actions on a block of L columns (the coordinate rows of a row-major 6 x L block),
  // each column against the dense forms
  {
    constexpr int L = 5;
    using Blk = Eigen::Matrix<double, 6, L, Eigen::RowMajor>;
    using Row = Eigen::Matrix<double, 1, L>;
    const Blk P = Blk::Random();   // motion columns [v; w], parent frame
    const Blk Fc = Blk::Random();  // force columns [f; n], body frame
    const Blk Q0 = Blk::Random();
    Blk Q = Q0;  // the forces carried to the parent are added to these
    const Row xr = Row::Random();
    Row v[3], w[3], st;
    {
      NoAllocScope guard;
      B::motion_to_child(js, rows_of<0>(P), rows_of<3>(P), v, w);
      B::add_S(v, w, xr);
      B::template force_to_parent<true>(js, rows_of<0>(Fc), rows_of<3>(Fc), rows_of<0>(Q),
                                        rows_of<3>(Q));
      st = B::ST(rows_of<0>(Fc), rows_of<3>(Fc));
    }
    for (int c = 0; c < L; ++c) {
      V6 mc6;
      for (int j = 0; j < 3; ++j) {
        mc6[j] = v[j][c];
        mc6[3 + j] = w[j][c];
      }
      const V6 m_ref = X.actInv(Motion<double>::from(P.col(c))).vector() + S * xr[c];
      EXPECT_LE((mc6 - m_ref).norm(), 1e-13) << "body " << i << " column " << c;
      const V6 f_ref = Q0.col(c) + X.act(Force<double>::from(Fc.col(c))).vector();
      EXPECT_LE((Q.col(c) - f_ref).norm(), 1e-13) << "body " << i << " column " << c;
      EXPECT_NEAR(st[c], S.dot(Fc.col(c)), 1e-14) << "body " << i << " column " << c;
    }
  }
  // articulated products with known zeros, and the projection added to a parent's inertia
  {
    const ArticulatedInertia<double> Ya = ArticulatedInertia<double>::from(A6);
    const Motion<double> c = B::cross_S(m, x);  // zero outside B::cross_S_nz
    const Force<double> Yc = art_times<B::cross_S_nz>(Ya, c);
    EXPECT_LE((Yc.vector() - A6 * c.vector()).norm(), 1e-13) << "body " << i;
    EXPECT_NEAR(dot_masked<B::cross_S_nz>(f, c), f.vector().dot(c.vector()), 1e-14);
    Force<double> U;
    B::art_S(Ya, U);
    const double Dinv = 1.0 / B::ST(U);
    const V6 U6 = A6 * S;
    const M6 Pr = Xinv.transpose() * (A6 - U6 * U6.transpose() * Dinv) * Xinv;
    M6 Y0 = M6::Random();
    Y0 = (Y0 + Y0.transpose()).eval();
    ArticulatedInertia<double> Yp = ArticulatedInertia<double>::from(Y0);
    B::add_art_projection(js, Ya, U, Dinv, Yp);
    EXPECT_LE((Yp.matrix() - (Y0 + Pr)).norm(), 1e-11) << "body " << i;
    if constexpr (B::parent >= 0) {
      using BP = BodyOps<R, B::parent, double>;
      B::template add_art_projection<BP>(js, Ya, U, Dinv, Yp);
      EXPECT_LE((Yp.matrix() - (BP::art_inertia().matrix() + Pr)).norm(), 1e-11) << "body " << i;
    }
  }
}

template <class R>
void check_robot_bodies() {
  [&]<int... Is>(std::integer_sequence<int, Is...>) {
    (check_body<R, Is>(), ...);
  }
  (std::make_integer_sequence<int, R::nb>{});
}

TEST(Spatial, BodyOpsMatchDenseForms) {
  check_robot_bodies<arbor::test::RandomRobot<11, 16>>();
  check_robot_bodies<arbor::test::RandomRobot<12, 16>>();
}

TEST(Spatial, FloatInstantiates) {
  const SE3<float> X{Mat3<float>::Identity(), Vec3<float>(1, 2, 3)};
  const Motion<float> m{Vec3<float>(1, 0, 0), Vec3<float>(0, 0, 1)};
  const Motion<float> r = X.actInv(X.act(m));
  EXPECT_LE((r.vector() - m.vector()).norm(), 1e-6f);
  const Inertia<float> I =
      Inertia<float>::FromMassComInertia(1.f, Vec3<float>(0.1f, 0, 0), Mat3<float>::Identity());
  EXPECT_LE(((I * m).vector() - I.matrix() * m.vector()).norm(), 1e-6f);
}

}  // namespace
