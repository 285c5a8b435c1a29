// The paper's Fig. 2 (bench/nmpc/fig2.sh): what one closed-loop run of one contour-NMPC variant
// (OCP-FD or OCP-ID; analytical, dual-number AD or code-generated AD RBD derivatives; paper's SQP
// mode or real-time iteration) measures per sample, and the six runner functions (one translation
// unit each, fig2_variant.cpp, for compile memory) that fig2_main.cpp calls.
#pragma once

#include <cstddef>
#include <vector>

namespace fig2 {

/// How to run one variant.
struct RunOptions {
  bool sqp = false;   ///< paper's mode (full SQP, at most sqp_iter iterations) instead of RTI
  int sqp_iter = 5;   ///< SQP iterations per sample (paper's mode)
  int samples = 250;  ///< closed-loop samples after the warm start
  /// callgrind: instrument samples cg_from..cg_from + cg_count - 1 only, and collect only inside
  /// the controller's calls (no isolated RBD timing then); cg_count = 0: no callgrind
  int cg_from = 0;
  int cg_count = 0;
  /// run ContourLoop::sample() (the example's own loop) in lockstep and compare the controls
  bool check = false;
  /// diagnostics: QP settings after the warm start (0: the example's), e.g. to find what makes
  /// the QPs of the paper's mode hit their iteration cap
  double qp_tol_primal = 0, qp_tol_dual = 0, qp_tol_comp = 0, qp_reg_dual = 0;
  int qp_max_iter = 0;
};

/// One sample (after the plant moved h): controller time split by phase [us].
struct Sample {
  double total_us = 0;  ///< every controller call of the sample: shift, linearisations, QPs...
  double lin_us = 0;    ///< linearisations (RTI: prepare(); SQP: solve(x0) with max_iter = 0)
  double rbd_us = 0;    ///< RBD Jacobians of those linearisations (isolated timing, see main)
  double qp_us = 0;     ///< QP update + solve (RTI: feedback(); SQP: solve_qp())
  double rest_us = 0;   ///< total - lin - qp: shift, line search (SQP), step
  int linearizations = 0;
  int sqp_iterations = 0;  ///< QP solves
  int qp_iterations = 0;   ///< active-set iterations, all QPs of the sample
  int status = 0;          ///< arbor::nmpc::NmpcStatus of the sample (as in solve()/feedback())
  int qp_status = 0;       ///< arbor::qp::QpStatus of the last QP
  bool failed = false;     ///< status is qp_failed, line_search_failed or non-finite
  double e_p = 0;          ///< plant's |p_ee - p_ref(s)| after the sample [m]
  double s = 0;            ///< plant's path parameter
  double check_du = 0;     ///< |u - u_example|_inf (check mode)
};

/// One closed-loop run.
struct Run {
  const char* name = "";
  int start_status = 0;  ///< the warm start's NmpcStatus
  int start_iterations = 0;
  std::size_t controller_bytes = 0;
  /// RBD Jacobian calls per linearisation (per path stage x N, + terminal)
  int rbd_calls_per_linearization = 0;
  std::vector<Sample> samples;
  long cg_controller_calls = 0;  ///< samples collected by callgrind
};

void run_fd_analytical(const RunOptions& o, Run& r);
void run_fd_autodiff(const RunOptions& o, Run& r);
void run_id_analytical(const RunOptions& o, Run& r);
void run_id_autodiff(const RunOptions& o, Run& r);
void run_fd_generated(const RunOptions& o, Run& r);
void run_id_generated(const RunOptions& o, Run& r);

const char* status_name(int nmpc_status);
const char* qp_status_name(int qp_status);

}  // namespace fig2
