// The limits where the hardware checks them: a joint's velocity monitor and its drive's torque
// limit act at every plant step (1 ms), not at the controller's 20 ms samples. StepMonitor is
// called after every plant step (the plants' substep hook) with the state it reached and the
// torque applied, and keeps, over one sample, per joint max |qd_i| and max |q_i|, and the largest
// tunnel error |p_ee(q) - p_ref(s)|, s at the step from the sample's start and its held sdd (the
// plants integrate s exactly so). It also keeps the last kKeep steps' states: a measurement
// delayed by a few plant steps is read from them (ContourLoop, Options::delay_steps). Cost: one forward kinematics per plant step (20 per sample),
// outside the controller's timed phases.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "plant.hpp"
#include "task.hpp"

namespace contour {

/// The peaks of one sample over every plant step (see the top of this file).
struct StepPeaks {
  VecN<double, nq> qd = VecN<double, nq>::Zero();  ///< max |qd_i| over the plant steps
  VecN<double, nq> q = VecN<double, nq>::Zero();   ///< max |q_i| over the plant steps
  double e_p = 0;                                  ///< max tunnel error over the plant steps [m]
};

class StepMonitor {
 public:
  using Vq = VecN<double, nq>;
  static constexpr int kKeep = 16;  ///< the states of the last kKeep plant steps are kept

  /// Before a sample: the reference, the plant's step length, s and sd at the sample's start and
  /// the sdd the plant holds over it.
  void begin(const Reference& ref, double dt, double s0, double sd0, double sdd) {
    ref_ = &ref;
    dt_ = dt;
    s0_ = s0;
    sd0_ = sd0;
    sdd_ = sdd;
    step_ = 0;
    peaks_ = StepPeaks{};
  }

  /// After one plant step: the state it reached.
  void record(const Vq& q, const Vq& qd) {
    recent_q_[std::size_t(step_ % kKeep)] = q;
    recent_qd_[std::size_t(step_ % kKeep)] = qd;
    ++step_;
    peaks_.qd = peaks_.qd.cwiseMax(qd.cwiseAbs());
    peaks_.q = peaks_.q.cwiseMax(q.cwiseAbs());
    if (ref_ == nullptr)
      return;
    const double t = step_ * dt_;
    const double s = s0_ + sd0_ * t + 0.5 * sdd_ * t * t;
    arbor::forward_kinematics<Robot>(d_, q);
    const VecN<double, 3> p = arbor::frame_placement<Robot>(d_, ee_frame).p;
    peaks_.e_p = std::fmax(peaks_.e_p, (p - p_ref(*ref_, s)).norm());
  }

  /// The peaks since begin().
  const StepPeaks& peaks() const { return peaks_; }
  /// Plant steps since begin().
  int steps() const { return step_; }
  /// q and qd `back` plant steps before the last one recorded (0: the last; back < kKeep and
  /// back < steps()).
  const Vq& q_before(int back) const { return recent_q_[std::size_t((step_ - 1 - back) % kKeep)]; }
  const Vq& qd_before(int back) const {
    return recent_qd_[std::size_t((step_ - 1 - back) % kKeep)];
  }

  /// A hook that records into this monitor, then calls next (a plant's SubstepHook, e.g. the
  /// estimator's torque-rate observer): what ContourLoop passes to the plant.
  SubstepHook hook(SubstepHook next) {
    next_ = next;
    return {this, [](void* self, const Vq& q, const Vq& qd, const Vq& tau) {
              auto& m = *static_cast<StepMonitor*>(self);
              m.record(q, qd);
              m.next_(q, qd, tau);
            }};
  }

 private:
  arbor::Data<Robot, double> d_;
  const Reference* ref_ = nullptr;
  double dt_ = 0, s0_ = 0, sd0_ = 0, sdd_ = 0;
  int step_ = 0;
  StepPeaks peaks_;
  SubstepHook next_;
  std::array<Vq, kKeep> recent_q_{}, recent_qd_{};
};

}  // namespace contour
