// arbor::qp: solver settings with defaults per scalar type (double, float), and whether
// setup()/update() check convexity (Convexity).
//
// Tolerances are relative and judged per constraint (active_set.hpp): a row's violation is
// divided by its norm |a_i| and its multiplier multiplied by it, so scaling a row changes no test;
// a residual passes when it is below tol * (1 + scale), with scale max(1, |x|_inf, |z_i| / |a_i|)
// for the primal and complementarity residuals and the largest of |H x|_inf, |g|_inf,
// |A' lam + lam_x|_inf for the dual one (cancellation in float makes absolute tolerances
// unreachable on data of magnitude 10-100). tol_certificate: a Farkas certificate must prove
// that no point within 1 / tol_certificate times that scale is feasible. reg_primal (delta) and
// reg_dual (epsilon) are the proximal regularisations of every linear solve (see active_set.hpp):
// delta > 0 makes zero-curvature directions (a path parameter without cost, an LP) solvable and
// turns them into long steps that the ratio test cuts at the first blocking constraint; epsilon > 0
// keeps dependent active constraints solvable. Neither changes the solution: both are centred at
// the current iterate. With relative_regularisation, epsilon is relative to the curvature: the
// weights are h / reg_dual with h the largest |H_ii| (1 when H = 0), so multiplying the cost by
// any s > 0 gives the same steps (with the absolute epsilon, float solves of rank-deficient
// problems stall from s = 100 on; tests/qp/qp_float_test.cpp), and delta's cap is reg_primal_max
// or 1000 eps h (float: 1.2e-4 h), whichever is larger. Not the default: on the float contour
// closed loop (costs with curvatures from 1e-3 to ~1e3 side by side) the weights h / reg_dual
// doubled the QP iterations (238 against 112 over 50 samples, tests/contour/target_test.cpp);
// a weight per constraint from its own curvature would serve both (docs/qp.md).
#pragma once

#include <type_traits>

namespace arbor::qp {

/// Whether setup()/update() verify that the Hessian (each stage block of an OcpQp) is positive
/// semidefinite. The check is one Cholesky per block: about 12 % of a warm-started Kinova-sized
/// solve (bench/qp/RESULTS.md).
enum class Convexity : unsigned char {
  checked,  ///< verify; a non-convex block makes the call return QpStatus::non_convex (default)
  assumed,  ///< the caller guarantees convexity (e.g. Gauss-Newton Hessians): skip the check
};

/// Name of a Convexity value, for logs and test messages.
constexpr const char* to_string(Convexity c) {
  switch (c) {
    case Convexity::checked:
      return "checked";
    case Convexity::assumed:
      return "assumed";
  }
  return "unknown";
}

/// Whether update() checks the stage matrices for non-finite values (the vectors and bounds are
/// always checked). The check reads every matrix entry once: about 32 k Cortex-M7 instructions
/// per update of the Kinova contour QP (16 stages), 1 % of a real-time sample.
enum class Finiteness : unsigned char {
  checked,  ///< verify; a NaN or infinity makes the call return QpStatus::non_finite (default)
  assumed,  ///< the caller checked the matrices since it last wrote them (e.g. nmpc::Nmpc)
};

/// Settings of the active-set solvers.
template <typename Scalar>
struct QpSettings;

/// Double-precision defaults.
template <>
struct QpSettings<double> {
  int max_iter = 200;             ///< hard cap on iterations (real-time use)
  double tol_primal = 1e-8;       ///< max allowed constraint violation
  double tol_dual = 1e-8;         ///< max allowed stationarity residual
  double tol_comp = 1e-8;         ///< max allowed complementarity residual
  double reg_primal = 1e-8;       ///< delta: primal proximal weight (> 0)
  double reg_dual = 1e-6;         ///< epsilon: dual proximal weight (> 0), relative to h
  double reg_primal_max = 1e-3;   ///< delta is raised tenfold up to this on round-off failure
  double tol_certificate = 1e-6;  ///< relative tolerance of infeasibility/unboundedness tests
  double psd_tolerance = 1e-10;   ///< relative eigenvalue slack of the convexity check
  bool relative_regularisation = false;  ///< weights h / reg_dual (scale-invariant; see above)
  /// At max_iter, return the last iterate (the progress of a solve cut short, e.g. the NMPC's
  /// bounded feedback) instead of the best seen by merit (which may be the starting point)
  bool last_iterate_at_cap = false;
  /// Field by field (not the padding bytes).
  friend bool operator==(const QpSettings&, const QpSettings&) = default;
};

/// Single-precision defaults (tolerances scaled for float's 24-bit mantissa).
template <>
struct QpSettings<float> {
  int max_iter = 200;             ///< hard cap on iterations (real-time use)
  float tol_primal = 1e-4f;       ///< max allowed constraint violation
  float tol_dual = 1e-4f;         ///< max allowed stationarity residual
  float tol_comp = 1e-4f;         ///< max allowed complementarity residual
  float reg_primal = 1e-4f;       ///< delta: primal proximal weight (> 0)
  float reg_dual = 1e-3f;         ///< epsilon: dual proximal weight (> 0), relative to h
  float reg_primal_max = 1e-1f;   ///< delta is raised tenfold up to this on round-off failure
  float tol_certificate = 1e-3f;  ///< relative tolerance of infeasibility/unboundedness tests
  float psd_tolerance = 1e-5f;    ///< relative eigenvalue slack of the convexity check
  bool relative_regularisation = false;  ///< weights h / reg_dual (scale-invariant; see above)
  /// At max_iter, return the last iterate (the progress of a solve cut short, e.g. the NMPC's
  /// bounded feedback) instead of the best seen by merit (which may be the starting point)
  bool last_iterate_at_cap = false;
  /// Field by field (not the padding bytes).
  friend bool operator==(const QpSettings&, const QpSettings&) = default;
};

/// Settings of the interior-point cold start (OcpInteriorPoint, ocp_interior_point.hpp). For a
/// crossover the interior point need not be accurate: the active set finishes; tol decides how
/// close to the end of the central path the guess is taken.
template <typename Scalar>
struct IpmSettings {
  int max_iter = 30;  ///< interior-point iterations at most
  /// converged: residuals <= tol (1 + data scale) and mean complementarity <= tol
  Scalar tol = std::is_same_v<Scalar, float> ? Scalar(1e-4) : Scalar(1e-8);
  /// smallest initial slack; initial multipliers (1: on the Kinova-sized benchmark QPs 13 / 22
  /// iterations (FD / ID), 10: 11 / 14, but more on the random test problems and a float FD
  /// crossover 4x longer)
  Scalar init = Scalar(1);
  Scalar boundary = Scalar(0.995);  ///< fraction to the boundary of each step
  /// proximal term on every free variable (keeps R + B' P B definite when H is only PSD)
  Scalar reg = std::is_same_v<Scalar, float> ? Scalar(1e-6) : Scalar(1e-10);
};

}  // namespace arbor::qp
