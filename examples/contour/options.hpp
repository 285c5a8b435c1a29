// The contour example's run options (each one a command-line option of main.cpp), shared by the
// controller (mpc.hpp), the estimator (estimator.hpp) and the closed loop (closed_loop.hpp).
#pragma once

#include <cstdint>

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
  /// The measurement is the plant's state this many plant steps (1 ms) before the sample's end
  /// (a sensor and bus delay; s and sd, the controller's own states, are not delayed); at most
  /// StepMonitor::kKeep - 1
  int delay_steps = 0;
  /// OCP-FD: a torque-rate inner loop between samples (arbor/nmpc/inner_loop.hpp): at every
  /// plant step u = clamp(u_0 + K_0 (x - x_pred(t)) - (d - d_0)) with the QP's own feedback gain
  /// K_0 (Nmpc::feedback_gain), x the (noisy, delayed) measurement at that step, x_pred the plan's
  /// chord from x_0 to x_1, d the observer's estimate when it runs at the plant's rate
  bool inner_loop = false;
};

}  // namespace contour
