// arbor::nmpc: the torque-rate inner loop between two NMPC samples (issue 59): a firmware's
// fast interrupt (1 kHz) calls it with the measured state x at time t since the sample's
// measurement and gets
//   u(t) = clamp(u_0 + K_0 (x - x_pred(t)) + G (d(t) - d_0), lb, ub),
//   x_pred(t) = x_0 + (t / T) (x_1 - x_0)      (t clamped to [0, T])
// with u_0, x_0, x_1 the plan of the last feedback(), K_0 its QP's local feedback gain of stage 0
// (Nmpc::feedback_gain: the Riccati gain on the QP's final working set, zero rows for inputs on a
// bound), T the duration of stage 0, d(t) a disturbance estimate updated at the same rate (the
// MomentumObserver's, nmpc/momentum_observer.hpp; its value d_0 at the sample is what the plan
// already compensates through its stage parameter) and G the map of the estimate into the inputs
// (default: -I on the first ND inputs, the joint torques, which cancels the estimate's change).
//
// Why x_pred is the interpolation of x_0 and x_1: the plan moves during the sample, and
// K_0 (x - x_0) would push the state back to where the sample started (at 1 rad/s and
// T = 20 ms, 0.02 rad of position error by the end of the sample). Under the held u_0 the plan's
// x(t) = x_0 + t f(x_0, u_0) + O(t^2): the chord from x_0 to x_1 is exact at both ends and off
// by a T^2 / 8 at mid-sample for an acceleration a of the positions (velocities: to the change
// of the acceleration), the same order as the plan's own integration error, for NX
// multiply-adds; a finer prediction (the integrator's intermediate states, the model at 1 kHz)
// would cost a dynamics evaluation per call.
//
// Cost per call: NU NX + NU ND + 2 NX multiply-adds and 2 NU comparisons, no heap (Kinova
// sizes nx = 16, nu = 8, ND = 7: 234 instructions on x86-64 in double, 1 057 on the Cortex-M7:
// bench/nmpc/RESULTS-inner-loop.md). The object is the caller's state (the plan's vectors and the
// NU x NX gain: 2.0 KB in double at the Kinova sizes).
#pragma once

#include <Eigen/Core>
#include <limits>

#include "arbor/core/config.hpp"
#include "arbor/nmpc/status.hpp"

namespace arbor::nmpc {

/// The torque-rate inner loop for NX states, NU inputs and an ND-dimensional disturbance
/// estimate (0: none) at Scalar (see the top of this file).
///   InnerLoop<double, 16, 8, 7> loop;                   // caller-owned (static or a member)
///   at each sample, after ctrl.feedback(x0):
///     loop.start(ctrl, T, lbu, ubu, &obs.estimate());   // u_0, x_0, x_1, K_0, d_0
///   at each fast tick, t since the measurement:
///     obs.update(q, qd, u); u = loop.control(t, x, obs.estimate());
template <class Scalar, int NX, int NU, int ND = 0>
class InnerLoop {
 public:
  using Vx = Eigen::Matrix<Scalar, NX, 1>;
  using Vu = Eigen::Matrix<Scalar, NU, 1>;
  using Vd = Eigen::Matrix<Scalar, ND, 1>;
  using Gain = Eigen::Matrix<Scalar, NU, NX>;
  using DisturbanceMap = Eigen::Matrix<Scalar, NU, ND>;

  /// No sample yet: control() returns zero inputs (status() not_prepared).
  InnerLoop() {
    u0_.setZero();
    x0_.setZero();
    dx_.setZero();
    k_.setZero();
    d0_.setZero();
    lb_.setZero();
    ub_.setZero();
    g_.setZero();
    for (int i = 0; i < (ND < NU ? ND : NU); ++i)
      g_(i, i) = Scalar(-1);
  }

  /// The map of the estimate's change into the inputs (default: -I on the first min(ND, NU)
  /// inputs: a torque that cancels the change of the estimated disturbance torque).
  void set_disturbance_map(const DisturbanceMap& g) { g_ = g; }
  const DisturbanceMap& disturbance_map() const { return g_; }

  /// Starts a sample: the plan's u_0, x_0, x_1, stage 0's duration T (> 0), the input bounds
  /// lb <= ub of stage 0, the gain K_0 with the status its source returned (accepted: used;
  /// anything else: no gain, K = 0, and status() passes that status on) and the estimate at the
  /// sample d0 (nullptr: none; then the compensation is off until the next start). Returns
  /// status(), or non_finite_input (nothing stored: control() keeps the last sample's law) when
  /// a value is not finite.
  NmpcStatus start(const Vu& u0, const Vx& x0, const Vx& x1, Scalar T, const Vu& lb, const Vu& ub,
                   NmpcStatus gain_status, const Gain& k0, const Vd* d0 = nullptr) {
    const bool with_gain = gain_status == NmpcStatus::accepted;
    if (!u0.allFinite() || !x0.allFinite() || !x1.allFinite() || !(T > Scalar(0)) ||
        !(T < std::numeric_limits<Scalar>::infinity()) || lb.hasNaN() || ub.hasNaN() ||
        (with_gain && !k0.allFinite()) || (d0 != nullptr && !d0->allFinite()))
      return NmpcStatus::non_finite_input;
    ARBOR_ASSERT((lb.array() <= ub.array()).all(), "inner loop: lb <= ub");
    u0_ = u0;
    x0_ = x0;
    dx_ = x1 - x0;
    inv_t_ = Scalar(1) / T;
    lb_ = lb;
    ub_ = ub;
    if (with_gain)
      k_ = k0;
    else
      k_.setZero();
    compensate_ = d0 != nullptr;
    if (compensate_)
      d0_ = *d0;
    status_ = gain_status;
    return status_;
  }

  /// start() from a controller after its feedback(): u_0 = ctrl.control(), x_0, x_1 =
  /// ctrl.state(0), ctrl.state(1), K_0 and its status from ctrl.feedback_gain(0, .).
  template <class Ctrl>
  NmpcStatus start(const Ctrl& ctrl, Scalar T, const Vu& lb, const Vu& ub, const Vd* d0 = nullptr) {
    Gain k;
    const NmpcStatus gs = ctrl.feedback_gain(0, k);
    return start(ctrl.control(), ctrl.state(0), ctrl.state(1), T, lb, ub, gs, k, d0);
  }

  /// The input at time t (s since the sample's measurement; clamped to [0, T]) for the measured
  /// state x, without disturbance compensation.
  Vu control(Scalar t, const Vx& x) const {
    Vu u = feedback(t, x);
    return clamp(u);
  }

  /// The input at time t for the measured x and the current estimate d (compensation of
  /// d - d_0 when start() was given d_0).
  Vu control(Scalar t, const Vx& x, const Vd& d) const {
    Vu u = feedback(t, x);
    if (compensate_)
      u.noalias() += g_ * (d - d0_);
    return clamp(u);
  }

  /// The predicted state x_pred(t) (see the top of this file).
  Vx predicted(Scalar t) const {
    Scalar s = t * inv_t_;
    s = s < Scalar(0) ? Scalar(0) : (s > Scalar(1) ? Scalar(1) : s);
    return x0_ + s * dx_;
  }

  /// accepted when the last start() had a gain; else the gain's status it was given (qp_failed,
  /// not_prepared, ...: the law is then u_0 plus the compensation, clamped); not_prepared before
  /// the first start().
  NmpcStatus status() const { return status_; }
  /// The gain in use (zero without one).
  const Gain& gain() const { return k_; }

 private:
  Vu feedback(Scalar t, const Vx& x) const {
    const Vx e = x - predicted(t);
    Vu u = u0_;
    u.noalias() += k_ * e;
    return u;
  }
  Vu clamp(const Vu& u) const { return u.cwiseMax(lb_).cwiseMin(ub_); }

  Vu u0_;                    ///< the plan's u_0
  Vx x0_;                    ///< the plan's x_0
  Vx dx_;                    ///< x_1 - x_0
  Scalar inv_t_ = 1;         ///< 1 / T
  Gain k_;                   ///< K_0 (zero without a gain)
  Vd d0_;                    ///< the estimate at the sample
  Vu lb_, ub_;               ///< stage 0's input bounds
  DisturbanceMap g_;         ///< the estimate's map into the inputs
  bool compensate_ = false;  ///< d0_ holds an estimate
  NmpcStatus status_ = NmpcStatus::not_prepared;
};

}  // namespace arbor::nmpc
