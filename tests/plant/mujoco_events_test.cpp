// The MuJoCo plant's events in the middle of a task (examples/contour/mujoco_plant.hpp): a payload
// attached and released at given times, and a push on the forearm. Against arbor's plant
// (plant.hpp's ArborPlant: arbor's aba + RK4 at 1 ms, on the nominal Gen3 or on the Gen3 with the
// 0.5 kg point mass, PayloadRobot, whose inertia arbor's own algebra forms): over every sample the
// MuJoCo plant moves as arbor's plant of the model that holds at that time does, from the same
// state, and not as the other one. A push's one step moves qd by dt M(q)^-1 J(q)^T F, J the
// forearm's centre of mass's Jacobian by central differences of arbor's forward kinematics.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <string>

#include "arbor/dynamics/crba.hpp"
#include "mujoco_plant.hpp"
#include "plant.hpp"

namespace contour {
namespace {

using Vq = VecN<double, nq>;

VecN<double, nu> holding_torque() {
  static arbor::Data<Robot, double> d;
  VecN<double, nu> u = VecN<double, nu>::Zero();
  u.head<nq>() = arbor::rnea<Robot>(d, initial_q(), Vq::Zero(), Vq::Zero());  // nominal gravity
  u[0] += 2;  // and a swing about the base
  return u;
}

TEST(MujocoEvents, PayloadAttachedAndReleased) {
  MujocoPlantOptions o;
  o.urdf = std::string(ARBOR_ROBOTS_DIR) + "/kinova_gen3.urdf";
  o.payload = PayloadRobot::payload;
  o.payload_on = 0.04;  // samples 2 and 3 (0.04 .. 0.08 s) carry it
  o.payload_off = 0.08;
  static MujocoPlant mj;
  std::string err;
  ASSERT_TRUE(mj.init(o, err)) << err;
  static ArborPlant<Robot> nominal;
  static ArborPlant<PayloadRobot> payload;
  const VecN<double, nu> u = holding_torque();
  mj.x.setZero();
  mj.x.head<nq>() = initial_q();
  for (int k = 0; k < 6; ++k) {
    const bool attached = k == 2 || k == 3;
    nominal.x = mj.x;
    payload.x = mj.x;
    nominal.step(Formulation::fd, u);
    payload.step(Formulation::fd, u);
    mj.step(Formulation::fd, u);
    EXPECT_EQ(mj.payload_attached(), attached) << "sample " << k;
    const auto& same = attached ? payload.x : nominal.x;
    const auto& other = attached ? nominal.x : payload.x;
    EXPECT_LE((mj.x.head<2 * nq>() - same.head<2 * nq>()).cwiseAbs().maxCoeff(), 1e-7)
        << "sample " << k;
    EXPECT_GE((mj.x.head<2 * nq>() - other.head<2 * nq>()).cwiseAbs().maxCoeff(), 1e-4)
        << "sample " << k;  // the payload is felt: the check above can fail
  }
  EXPECT_NEAR(mj.time(), 0.12, 1e-12);
}

/// The world position of the centre of mass of arbor's body b at q.
VecN<double, 3> com_position(arbor::Data<Robot, double>& d, int frame, const Vq& q) {
  arbor::forward_kinematics<Robot>(d, q);
  const auto& f = Robot::frames[std::size_t(frame)];
  const auto oMf = arbor::frame_placement<Robot>(d, frame);
  Eigen::Matrix3d Rf;
  Eigen::Vector3d pf, c;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      Rf(i, j) = f.placement.R[i][j];
    pf[i] = f.placement.p[i];
    c[i] = Robot::body_inertia[std::size_t(f.body)].com[i];
  }
  const Eigen::Matrix3d Rb = Eigen::Matrix3d(oMf.R) * Rf.transpose();  // the body's placement
  const Eigen::Vector3d pb = Eigen::Vector3d(oMf.p) - Rb * pf;
  return pb + Rb * c;
}

TEST(MujocoEvents, PushOnTheForearm) {
  int frame = -1;
  for (int f = 0; f < Robot::nf; ++f)
    if (Robot::frames[std::size_t(f)].name == "forearm_link")
      frame = f;
  ASSERT_GE(frame, 0);
  MujocoPlantOptions o;
  o.urdf = std::string(ARBOR_ROBOTS_DIR) + "/kinova_gen3.urdf";
  static MujocoPlant pushed, unpushed;
  std::string err;
  ASSERT_TRUE(unpushed.init(o, err)) << err;
  o.push_at = 0;
  o.push_force = 10;
  o.push_duration = 1e-3;  // the first MuJoCo step only
  ASSERT_TRUE(pushed.init(o, err)) << err;
  Vq q = initial_q();
  q[1] += 0.3;
  q[3] -= 0.4;  // the forearm off the vertical
  const VecN<double, nu> u = holding_torque();
  Vq first_pushed, first_free;
  struct First {
    Vq* qd;
    int n = 0;
  } a{&first_pushed}, b{&first_free};
  const auto record = [](void* o, const Vq&, const Vq& qd, const Vq&) {
    auto& f = *static_cast<First*>(o);
    if (f.n++ == 0)
      *f.qd = qd;
  };
  for (MujocoPlant* p : {&pushed, &unpushed}) {
    p->x.setZero();
    p->x.head<nq>() = q;
  }
  pushed.step(Formulation::fd, u, SubstepHook{&a, record});
  unpushed.step(Formulation::fd, u, SubstepHook{&b, record});
  // dt M^-1 J^T F, J of the forearm's centre of mass by central differences
  static arbor::Data<Robot, double> d;
  Eigen::Matrix<double, 3, nq> J;
  for (int i = 0; i < nq; ++i) {
    Vq qp = q, qm = q;
    qp[i] += 1e-6;
    qm[i] -= 1e-6;
    J.col(i) = (com_position(d, frame, qp) - com_position(d, frame, qm)) / 2e-6;
  }
  const Eigen::Matrix<double, nq, nq> M = arbor::crba<Robot>(d, q);
  const Vq expected = 1e-3 * M.ldlt().solve(J.transpose() * Eigen::Vector3d(10, 0, 0));
  const Vq got = first_pushed - first_free;
  ASSERT_GT(expected.norm(), 1e-3);
  EXPECT_LE((got - expected).norm(), 2e-2 * expected.norm()) << got.transpose() << "\n"
                                                             << expected.transpose();
}

}  // namespace
}  // namespace contour
