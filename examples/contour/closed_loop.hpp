// The closed loop of the contour example: the NMPC (controller scalar Scalar, formulation F,
// RBD derivative provider Tag, hard or Soft tunnel) against the plant of plant.hpp, or against
// an external plant of the same interface (ExtPlant, e.g. MujocoPlant of mujoco_plant.hpp).
//
//   ContourLoop<F, Tag, Soft, Scalar[, Timer[, ExtPlant]]> loop(options);  // big: static storage
//   loop.set_external_plant(&plant);  // optional (ExtPlant): used instead of arbor's plant
//   loop.start();                 // plant at x0, first OCP solved to convergence (warm start)
//   while (!loop.done()) loop.sample();                // one 0.02 s sample, see sample()
//
// Real-time iteration (default), per sample: the plant runs the current control u_0 for h;
// shift(); prepare() (linearisation around the shifted plan: before the measurement); the state
// is measured (optionally with noise); feedback(x) solves one QP and gives the next u_0. SQP mode
// (the paper's): shift(), then solve(x) with at most sqp_iter iterations and the tolerances of
// CONTOUR.md. The controller's calls allocate nothing; the logging does not run inside them.
// Timer (default SteadyTimer: the host's clock, microseconds) times the phases; bare-metal targets
// give one that counts instructions (tests/contour/target_test.cpp).
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <random>
#include <type_traits>

#include "arbor/dynamics/payload.hpp"
#include "arbor/nmpc/controller.hpp"
#include "arbor/nmpc/momentum_observer.hpp"
#include "plant.hpp"
#include "stage_definition.hpp"
#include "task.hpp"

/// 1: the loops use generated stage code where it exists (ContourLoop::has_generated_stage).
#ifndef CONTOUR_GENERATED_STAGE
#define CONTOUR_GENERATED_STAGE 0
#endif
#if CONTOUR_GENERATED_STAGE
#include "contour_stages_ad.hpp"  // (arbor_add_stage_ad: ARBOR_CONTOUR_GENERATED_STAGE)
#endif

namespace contour {

/// Run options (every one is a command-line option of the example).
struct Options {
  double c = 0.2;          ///< sd_ref scale
  int max_samples = 4000;  ///< stop after this many samples
  double s_end = 0.99;     ///< stop when s exceeds this
  bool sqp = false;        ///< paper's mode (full SQP, at most sqp_iter iterations) instead of RTI
  int sqp_iter = 5;        ///< SQP iterations per sample (sqp mode)
  bool mismatch = false;   ///< plant with a 0.5 kg payload at the end effector
  /// The controller knows the plant's payload (with mismatch): declared at run time on its
  /// workspace (ad::set_payload) and on the observer's model, the robot as generated
  bool known_payload = false;
  double noise = 0;          ///< std. dev. of the measurement noise on q [rad] (qd: 10x)
  std::uint32_t seed = 1;    ///< noise seed
  double soft_weight = 100;  ///< slack weight of the soft tunnel (soft builds)
  /// the controller's tunnel is rho - backoff [m]; < 0: the scalar's default (default_backoff)
  double backoff = -1;
  int qp_max_iter = 0;  ///< QP active-set iterations per QP (0: the library's default)
  /// RTI: the feedback's QP stops after this many iterations and its step is taken anyway
  /// (NmpcSettings::feedback_qp_iterations; status step_limited); 0: no bound
  int feedback_qp_iter = 0;
  /// RTI: the feedback's first QP step prepared in prepare() and moved to the measured state
  /// (NmpcSettings::presolve_feedback): less latency, more work per sample; on as the library's
  bool presolve = true;
  /// QP tolerances in real-time iteration (0: the library's; its 1e-10 default for the SQP is
  /// not reached from the warm start on this problem: iteration limits, see README)
  double qp_tol = 1e-8;
  /// The tunnel row as |e_p / radius|^2 - 1 <= 0 (order one) instead of |e_p|^2 - radius^2 <= 0
  /// (make_problem's `scaled`). The QP measures a row's violation as a distance, invariant to
  /// this scaling. The paper's SQP mode (sqp) always uses it: with CONTOUR.md's loose SQP
  /// tolerances the unscaled row lets OCP-ID drift out of the tunnel (measured at 7d4c7d9: first
  /// QP failure at sample 98, 3903 failed samples of 4000) while the scaled row runs clean.
  bool scaled_tunnel = false;
  /// shift() moves the multipliers with the plan (NmpcSettings::shift_multipliers; off: the
  /// library's default, the QP starts from the last solution's working set stage by stage)
  bool shift_multipliers = false;
  /// The generalized-momentum observer (arbor/nmpc/momentum_observer.hpp) estimates the joint
  /// torque the controller's model lacks and feeds it to the OCP as the stage parameters d
  /// (OCP-FD: FD(q, qd, tau + d); task.hpp)
  bool observer = false;
  double observer_gain = 20;        ///< its gain K [1/s] (bandwidth)
  bool observer_plant_rate = true;  ///< update it after every plant step (else once per sample)
  /// start phase [s]: the controller holds the initial pose (s and sd bounded to 0) before the
  /// task starts; the observer settles meanwhile
  double hold = 0;
  /// the controller's velocity bound is (1 - qd_margin) qd_max (the plant's limit stays qd_max)
  double qd_margin = 0;
  /// Measured-state filter (0: off): the state the controller gets is the plan's prediction of
  /// it (x_1 of the last plan, on the controller's model) plus state_filter times the innovation
  /// (measurement - prediction), on q and qd: a fixed-gain predictor-corrector against
  /// measurement noise (a model error biases it: use it with the observer)
  double state_filter = 0;
};

/// QP primal tolerance of float controllers in real-time iteration. The float QP's default, 1e-4,
/// is a distance relative to 1 + max(1, |x|_inf, ...) over the QP's variables, torques of ~10 N m
/// among them: the tunnel row may end ~0.1-1.5 mm outside. Tighter tolerances cost QP iterations
/// and, in OCP-ID, make the float QP stall (1e-6: 24 of 320 samples): 3e-5 with a larger back-off
/// (default_backoff) holds rho in both formulations with 2 QP iterations per sample (README.md,
/// "Float").
constexpr double float_qp_tol_primal = 3e-5;

/// The default timer of ContourLoop: the host's steady clock, in microseconds. A timer is a type
/// with `Stamp now()` and `double elapsed(Stamp from, Stamp to)`.
struct SteadyTimer {
  using Stamp = std::chrono::steady_clock::time_point;
  static Stamp now() { return std::chrono::steady_clock::now(); }
  static double elapsed(Stamp from, Stamp to) {
    return std::chrono::duration<double, std::micro>(to - from).count();
  }
};

/// ContourLoop's default ExtPlant: none (only arbor's plants, plant.hpp).
struct NoExternalPlant {};

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
};

template <Formulation F, class Tag, bool Soft, class Scalar = double, class Timer = SteadyTimer,
          class ExtPlant = NoExternalPlant>
class ContourLoop {
 public:
  using W = Workspace<Tag, Scalar>;
  using ExprProblem = decltype(make_problem<F, Tag, Soft>(std::declval<W&>(), Reference{}));
  /// The problem definition of generated stage code (stage_definition.hpp) for this loop.
  using StageDef = StageDefinition<F, Soft, Scalar>;
  /// The controller's Gauss-Newton stages come from generated code (built with
  /// CONTOUR_GENERATED_STAGE=1, the analytical provider and the definition's header included:
  /// CMake ARBOR_CONTOUR_GENERATED_STAGE) when the run's options are the definition's
  /// (generated_stage_applies), else from the expression layer.
  static constexpr bool has_generated_stage = CONTOUR_GENERATED_STAGE &&
                                              std::is_same_v<Tag, arbor::ad::Analytical> &&
                                              arbor::ocp::GeneratedStage<StageDef>::available;
  using Problem =
      std::conditional_t<has_generated_stage, arbor::ocp::WithGeneratedStage<ExprProblem, StageDef>,
                         ExprProblem>;
  using Controller = arbor::nmpc::Nmpc<Problem, Scalar>;
  using PlantModel = Plant<Robot>;
  using PayloadPlant = Plant<PayloadRobot>;
  static constexpr Formulation formulation = F;
  static constexpr bool soft = Soft;
  static constexpr bool is_float = std::is_same_v<Scalar, float>;
  static constexpr bool has_external = !std::is_same_v<ExtPlant, NoExternalPlant>;

  explicit ContourLoop(const Options& o)
      : options_(o),
        ref_(make_reference(o.c)),
        problem_(with_generated(
            with_margin(make_problem<F, Tag, Soft>(ws_, ref_, o.soft_weight, rho - backoff(o),
                                                   o.scaled_tunnel || o.sqp),
                        o.qd_margin),
            o)),
        ctrl_(problem_),
        rng_(o.seed) {
    // The controller's model with the plant's payload (a point mass at the end-effector frame)
    // at run time: its RBD workspace, the observer's model and the plants' copies of the
    // controller's model (OCP-ID's computed torque, the initial gravity compensation).
    if (o.known_payload) {
      const bool ok =
          arbor::ad::set_payload(ws_, ee_frame, PayloadRobot::payload, arbor::Vec3<double>::Zero(),
                                 arbor::Mat3<double>::Zero()) &&
          declare_payload(obs_.data()) && declare_payload(nominal_.nominal) &&
          declare_payload(payload_.nominal);
      ARBOR_ASSERT(ok, "the end-effector frame takes a payload");
      (void)ok;
    }
  }
  ContourLoop(const ContourLoop&) = delete;
  ContourLoop& operator=(const ContourLoop&) = delete;

  /// Runs the loop against p (not owned; it keeps its own payload and joint properties, and
  /// options().mismatch no longer selects the plant) instead of arbor's plant; nullptr: arbor's.
  void set_external_plant(ExtPlant* p) {
    external_ = p;
    if constexpr (requires { p->nominal; })
      if (p && options_.known_payload)
        (void)declare_payload(p->nominal);
  }
  /// True when the external plant runs the loop.
  bool external() const { return external_ != nullptr; }

  /// Declares the plant's payload on a Data of the controller's model (known_payload).
  static bool declare_payload(arbor::Data<Robot, double>& d) {
    return arbor::set_payload(d, ee_frame, PayloadRobot::payload, arbor::Vec3<double>::Zero(),
                              arbor::Mat3<double>::Zero());
  }

  /// The back-off the controller runs with: o.backoff, or the scalar's default if it is < 0.
  static double backoff(const Options& o) {
    return o.backoff < 0 ? default_backoff<Scalar> : o.backoff;
  }

  /// The generated stage code sees the definition's constants and the robot as generated: it
  /// applies when the run's reference, tunnel and slack weight are the definition's and no
  /// payload is declared on the controller's model.
  static bool generated_stage_applies(const Options& o) {
    return has_generated_stage && o.c == StageDef::c && rho - backoff(o) == StageDef::radius &&
           !(o.scaled_tunnel || o.sqp) && (!Soft || o.soft_weight == StageDef::soft_weight) &&
           !o.known_payload;
  }
  /// True when the controller's stages come from generated code.
  bool generated_stage() const {
    if constexpr (has_generated_stage)
      return problem_.generated;
    else
      return false;
  }

  /// The problem, with generated stages where they exist and apply (generated_stage_applies).
  static Problem with_generated(const ExprProblem& p, const Options& o) {
    if constexpr (has_generated_stage)
      return Problem(p, generated_stage_applies(o));
    else
      return p;
  }

  /// The problem with the velocity bounds (1 - margin) qd_max.
  static ExprProblem with_margin(ExprProblem p, double margin) {
    for (int i = 0; i < nq; ++i) {
      p.lbx[nq + i] = -(1 - margin) * qd_max;
      p.ubx[nq + i] = (1 - margin) * qd_max;
    }
    return p;
  }

  /// Start phase (hold): s and sd bounded to 0 on every stage, sdd to 0; else the problem's.
  void set_hold(bool hold) {
    using Vx = typename Controller::Vx;
    using Vu = typename Controller::Vu;
    Vx lb = problem_.lbx.template cast<Scalar>(), ub = problem_.ubx.template cast<Scalar>();
    Vu lbu = problem_.lbu.template cast<Scalar>(), ubu = problem_.ubu.template cast<Scalar>();
    if (hold) {
      ub[14] = ub[15] = 0;
      lbu[7] = ubu[7] = 0;
    }
    for (int k = 0; k <= horizon; ++k) {
      ctrl_.set_state_bounds(k, lb, ub);
      if (k < horizon)
        ctrl_.set_input_bounds(k, lbu, ubu);
    }
    holding_ = hold;
  }

  /// Stage parameters: the tunnel's weight (0 on stage 0) and the observer's estimate d.
  void set_parameters() {
    for (int k = 0; k <= horizon; ++k) {
      typename Controller::Vp p = Controller::Vp::Zero();
      p[0] = Scalar(k == 0 ? 0 : 1);  // the tunnel is not imposed on the measured x_0
      if (options_.observer)
        p.template tail<nq>() = obs_.estimate().template cast<Scalar>();
      ctrl_.set_parameter(k, p);
    }
  }

  /// Plant at x0; the first OCP solved to convergence from a gravity-compensating guess.
  arbor::nmpc::NmpcStatus start() {
    VecN<double, nx> x0 = VecN<double, nx>::Zero();
    x0.head<nq>() = initial_q();
    nominal_.x = x0;
    payload_.x = x0;
    if constexpr (has_external)
      if (external_)
        external_->x = x0;
    t_ = 0;
    samples_ = 0;
    hold_samples_ = int(std::lround(options_.hold / h));
    double obs_dt = h;
    if (options_.observer_plant_rate) {
      obs_dt = PlantModel::dt;
      if constexpr (has_external)
        if constexpr (requires { external_->options().dt; })
          if (external_)
            obs_dt = external_->options().dt;
    }
    obs_.set_gain(options_.observer_gain, obs_dt);
    (void)obs_.reset(initial_q(), VecN<double, nq>::Zero());
    set_parameters();
    set_hold(hold_samples_ > 0);
    VecN<double, nu> u0 = VecN<double, nu>::Zero();
    if constexpr (F == Formulation::fd)  // gravity compensation at q0 (the controller's model)
      u0.head<nq>() = arbor::rnea<Robot>(nominal_.nominal, initial_q(), VecN<double, nq>::Zero(),
                                         VecN<double, nq>::Zero());
    auto st = ctrl_.set_initial_guess(x0.cast<Scalar>(), u0.cast<Scalar>());
    if (st != arbor::nmpc::NmpcStatus::prepared)
      return st;
    auto& set = ctrl_.settings();
    set.shift_multipliers = options_.shift_multipliers;
    if (options_.qp_max_iter > 0)
      set.qp.max_iter = options_.qp_max_iter;
    set.feedback_qp_iterations = options_.feedback_qp_iter;
    set.presolve_feedback = options_.presolve;
    const auto keep = set;  // the first solve runs with the library's defaults
    set.max_iter = 100;
    st = ctrl_.solve(x0.cast<Scalar>());
    set = keep;
    if constexpr (!is_float) {
      if (!options_.sqp && options_.qp_tol > 0)
        set.qp.tol_primal = set.qp.tol_dual = set.qp.tol_comp = Scalar(options_.qp_tol);
    } else if (!options_.sqp) {  // float keeps its dual and complementarity defaults (1e-4)
      set.qp.tol_primal = Scalar(float_qp_tol_primal);
    }
    if (options_.sqp) {
      // CONTOUR.md: primal 1e-3, dual 1e-1, at most 3 line-search steps; QP 1e-3 / 1e-1
      set.max_iter = options_.sqp_iter;
      set.tol_primal = Scalar(1e-3);
      set.tol_stationarity = Scalar(1e-1);
      set.tol_complementarity = Scalar(1e-1);
      set.max_line_search = 3;
      // The QP judges a row's violation as a distance, |a_i' z - b_i| / |a_i| (issue 15: invariant
      // to scaling a row), not in the row's units as CONTOUR.md's QRQP did: its 1e-3 then let
      // the scaled tunnel row (|a_i| ~ 1e2) end 10 % outside (max 10.36 mm, 16 line-search
      // failures, every sample at the SQP cap). 1e-6 as a distance keeps the rows within ~1e-3
      // in their units: 0 failures, 9.902 mm.
      set.qp.tol_primal = Scalar(1e-6);
      set.qp.tol_dual = Scalar(1e-1);
      // (CONTOUR.md gives no complementarity tolerance: as loose as the dual one. At the QP's
      // default 1e-8 the working-set rule, which follows the loose tolerances, runs out of
      // changes before termination: 112 of 250 OCP-FD samples ended at the iteration cap.)
      set.qp.tol_comp = Scalar(1e-1);
    }
    start_status_ = st;
    start_iterations_ = ctrl_.info().iterations;
    return st;
  }

  /// One sample (see the top of this file); fills rec.
  void sample(Record& rec) {
    const VecN<double, nu> u = ctrl_.control().template cast<double>();
    const bool fast = options_.observer && options_.observer_plant_rate;
    // the torque loop's observer: after every plant step, from its (noisy) measurement
    auto hook = [&](const VecN<double, nq>& q, const VecN<double, nq>& v,
                    const VecN<double, nq>& tau) {
      if (!fast)
        return;
      VecN<double, nq> qm = q, vm = v;
      add_noise(qm, vm);
      (void)obs_.update(qm, vm, tau);
    };
    on_plant([&](auto& p) { p.step(F, u, hook); });
    ++samples_;
    t_ += h;
    const auto& pl = plant_x();
    VecN<double, nx> meas = pl;
    {
      VecN<double, nq> qm = meas.template head<nq>(), vm = meas.template segment<nq>(nq);
      add_noise(qm, vm);
      meas.template head<nq>() = qm;
      meas.template segment<nq>(nq) = vm;
    }
    rec.hold = holding_;
    if (options_.observer) {
      if (!fast)  // once per sample, with the torque held over it
        (void)obs_.update(meas.template head<nq>(), meas.template segment<nq>(nq),
                          on_plant([](auto& p) { return VecN<double, nq>(p.tau_applied); }));
      set_parameters();
    }
    if (holding_ && samples_ >= hold_samples_)
      set_hold(false);  // the task starts with the control computed now
    namespace nm = arbor::nmpc;
    nm::NmpcStatus st;
    double prep = 0, fb = 0;
    ctrl_.shift();
    if (options_.state_filter > 0 && !rec.hold) {
      // after shift(), state(0) is the last plan's x_1: the prediction of this measurement
      const VecN<double, nx> pred = ctrl_.state(0).template cast<double>();
      const double a = options_.state_filter;
      meas.template head<2 * nq>() =
          pred.template head<2 * nq>() + a * (meas - pred).template head<2 * nq>();
    }
    if (!options_.sqp) {
      const auto t0 = Timer::now();
      st = ctrl_.prepare();
      const auto t1 = Timer::now();
      if (st == nm::NmpcStatus::prepared)
        st = ctrl_.feedback(meas.cast<Scalar>());
      const auto t2 = Timer::now();
      prep = Timer::elapsed(t0, t1);
      fb = Timer::elapsed(t1, t2);
    } else {
      const auto t0 = Timer::now();
      st = ctrl_.solve(meas.cast<Scalar>());
      const auto t1 = Timer::now();
      fb = Timer::elapsed(t0, t1);
    }
    rec.t = t_;
    rec.x = pl;
    rec.p = on_plant([](auto& p) { return p.ee_position(); });
    rec.p_ref = p_ref(ref_, pl[14]);
    rec.e_p = (rec.p - rec.p_ref).norm();
    rec.e_R = on_plant([this](auto& p) { return p.rotation_error(ref_); }).norm();
    rec.sd_ref = sd_ref(ref_.c, pl[14]);
    rec.tau = on_plant([](auto& p) { return VecN<double, nq>(p.tau_applied); });
    rec.tau_peak = on_plant([](auto& p) { return VecN<double, nq>(p.tau_peak); });
    rec.u = ctrl_.control().template cast<double>();
    rec.prepare_us = prep;
    rec.feedback_us = fb;
    rec.sqp_iterations = ctrl_.info().iterations;
    rec.qp_iterations = ctrl_.info().qp_iterations;
    rec.status = st;
    rec.qp_status = ctrl_.info().qp_status;
    rec.qp_presolved = ctrl_.info().qp_presolved;
    rec.d_hat = obs_.estimate();
  }

  /// s reached s_end or the sample budget is spent.
  bool done() const { return plant_x()[14] > options_.s_end || samples_ >= options_.max_samples; }

  const VecN<double, nx>& plant_x() const {
    if constexpr (has_external)
      if (external_)
        return external_->x;
    return options_.mismatch ? payload_.x : nominal_.x;
  }
  Controller& controller() { return ctrl_; }
  const Reference& reference() const { return ref_; }
  const Options& options() const { return options_; }
  arbor::nmpc::NmpcStatus start_status() const { return start_status_; }
  int start_iterations() const { return start_iterations_; }
  int samples() const { return samples_; }
  /// Samples of the start phase (Options::hold).
  int hold_samples() const { return hold_samples_; }
  const arbor::nmpc::MomentumObserver<Robot, double>& observer() const { return obs_; }

 private:
  /// fn(plant) on the plant that runs the loop: the external one if set, else arbor's nominal or
  /// payload plant (options().mismatch).
  template <class Fn>
  decltype(auto) on_plant(Fn&& fn) {
    if constexpr (has_external)
      if (external_)
        return fn(*external_);
    return options_.mismatch ? fn(payload_) : fn(nominal_);
  }

  /// Measurement noise (Options::noise on q, 10x on qd).
  void add_noise(VecN<double, nq>& q, VecN<double, nq>& v) {
    if (options_.noise <= 0)
      return;
    std::normal_distribution<double> n(0.0, options_.noise);
    for (int i = 0; i < nq; ++i) {
      q[i] += n(rng_);
      v[i] += 10 * n(rng_);
    }
  }

  Options options_;
  Reference ref_;
  W ws_{};  // declared before problem_: the problem's handles point here
  Problem problem_;
  Controller ctrl_;
  PlantModel nominal_;
  PayloadPlant payload_;
  ExtPlant* external_ = nullptr;
  std::mt19937 rng_;
  double t_ = 0;
  int samples_ = 0;
  arbor::nmpc::NmpcStatus start_status_ = arbor::nmpc::NmpcStatus::not_prepared;
  int start_iterations_ = 0;
  arbor::nmpc::MomentumObserver<Robot, double> obs_{20.0, h};  ///< the disturbance observer
  int hold_samples_ = 0;                                       ///< samples of the start phase
  bool holding_ = false;                                       ///< the start phase's bounds are set
};

}  // namespace contour
