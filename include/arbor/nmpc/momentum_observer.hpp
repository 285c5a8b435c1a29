// arbor::nmpc: the generalized-momentum observer (De Luca & Mattone 2003, the disturbance
// observer of robotics practice): an estimate d_hat of the joint torque the model does not
// explain (a payload, friction, damping, a contact), from the applied torque tau and the measured
// q, qd only (no acceleration). With p = M(q) qd, Lagrange's equations give
//   p' = tau + C(q, qd)' qd - g(q) + d,
// and the observer is the first-order filter
//   d_hat = K (p - p(0) - integral(tau + C' qd - g + d_hat)),   i.e. d_hat' = K (d - d_hat):
// one gain K [1/s], the bandwidth; a step of d is tracked as d (1 - e^(-K t)).
//
// Discretisation (sample time dt, tau held over each interval as the controller applies it):
// the momentum balance of the last interval gives the measured mean disturbance
//   d_k = (p_k - p_{k-1}) / dt - tau - (beta_{k-1} + beta_k) / 2,   beta = C' qd - g
// (tau exact under a zero-order hold, beta by the trapezoid rule: error O(dt^2) beta''), and
// the filter is discretised exactly for a disturbance constant over the interval:
//   d_hat_k = d_hat_{k-1} + (1 - e^(-K dt)) (d_k - d_hat_{k-1}).
// A constant d is then tracked as d (1 - e^(-K k dt)) at the samples, for any K dt (no
// stability limit on the gain; K dt >> 1 makes d_hat the last interval's mean). Run it at the
// rate at which tau is held: the controller's sample time, or the plant's (the torque loop's)
// rate if the update can run there (examples/contour runs it per plant step, 1 ms).
//
// C' qd without C: C' qd = dT/dq for the kinetic energy T = qd' M(q) qd / 2, and the symmetric
// part of d tau / d qd gives it exactly: with tau_ID(q, qd, 0) = C qd + g (quadratic in qd),
//   C' qd = (d tau/d qd)' qd / 2,   C qd = (d tau/d qd) qd / 2,   so
//   beta = C' qd - g = ((d tau/d qd) + (d tau/d qd)') qd / 2 - tau_ID(q, qd, 0).
// One rnea_derivatives sweep at (q, qd, 0) returns tau_ID, d tau/d qd and M (d tau/d a): the
// whole update is that sweep (Kinova Gen3: 7 931 instructions, bench/RESULTS.md) plus O(n^2)
// (M qd and the symmetric product). Its workspaces (one Data, one DerivativeData) are members:
// static memory, sizeof(MomentumObserver<Gen3, double>) is about 17 KB.
//
// When it helps, when it cannot (docs/nmpc.md): an unmodelled torque that varies slower than
// the bandwidth K (a payload's weight, joint damping at slowly varying speed, a steady contact)
// is estimated and, as a stage parameter of the OCP (FD(q, qd, tau + d_hat)), compensated: the
// controller becomes offset-free for it. A disturbance faster than K (an impact, friction's sign
// change at a velocity reversal, a payload's inertial torque in a fast motion) is seen late and
// low-pass filtered: the estimate lags by about 1/K and the plan assumes d constant over its
// horizon. Measurement noise on qd enters d_k as M (noise change) / dt: K trades noise against
// bandwidth.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "arbor/core/config.hpp"
#include "arbor/derivatives/derivative_data.hpp"
#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/dynamics/data.hpp"

namespace arbor::nmpc {

/// Generalized-momentum disturbance observer of robot R at Scalar (see the top of this file).
///   MomentumObserver<R> obs(gain, dt);       // static storage: it holds its RBD workspaces
///   obs.reset(q, qd);                        // at the first measurement (d_hat = 0)
///   loop: apply tau for dt; measure q, qd; obs.update(q, qd, tau); use obs.estimate()
template <Robot R, class Scalar = double>
class MomentumObserver {
 public:
  static constexpr int nv = R::nv;  ///< joints
  using Vq = VecN<Scalar, R::nq>;   ///< a configuration
  using Vv = VecN<Scalar, nv>;      ///< a velocity, torque or disturbance

  /// gain K [1/s] (> 0) and sample time dt [s] (> 0).
  MomentumObserver(Scalar gain, Scalar dt) { set_gain(gain, dt); }

  /// Gain K and sample time dt (both > 0); the estimate is kept.
  void set_gain(Scalar gain, Scalar dt) {
    ARBOR_ASSERT(gain > Scalar(0) && dt > Scalar(0), "observer gain and sample time must be > 0");
    gain_ = gain;
    dt_ = dt;
    alpha_ = Scalar(1) - std::exp(-gain * dt);
  }
  Scalar gain() const { return gain_; }
  Scalar dt() const { return dt_; }
  /// The filter's weight per update, 1 - e^(-K dt).
  Scalar alpha() const { return alpha_; }

  /// Starts at the measured (q, qd) with the estimate d0 (default zero). False (nothing
  /// changed) when an input is not finite.
  bool reset(const Vq& q, const Vv& qd, const Vv& d0 = Vv::Zero()) {
    if (!q.allFinite() || !qd.allFinite() || !d0.allFinite())
      return false;
    Vv p, beta;
    momentum_terms(q, qd, p, beta);
    if (!p.allFinite() || !beta.allFinite())
      return false;
    p_ = p;
    beta_ = beta;
    d_ = d0;
    last_ = Vv::Zero();
    started_ = true;
    return true;
  }

  /// One update after tau was applied (held) for dt since the last reset()/update(), at the
  /// newly measured (q, qd). Returns false (the estimate and the stored momentum unchanged) when
  /// an input or the result is not finite, or before reset().
  bool update(const Vq& q, const Vv& qd, const Vv& tau) {
    if (!started_ || !q.allFinite() || !qd.allFinite() || !tau.allFinite())
      return false;
    Vv p, beta;
    momentum_terms(q, qd, p, beta);
    const Vv meas = (p - p_) / dt_ - tau - Scalar(0.5) * (beta_ + beta);
    const Vv d = d_ + alpha_ * (meas - d_);
    if (!d.allFinite())
      return false;
    p_ = p;
    beta_ = beta;
    last_ = meas;
    d_ = d;
    return true;
  }

  /// The disturbance estimate d_hat (joint torques; zero before the first update).
  const Vv& estimate() const { return d_; }
  /// The last interval's measured mean disturbance d_k (unfiltered).
  const Vv& measured() const { return last_; }
  /// The generalized momentum M(q) qd at the last reset()/update().
  const Vv& momentum() const { return p_; }
  /// beta = C(q, qd)' qd - g(q) at the last reset()/update().
  const Vv& beta() const { return beta_; }
  /// Whether reset() has succeeded.
  bool started() const { return started_; }
  /// The observer's model: a payload known to the controller goes here too (set_payload,
  /// dynamics/payload.hpp), or the observer reports it as a disturbance. Set it before reset().
  Data<R, Scalar>& data() { return data_; }

  /// p = M(q) qd and beta = C(q, qd)' qd - g(q), exactly, from one rnea_derivatives sweep at
  /// (q, qd, 0) (see the top of this file).
  void momentum_terms(const Vq& q, const Vv& qd, Vv& p, Vv& beta) {
    rnea_derivatives<R>(data_, deriv_, q, qd, Vv::Zero());
    const auto& Dv = deriv_.dtau_dv;
    p.noalias() = data_.M * qd;
    const Vv a = Dv * qd;
    const Vv b = Dv.transpose() * qd;
    beta = Scalar(0.5) * (a + b) - data_.tau;
  }

 private:
  Data<R, Scalar> data_;
  DerivativeData<R, Scalar> deriv_;
  Scalar gain_ = 1, dt_ = 1, alpha_ = 0;
  Vv p_ = Vv::Zero();     ///< momentum at the last update
  Vv beta_ = Vv::Zero();  ///< beta at the last update
  Vv d_ = Vv::Zero();     ///< the estimate
  Vv last_ = Vv::Zero();  ///< the last interval's measured disturbance
  bool started_ = false;
};

}  // namespace arbor::nmpc
