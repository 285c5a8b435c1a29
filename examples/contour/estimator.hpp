// What the contour controller is told of the plant (Estimator): the measured state with
// Gaussian noise (Options::noise on q, 10x on qd), optionally filtered against the plan's
// prediction (Options::state_filter), and the generalized-momentum observer's estimate of the
// joint torque the controller's model lacks (Options::observer; arbor/nmpc/momentum_observer.hpp),
// updated after every plant substep (the torque loop's rate) or once per sample. Cost per sample:
// 2 nq normal draws per measurement with noise; one observer update (an RNEA-like pass) per
// update; nothing else.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>

#include "arbor/nmpc/momentum_observer.hpp"
#include "options.hpp"
#include "plant.hpp"
#include "task.hpp"

namespace contour {

class Estimator {
 public:
  using Vx = VecN<double, nx>;
  using Vq = VecN<double, nq>;
  using Observer = arbor::nmpc::MomentumObserver<Robot, double>;

  explicit Estimator(const Options& o) : options_(o), rng_(o.seed) {}

  /// The observer at rest at q0 with gain Options::observer_gain, sampled every substep_dt (the
  /// plant's substep) or every h (Options::observer_plant_rate off).
  void reset(const Vq& q0, double substep_dt) {
    obs_.set_gain(options_.observer_gain, options_.observer_plant_rate ? substep_dt : h);
    (void)obs_.reset(q0, Vq::Zero());
  }

  /// The hook a plant calls after each substep: the observer's update from the substep's noisy
  /// measurement when it runs at the plant's rate, else nothing.
  SubstepHook substep_hook() {
    if (!fast())
      return {};
    return {this, [](void* self, const Vq& q, const Vq& qd, const Vq& tau) {
              auto& e = *static_cast<Estimator*>(self);
              Vq qm = q, vm = qd;
              e.add_noise(qm, vm);
              (void)e.obs_.update(qm, vm, tau);
            }};
  }

  /// The measurement of the plant's state x at the end of a sample (noise on q, qd); the
  /// observer's once-per-sample update from it with tau_held, the torque held over the sample.
  Vx measure(const Vx& x, const Vq& tau_held) {
    Vx meas = x;
    Vq qm = meas.head<nq>(), vm = meas.segment<nq>(nq);
    add_noise(qm, vm);
    meas.head<nq>() = qm;
    meas.segment<nq>(nq) = vm;
    if (options_.observer && !fast())
      (void)obs_.update(meas.head<nq>(), meas.segment<nq>(nq), tau_held);
    return meas;
  }

  /// The state filter (Options::state_filter > 0): meas's q, qd become prediction + state_filter
  /// (meas - prediction), the prediction being the last plan's x_1.
  void filter(Vx& meas, const Vx& prediction) const {
    if (options_.state_filter <= 0)
      return;
    const double a = options_.state_filter;
    meas.head<2 * nq>() =
        prediction.head<2 * nq>() + a * (meas - prediction).template head<2 * nq>();
  }

  /// A noisy reading of the plant's q, qd at a plant step (Options::noise), and the observer's
  /// update from it when it runs at the plant's rate: what ContourLoop's torque-rate inner loop
  /// reads at every step (instead of substep_hook()).
  void sense_step(Vq& q, Vq& v, const Vq& tau) {
    add_noise(q, v);
    if (fast())
      (void)obs_.update(q, v, tau);
  }
  /// A noisy reading of q, qd (Options::noise), nothing else.
  void sense(Vq& q, Vq& v) { add_noise(q, v); }

  /// The observer runs (Options::observer).
  bool observing() const { return options_.observer; }
  /// Its estimate d of the missing joint torque.
  const Vq& estimate() const { return obs_.estimate(); }
  const Observer& observer() const { return obs_; }
  /// Its model (the controller's: a declared payload goes here too).
  arbor::Data<Robot, double>& model() { return obs_.data(); }

 private:
  bool fast() const { return options_.observer && options_.observer_plant_rate; }

  /// Measurement noise (Options::noise on q, 10x on qd).
  void add_noise(Vq& q, Vq& v) {
    if (options_.noise <= 0)
      return;
    std::normal_distribution<double> n(0.0, options_.noise);
    for (int i = 0; i < nq; ++i) {
      q[i] += n(rng_);
      v[i] += 10 * n(rng_);
    }
  }

  Options options_;
  std::mt19937 rng_;
  Observer obs_{20.0, h};
};

}  // namespace contour
