// The closed loop of the contour example (ContourLoop<F, Tag, Soft, Scalar[, Timer]>): the
// controller (mpc.hpp: formulation F, RBD derivative provider Tag, hard or Soft tunnel, controller
// scalar Scalar), the estimator (estimator.hpp: noise, state filter, momentum observer) and one
// plant (plant.hpp's Plant concept: arbor's, the default, or MuJoCo's, mujoco_plant.hpp, chosen
// once with use_plant()).
//
//   ContourLoop<F, Tag, Soft, Scalar[, Timer]> loop(options);  // big: static storage
//   loop.use_plant(plant);        // optional: instead of arbor's plant (options.mismatch: with
//                                 // the payload)
//   loop.start();                 // plant at x0, first OCP solved to convergence (warm start)
//   while (!loop.done()) loop.sample(record);          // one 0.02 s sample, see sample()
//
// Real-time iteration (default), per sample: the plant runs the current control u_0 for h (its
// every step watched by step_monitor.hpp: velocities and the tunnel where the hardware checks them);
// shift(); prepare() (linearisation around the shifted plan: before the measurement); the state
// is measured (the estimator); feedback(x) solves one QP and gives the next u_0. SQP mode (the
// paper's): shift(), then solve(x) with at most sqp_iter iterations and the tolerances of
// CONTOUR.md. The controller's calls allocate nothing; the logging does not run inside them.
// Timer (default SteadyTimer: the host's clock, microseconds) times the phases; bare-metal targets
// give one that counts instructions (tests/contour/target_test.cpp).
#pragma once

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cmath>

#include "arbor/nmpc/inner_loop.hpp"
#include "estimator.hpp"
#include "mpc.hpp"
#include "options.hpp"
#include "plant.hpp"
#include "step_monitor.hpp"
#include "task.hpp"

namespace contour {

/// The default timer of ContourLoop: the host's steady clock, in microseconds. A timer is a type
/// with `Stamp now()` and `double elapsed(Stamp from, Stamp to)`.
struct SteadyTimer {
  using Stamp = std::chrono::steady_clock::time_point;
  static Stamp now() { return std::chrono::steady_clock::now(); }
  static double elapsed(Stamp from, Stamp to) {
    return std::chrono::duration<double, std::micro>(to - from).count();
  }
};

/// What one sample records (plant state after the sample, the control computed from it).
struct Record {
  double t = 0;                            ///< time at the end of the sample [s]
  VecN<double, nx> x;                      ///< plant state (measured without noise)
  VecN<double, 3> p, p_ref;                ///< end-effector position and its reference at s
  double e_p = 0, e_R = 0;                 ///< |p - p_ref(s)|, |e_R|
  double sd_ref = 0;                       ///< sd_ref(s)
  VecN<double, nq> tau;                    ///< max |tau| applied during the sample (signed: last)
  VecN<double, nq> tau_peak;               ///< max |tau_i| over the sample's substeps
  VecN<double, nu> u;                      ///< the control computed at the end of the sample
  double prepare_us = 0, feedback_us = 0;  ///< controller time in the Timer's unit (SteadyTimer:
                                           ///< us; SQP mode: solve in feedback)
  int sqp_iterations = 0, qp_iterations = 0;
  bool qp_presolved = false;  ///< the feedback took its prepared first step (NmpcInfo)
  arbor::nmpc::NmpcStatus status = arbor::nmpc::NmpcStatus::step_taken;
  arbor::qp::QpStatus qp_status = arbor::qp::QpStatus::solved;
  bool hold = false;                                  ///< the sample ran in the start phase
  VecN<double, nq> d_hat = VecN<double, nq>::Zero();  ///< the observer's estimate after it
  StepPeaks peaks;  ///< max |qd_i|, |q_i| and tunnel error over the sample's plant steps (1 ms)
};

template <Formulation F, class Tag, bool Soft, class Scalar = double, class Timer = SteadyTimer>
class ContourLoop {
 public:
  using Mpc = ContourMpc<F, Tag, Soft, Scalar>;
  using W = typename Mpc::W;
  using ExprProblem = typename Mpc::ExprProblem;
  using StageDef = typename Mpc::StageDef;
  using Problem = typename Mpc::Problem;
  using Controller = typename Mpc::Controller;
  using PlantModel = ArborPlant<Robot>;
  using PayloadPlant = ArborPlant<PayloadRobot>;
  static constexpr Formulation formulation = F;
  static constexpr bool soft = Soft;
  static constexpr bool is_float = Mpc::is_float;
  static constexpr bool has_generated_stage = Mpc::has_generated_stage;

  /// The controller and estimator of the options; the plant arbor's (with the payload:
  /// o.mismatch).
  explicit ContourLoop(const Options& o)
      : options_(o),
        mpc_(o),
        estimator_(o),
        plant_(o.mismatch ? PlantRef(payload_) : PlantRef(nominal_)) {
    if (o.known_payload) {
      // the controller's model carries the plant's payload (a point mass at the end-effector
      // frame) everywhere: its RBD workspace (mpc.hpp), the observer's model and the plants'
      // computed-torque models
      const bool ok = Mpc::declare_payload(estimator_.model()) &&
                      Mpc::declare_payload(nominal_.nominal) &&
                      Mpc::declare_payload(payload_.nominal);
      ARBOR_ASSERT(ok, "the end-effector frame takes a payload");
      (void)ok;
    }
  }
  ContourLoop(const ContourLoop&) = delete;
  ContourLoop& operator=(const ContourLoop&) = delete;

  /// Runs the loop against p (not owned; it keeps its own payload and joint properties, and
  /// options().mismatch no longer selects the plant) instead of arbor's plant. Before start().
  template <Plant P>
  void use_plant(P& p) {
    plant_ = PlantRef(p);
    external_ = true;
    if (options_.known_payload)
      (void)Mpc::declare_payload(plant_.nominal());
  }
  /// True when a plant of use_plant() runs the loop.
  bool external() const { return external_; }

  static bool declare_payload(arbor::Data<Robot, double>& d) { return Mpc::declare_payload(d); }
  static double backoff(const Options& o) { return Mpc::backoff(o); }
  static bool generated_stage_applies(const Options& o) { return Mpc::generated_stage_applies(o); }
  bool generated_stage() const { return mpc_.generated_stage(); }

  /// Plant at x0; the first OCP solved to convergence from a gravity-compensating guess.
  arbor::nmpc::NmpcStatus start() {
    VecN<double, nx> x0 = VecN<double, nx>::Zero();
    x0.head<nq>() = initial_q();
    plant_.x() = x0;
    t_ = 0;
    samples_ = 0;
    hold_samples_ = int(std::lround(options_.hold / h));
    estimator_.reset(initial_q(), plant_.substep_dt());
    step_count_ = 0;  // the inner loop's readings: the initial state's is step 0
    recent_q_[0] = initial_q();
    recent_qd_[0].setZero();
    if (inner_loop_runs())  // (no draw otherwise: the noise sequence stays the loop's without it)
      estimator_.sense(recent_q_[0], recent_qd_[0]);
    set_parameters();
    mpc_.set_hold(hold_samples_ > 0);
    start_status_ = mpc_.start(x0, plant_.nominal());
    start_iterations_ = mpc_.controller().info().iterations;
    return start_status_;
  }

  /// One sample (see the top of this file); fills rec.
  void sample(Record& rec) {
    namespace nm = arbor::nmpc;
    Controller& ctrl = mpc_.controller();
    const VecN<double, nu> u = ctrl.control().template cast<double>();
    monitor_.begin(mpc_.reference(), plant_.substep_dt(), plant_.x()[14], plant_.x()[15], u[7]);
    if (inner_loop_runs()) {
      start_inner_loop(u);
      plant_.step(F, u, monitor_.hook(reading_hook()), torque_law());
    } else {
      plant_.step(F, u, monitor_.hook(estimator_.substep_hook()));
    }
    ++samples_;
    t_ += h;
    const VecN<double, nx>& pl = plant_.x();
    VecN<double, nx> sensed = pl;  // what the sensors report at the sample's end
    if (options_.delay_steps > 0) {
      sensed.head<nq>() = monitor_.q_before(options_.delay_steps);
      sensed.segment<nq>(nq) = monitor_.qd_before(options_.delay_steps);
    }
    VecN<double, nx> meas = estimator_.measure(sensed, plant_.tau_applied());
    rec.hold = mpc_.holding();
    if (estimator_.observing())
      set_parameters();
    if (mpc_.holding() && samples_ >= hold_samples_)
      mpc_.set_hold(false);  // the task starts with the control computed now
    nm::NmpcStatus st;
    double prep = 0, fb = 0;
    ctrl.shift();
    if (!rec.hold)  // after shift(), state(0) is the last plan's x_1: the measurement's prediction
      estimator_.filter(meas, ctrl.state(0).template cast<double>());
    if (!options_.sqp) {
      const auto t0 = Timer::now();
      st = ctrl.prepare();
      const auto t1 = Timer::now();
      if (st == nm::NmpcStatus::prepared)
        st = ctrl.feedback(meas.cast<Scalar>());
      const auto t2 = Timer::now();
      prep = Timer::elapsed(t0, t1);
      fb = Timer::elapsed(t1, t2);
    } else {
      const auto t0 = Timer::now();
      st = ctrl.solve(meas.cast<Scalar>());
      const auto t1 = Timer::now();
      fb = Timer::elapsed(t0, t1);
    }
    rec.t = t_;
    rec.x = pl;
    rec.p = plant_.ee_position();
    rec.p_ref = p_ref(mpc_.reference(), pl[14]);
    rec.e_p = (rec.p - rec.p_ref).norm();
    rec.e_R = plant_.rotation_error(mpc_.reference()).norm();
    rec.sd_ref = sd_ref(mpc_.reference().c, pl[14]);
    rec.tau = plant_.tau_applied();
    rec.tau_peak = plant_.tau_peak();
    rec.u = ctrl.control().template cast<double>();
    rec.prepare_us = prep;
    rec.feedback_us = fb;
    rec.sqp_iterations = ctrl.info().iterations;
    rec.qp_iterations = ctrl.info().qp_iterations;
    rec.status = st;
    rec.qp_status = ctrl.info().qp_status;
    rec.qp_presolved = ctrl.info().qp_presolved;
    rec.d_hat = estimator_.estimate();
    rec.peaks = monitor_.peaks();
  }

  /// s reached s_end or the sample budget is spent.
  bool done() const { return plant_x()[14] > options_.s_end || samples_ >= options_.max_samples; }

  const VecN<double, nx>& plant_x() const { return plant_.x(); }
  Controller& controller() { return mpc_.controller(); }
  const Reference& reference() const { return mpc_.reference(); }
  const Options& options() const { return options_; }
  arbor::nmpc::NmpcStatus start_status() const { return start_status_; }
  int start_iterations() const { return start_iterations_; }
  int samples() const { return samples_; }
  /// Samples of the start phase (Options::hold).
  int hold_samples() const { return hold_samples_; }
  const arbor::nmpc::MomentumObserver<Robot, double>& observer() const {
    return estimator_.observer();
  }

 private:
  using InnerLoop = arbor::nmpc::InnerLoop<double, nx, nu, nq>;
  static constexpr int kReadings = StepMonitor::kKeep;  ///< readings kept (>= delay + 1)

  bool inner_loop_runs() const { return options_.inner_loop && F == Formulation::fd; }

  /// The inner loop's law for the coming sample: the plan's u_0, x_0, x_1 (the last feedback's),
  /// the QP's gain K_0 and its status, the torque bounds (sdd held at u_0's: the plant integrates
  /// s with the sample's sdd) and the estimate the plan compensates.
  void start_inner_loop(const VecN<double, nu>& u) {
    Controller& ctrl = mpc_.controller();
    Eigen::Matrix<Scalar, nu, nx> k;
    const arbor::nmpc::NmpcStatus gs = ctrl.feedback_gain(0, k);
    VecN<double, nu> lb, ub;
    for (int i = 0; i < nq; ++i) {
      lb[i] = -tau_max[std::size_t(i)];
      ub[i] = tau_max[std::size_t(i)];
    }
    lb[nq] = ub[nq] = u[nq];
    const bool compensate = estimator_.observing() && options_.observer_plant_rate;
    const VecN<double, nq> d0 = estimator_.estimate();
    (void)inner_.start(u, ctrl.state(0).template cast<double>(),
                       ctrl.state(1).template cast<double>(), h, lb, ub, gs,
                       k.template cast<double>(), compensate ? &d0 : nullptr);
    sample_start_ = step_count_;
  }

  /// After each plant step: the step's noisy reading (and the observer's update from it), kept
  /// for the inner loop.
  SubstepHook reading_hook() {
    return {this, [](void* self, const VecN<double, nq>& q, const VecN<double, nq>& qd,
                     const VecN<double, nq>& tau) {
              auto& l = *static_cast<ContourLoop*>(self);
              ++l.step_count_;
              const std::size_t i = std::size_t(l.step_count_ % kReadings);
              l.recent_q_[i] = q;
              l.recent_qd_[i] = qd;
              l.estimator_.sense_step(l.recent_q_[i], l.recent_qd_[i], tau);
            }};
  }

  /// Before each plant step k of the sample: the inner loop's torque from the reading
  /// Options::delay_steps steps old, at t = k dt since the plan's x_0 was measured.
  TorqueLaw torque_law() {
    return {this, [](void* self, int k, VecN<double, nq>& tau) {
              auto& l = *static_cast<ContourLoop*>(self);
              long idx = l.sample_start_ + k - l.options_.delay_steps;
              idx = idx < 0 ? 0 : idx;
              const std::size_t i = std::size_t(idx % kReadings);
              const double t = k * l.plant_.substep_dt();
              VecN<double, nx> x = l.inner_.predicted(t);  // s, sd: the plan's
              x.template head<nq>() = l.recent_q_[i];
              x.template segment<nq>(nq) = l.recent_qd_[i];
              tau = l.inner_.control(t, x, l.estimator_.estimate()).template head<nq>();
            }};
  }

  /// The controller's stage parameters: the observer's estimate when it runs.
  void set_parameters() {
    mpc_.set_parameters(estimator_.observing() ? &estimator_.estimate() : nullptr);
  }

  Options options_;
  Mpc mpc_;
  Estimator estimator_;
  StepMonitor monitor_;  ///< the limits at every plant step
  InnerLoop inner_;      ///< the torque-rate inner loop (Options::inner_loop)
  std::array<VecN<double, nq>, kReadings> recent_q_{}, recent_qd_{};  ///< its readings
  long step_count_ = 0;                                               ///< plant steps since start()
  long sample_start_ = 0;  ///< step_count_ at the sample's start
  PlantModel nominal_;
  PayloadPlant payload_;
  PlantRef plant_;  // after the plants it may refer to
  bool external_ = false;
  double t_ = 0;
  int samples_ = 0;
  arbor::nmpc::NmpcStatus start_status_ = arbor::nmpc::NmpcStatus::not_prepared;
  int start_iterations_ = 0;
  int hold_samples_ = 0;  ///< samples of the start phase
};

}  // namespace contour
