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

#include "arbor/nmpc/controller.hpp"
#include "plant.hpp"
#include "task.hpp"

namespace contour {

/// Run options (every one is a command-line option of the example).
struct Options {
  double c = 0.2;          ///< sd_ref scale
  int max_samples = 4000;  ///< stop after this many samples
  double s_end = 0.99;     ///< stop when s exceeds this
  bool sqp = false;        ///< paper's mode (full SQP, at most sqp_iter iterations) instead of RTI
  int sqp_iter = 5;        ///< SQP iterations per sample (sqp mode)
  bool mismatch = false;   ///< plant with a 0.5 kg payload at the end effector
  double noise = 0;        ///< std. dev. of the measurement noise on q [rad] (qd: 10x)
  std::uint32_t seed = 1;  ///< noise seed
  double soft_weight = 100;  ///< slack weight of the soft tunnel (soft builds)
  /// the controller's tunnel is rho - backoff [m]; < 0: the scalar's default (default_backoff)
  double backoff = -1;
  int qp_max_iter = 0;  ///< QP active-set iterations per QP (0: the library's default)
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
};

/// QP primal tolerance of float controllers in real-time iteration. The float QP's default, 1e-4,
/// is a distance relative to 1 + max(1, |x|_inf, ...) over the QP's variables, torques of ~10 N m
/// among them: the tunnel row may end ~0.1-1.5 mm outside. Tighter tolerances cost QP iterations
/// and, in OCP-ID, make the float QP stall (1e-6: 24 of 320 samples): 3e-5 with a larger back-off
/// (default_backoff) holds rho in both formulations with 2 QP iterations per sample (README.md,
/// "Float").
constexpr double float_qp_tol_primal = 3e-5;

/// The controller's default tunnel back-off [m] (Options::backoff < 0): the margin for the
/// linearisation error of real-time iteration (double, 1e-4: the plant reached 10.002 mm without
/// it) and, in float, for the QP's looser primal tolerance (3e-4; README.md, "Float").
template <class Scalar>
constexpr double default_backoff = std::is_same_v<Scalar, float> ? 3e-4 : 1e-4;

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
  arbor::nmpc::NmpcStatus status = arbor::nmpc::NmpcStatus::step_taken;
  arbor::qp::QpStatus qp_status = arbor::qp::QpStatus::solved;
};

template <Formulation F, class Tag, bool Soft, class Scalar = double, class Timer = SteadyTimer,
          class ExtPlant = NoExternalPlant>
class ContourLoop {
 public:
  using W = Workspace<Tag, Scalar>;
  using Problem = decltype(make_problem<F, Tag, Soft>(std::declval<W&>(), Reference{}));
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
        problem_(make_problem<F, Tag, Soft>(ws_, ref_, o.soft_weight, rho - backoff(o),
                                            o.scaled_tunnel || o.sqp)),
        ctrl_(problem_),
        rng_(o.seed) {}
  ContourLoop(const ContourLoop&) = delete;
  ContourLoop& operator=(const ContourLoop&) = delete;

  /// Runs the loop against p (not owned; it keeps its own payload and joint properties, and
  /// options().mismatch no longer selects the plant) instead of arbor's plant; nullptr: arbor's.
  void set_external_plant(ExtPlant* p) { external_ = p; }
  /// True when the external plant runs the loop.
  bool external() const { return external_ != nullptr; }

  /// The back-off the controller runs with: o.backoff, or the scalar's default if it is < 0.
  static double backoff(const Options& o) {
    return o.backoff < 0 ? default_backoff<Scalar> : o.backoff;
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
    for (int k = 0; k <= horizon; ++k) {
      typename Controller::Vp p;
      p[0] = Scalar(k == 0 ? 0 : 1);  // the tunnel is not imposed on the measured x_0
      ctrl_.set_parameter(k, p);
    }
    VecN<double, nu> u0 = VecN<double, nu>::Zero();
    if constexpr (F == Formulation::fd)  // gravity compensation at q0
      u0.head<nq>() = arbor::rnea<Robot>(nominal_.nominal, initial_q(), VecN<double, nq>::Zero(),
                                         VecN<double, nq>::Zero());
    auto st = ctrl_.set_initial_guess(x0.cast<Scalar>(), u0.cast<Scalar>());
    if (st != arbor::nmpc::NmpcStatus::prepared)
      return st;
    auto& set = ctrl_.settings();
    set.shift_multipliers = options_.shift_multipliers;
    if (options_.qp_max_iter > 0)
      set.qp.max_iter = options_.qp_max_iter;
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
    on_plant([&](auto& p) { p.step(F, u); });
    ++samples_;
    t_ += h;
    const auto& pl = plant_x();
    VecN<double, nx> meas = pl;
    if (options_.noise > 0) {
      std::normal_distribution<double> n(0.0, options_.noise);
      for (int i = 0; i < nq; ++i) {
        meas[i] += n(rng_);
        meas[nq + i] += 10 * n(rng_);
      }
    }
    namespace nm = arbor::nmpc;
    nm::NmpcStatus st;
    double prep = 0, fb = 0;
    ctrl_.shift();
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
};

}  // namespace contour
