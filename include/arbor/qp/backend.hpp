// arbor::qp::detail: the interface between the active-set logic (active_set.hpp) and its linear
// algebra (dense_backend.hpp, ocp_riccati_backend.hpp), written as a C++20 concept, and the
// working-set states both sides read. Declarations only: no code runs here.
//
// A backend owns the factorization of M = H + delta I + A_W' E A_W (active_set.hpp) for the
// working set W, and the products with the problem's H and A (PenalisedBackend), or the
// factorization of the KKT matrix of the rows it solves exactly with M of the others
// (ExactRowBackend: ocp_riccati_backend.hpp, the dynamics rows by a Riccati recursion). Sizes
// are fixed at compile time and no member may allocate.
#pragma once

#include <Eigen/Core>
#include <concepts>
#include <cstdint>

namespace arbor::qp::detail {

/// State of one constraint (a variable bound or a row) in the working set. The values of lower
/// and upper are the signs their multipliers must have.
enum class ConstraintState : std::int8_t {
  inactive = 0,  ///< not in the working set; its multiplier is exactly 0
  lower = -1,    ///< held at its lower bound (multiplier <= 0)
  upper = 1,     ///< held at its upper bound (multiplier >= 0)
  equality = 2,  ///< lower bound == upper bound: always active, multiplier of either sign
};

/// -1 for lower, +1 for upper (0 for inactive), as a Scalar.
template <typename Scalar>
constexpr Scalar side_sign(ConstraintState c) {
  return Scalar(static_cast<std::int8_t>(c));
}

/// What every backend provides, for a QP with NV variables and NA rows; z indices are flat:
/// bounds 0..NV-1, then rows NV..NV+NA-1.
template <typename B, typename Scalar, int NV, int NA>
concept BackendProducts = requires(B& b, const B& cb, const Eigen::Matrix<Scalar, NV, 1>& v,
                                   Eigen::Matrix<Scalar, NV, 1>& v_out,
                                   const Eigen::Matrix<Scalar, NA, 1>& a,
                                   Eigen::Matrix<Scalar, NA, 1>& a_out, const ConstraintState* ws,
                                   Scalar s, int i) {
  cb.hess_mul(v, v_out);   // v_out = H v
  cb.cons_mul(v, a_out);   // a_out = A v
  cb.cons_tmul(a, v_out);  // v_out = A' a
  cb.row_norms_sq(a_out);  // a_out_j = |a_j|^2
  // the largest |H_ii|: the curvature scale the regularisations are taken relative to
  { cb.hessian_scale() } -> std::convertible_to<Scalar>;
  b.mark_changed(i);  // constraint i changed state: refactorize what it touches
  b.mark_all();       // everything must be refactorized (new data, new delta)
  // factorizes for the working set ws[0..NV+NA) with delta, the bound weight w = h/eps
  // and the row weights a; returns the number of blocks factorized, -1 on a pivot failure
  { b.factorize(ws, s, s, a) } -> std::same_as<int>;
};

/// A backend that treats every working constraint by the proximal weights: it factorizes
/// M = H + delta I + A_W' E A_W and solves with it.
template <typename B, typename Scalar, int NV, int NA>
concept PenalisedBackend = BackendProducts<B, Scalar, NV, NA> &&
    requires(const B& cb, Eigen::Matrix<Scalar, NV, 1>& v_out) {
  cb.solve(v_out);  // v_out <- M^-1 v_out
};

/// A backend that solves some rows exactly (the OCP's dynamics, by a Riccati recursion): the
/// rows j with exact_row(j) are equalities, always in the working set, and take no proximal
/// weight; likewise the bounds i with exact_bound(i) hold exactly while they are in the working
/// set (the variable is fixed, removed from the recursion: no weight either). It factorizes the
/// KKT matrix [M_P D' E_B'; D 0 0; E_B 0 0] with M_P = H + delta I + A_P' E A_P (A_P: the other
/// working rows and bounds, D: the exact rows, E_B: the working exact bounds, rows of I) and
/// solve_exact(v, a, c, wa) (wa: the row weights given to factorize()) solves
///   M_P dx + D' dnu + E_B' dlam_B = v,   D dx = a_D,   E_B dx = c_B
/// in place: v <- dx, a_j <- dnu_j on the exact rows, c_i <- dlam_i on the working exact bounds
/// (the other entries of a and c are not read and keep their values).
template <typename B, typename Scalar, int NV, int NA>
concept ExactRowBackend = BackendProducts<B, Scalar, NV, NA> &&
    requires(const B& cb, Eigen::Matrix<Scalar, NV, 1>& v_out, Eigen::Matrix<Scalar, NA, 1>& a_out,
             const Eigen::Matrix<Scalar, NA, 1>& wa, int j) {
  { B::exact_row(j) } -> std::same_as<bool>;
  { B::exact_bound(j) } -> std::same_as<bool>;
  cb.solve_exact(v_out, a_out, v_out, wa);
};

/// An ExactRowBackend that also multiplies by the rows it does not solve exactly alone (A_P x,
/// A_P' l): compute_step() then needs no product with the exact rows (their A dx is the e the
/// solve was given, and only A_P enters the right-hand side).
template <typename B, typename Scalar, int NV, int NA>
concept PathProducts = ExactRowBackend<B, Scalar, NV, NA> &&
    requires(const B& cb, const Eigen::Matrix<Scalar, NV, 1>& v,
             Eigen::Matrix<Scalar, NV, 1>& v_out, const Eigen::Matrix<Scalar, NA, 1>& a,
             Eigen::Matrix<Scalar, NA, 1>& a_out) {
  cb.path_mul(v, a_out);   // a_out = A_P v on the non-exact rows, the others unchanged
  cb.path_tmul(a, v_out);  // v_out = A_P' a (a's exact rows not read)
};

/// Linear algebra of the active-set method: either kind.
template <typename B, typename Scalar, int NV, int NA>
concept ActiveSetBackend =
    PenalisedBackend<B, Scalar, NV, NA> || ExactRowBackend<B, Scalar, NV, NA>;

}  // namespace arbor::qp::detail
