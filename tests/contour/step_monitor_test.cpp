// The contour example's StepMonitor (examples/contour/step_monitor.hpp): the limits and the tunnel
// over every 1 ms plant step. Against a plain recorder of the plant's steps (every state the
// plant reached), and against the plant's own integration of s: at the sample's last step the
// monitor's s (from s0, sd0 and the held sdd) is the plant's s after the sample, so its tunnel
// error there is the one computed from the plant's end state. Two plants' models (nominal and
// with the payload) and both formulations' inputs.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "plant.hpp"
#include "step_monitor.hpp"
#include "task.hpp"

namespace contour {
namespace {

using Vq = VecN<double, nq>;

/// Every state the plant reached in one sample, and the monitor in front of it.
struct Recorder {
  std::vector<Vq> q, qd;
};

template <class P>
void check_one_sample(P& plant, const VecN<double, nu>& u, Formulation form) {
  const Reference ref = make_reference(0.2);
  StepMonitor monitor;
  Recorder rec;
  SubstepHook record{&rec, [](void* o, const Vq& q, const Vq& qd, const Vq&) {
                       static_cast<Recorder*>(o)->q.push_back(q);
                       static_cast<Recorder*>(o)->qd.push_back(qd);
                     }};
  monitor.begin(ref, plant.substep_dt(), plant.x[14], plant.x[15], u[7]);
  plant.step(form, u, monitor.hook(record));

  ASSERT_EQ(int(rec.q.size()), 20);  // 1 ms steps of a 20 ms sample
  EXPECT_EQ(monitor.steps(), 20);
  Vq qd_max_plain = Vq::Zero(), q_max_plain = Vq::Zero();
  for (std::size_t k = 0; k < rec.q.size(); ++k) {
    qd_max_plain = qd_max_plain.cwiseMax(rec.qd[k].cwiseAbs());
    q_max_plain = q_max_plain.cwiseMax(rec.q[k].cwiseAbs());
  }
  EXPECT_EQ(monitor.peaks().qd, qd_max_plain);
  EXPECT_EQ(monitor.peaks().q, q_max_plain);
  // the last step is the sample's end state; a delayed measurement reads the earlier steps
  EXPECT_EQ(rec.q.back(), Vq(plant.x.template head<nq>()));
  for (int back = 0; back < StepMonitor::kKeep; ++back) {
    EXPECT_EQ(monitor.q_before(back), rec.q[rec.q.size() - 1 - std::size_t(back)]);
    EXPECT_EQ(monitor.qd_before(back), rec.qd[rec.qd.size() - 1 - std::size_t(back)]);
  }
  // the tunnel error at the end, from the plant's own s and end effector: the peak bounds it
  const double e_end = (plant.ee_position() - p_ref(ref, plant.x[14])).norm();
  EXPECT_GE(monitor.peaks().e_p, e_end - 1e-12);
  // and the peak is attained at some step: recomputed independently at the step of the peak
  double e_plain = 0;
  arbor::Data<Robot, double> d;
  for (std::size_t k = 0; k < rec.q.size(); ++k) {
    const double t = double(k + 1) * plant.substep_dt();
    const double s = plant.x[14] - (h - t) * (plant.x[15] - u[7] * (h - t)) -
                     0.5 * u[7] * (h - t) * (h - t);  // s(t) backwards from the plant's end state
    arbor::forward_kinematics<Robot>(d, rec.q[k]);
    e_plain =
        std::fmax(e_plain, (arbor::frame_placement<Robot>(d, ee_frame).p - p_ref(ref, s)).norm());
  }
  EXPECT_NEAR(monitor.peaks().e_p, e_plain, 1e-12);
}

TEST(StepMonitor, PeaksOverEveryPlantStep) {
  static ArborPlant<Robot> nominal;
  static ArborPlant<PayloadRobot> payload;
  VecN<double, nu> u;
  u << 3, -20, 2, -8, 1, -2, 0.5, 4;  // torques and sdd: the arm falls and swings
  for (int sample = 0; sample < 5; ++sample) {
    nominal.x.setZero();
    nominal.x.head<nq>() = initial_q();
    nominal.x[14] = 0.1 * sample;
    nominal.x[15] = 0.05 * sample;
    for (int j = 0; j <= sample; ++j)  // a few samples in: the arm moves
      check_one_sample(nominal, u, Formulation::fd);
  }
  payload.x.setZero();
  payload.x.head<nq>() = initial_q();
  VecN<double, nu> qdd;
  qdd << 1, -2, 0.5, 1.5, -3, 2, 1, -1;  // OCP-ID: a computed-torque loop on accelerations
  for (int j = 0; j < 4; ++j)
    check_one_sample(payload, qdd, Formulation::id);
}

/// Without a reference the monitor keeps the joint peaks only; its hook calls the next one.
TEST(StepMonitor, ChainsTheNextHook) {
  static ArborPlant<Robot> plant;
  plant.x.setZero();
  plant.x.head<nq>() = initial_q();
  StepMonitor monitor;
  int calls = 0;
  SubstepHook count{&calls,
                    [](void* o, const Vq&, const Vq&, const Vq&) { ++*static_cast<int*>(o); }};
  VecN<double, nu> u = VecN<double, nu>::Zero();
  monitor.begin(make_reference(0.2), plant.substep_dt(), 0, 0, 0);
  plant.step(Formulation::fd, u, monitor.hook(count));
  EXPECT_EQ(calls, 20);
  EXPECT_GT(monitor.peaks().qd.maxCoeff(), 0);  // zero torque: the arm falls
}

/// A plant calls its torque law before every OCP-FD substep, k = 0 .. 19 in order, and applies
/// the law's torque (the inner loop's wiring).
TEST(TorqueLaw, CalledBeforeEveryStep) {
  static ArborPlant<Robot> plant;
  plant.x.setZero();
  plant.x.head<nq>() = initial_q();
  struct Calls {
    std::vector<int> k;
  } calls;
  TorqueLaw law{&calls, [](void* o, int k, Vq& tau) {
                  static_cast<Calls*>(o)->k.push_back(k);
                  tau *= 0.5;
                  tau[1] = -3.0 - k;  // a torque that changes per step
                }};
  VecN<double, nu> u;
  u << 4, 10, 2, 6, 1, 2, 0.5, 0;
  plant.step(Formulation::fd, u, SubstepHook{}, law);
  ASSERT_EQ(int(calls.k.size()), 20);
  for (int k = 0; k < 20; ++k)
    EXPECT_EQ(calls.k[std::size_t(k)], k);
  EXPECT_EQ(plant.tau_applied[1], -22.0);  // the last step's
  EXPECT_EQ(plant.tau_applied[0], 2.0);
  EXPECT_EQ(plant.tau_peak[1], 22.0);
  // OCP-ID runs its own computed-torque loop: no law call
  calls.k.clear();
  plant.step(Formulation::id, VecN<double, nu>::Zero(), SubstepHook{}, law);
  EXPECT_TRUE(calls.k.empty());
}

}  // namespace
}  // namespace contour
