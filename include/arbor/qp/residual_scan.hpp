// arbor::qp::detail: ResidualScan, one pass over the constraints of the active-set method
// (active_set.hpp): the per-constraint residuals of its termination test and the candidates of its
// working-set change (the most violated constraint not active on that side, the active multiplier
// of the most wrong sign). O(1) per constraint; no state beyond the running maxima.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "arbor/qp/backend.hpp"

namespace arbor::qp::detail {

/// What a pass reads: constraint i < NV is the bound of x_i (row norm 1), i = NV + j the row j with
/// value za_j = (A x)_j and norm rn_j; lam the multipliers, ws the working set.
template <typename Scalar, int NV, int NA>
struct ConstraintValues {
  const Eigen::Matrix<Scalar, NV, 1>& x;
  const Eigen::Matrix<Scalar, NV, 1>& lbx;
  const Eigen::Matrix<Scalar, NV, 1>& ubx;
  const Eigen::Matrix<Scalar, NV, 1>& lam_x;
  const Eigen::Matrix<Scalar, NA, 1>& za;
  const Eigen::Matrix<Scalar, NA, 1>& lba;
  const Eigen::Matrix<Scalar, NA, 1>& uba;
  const Eigen::Matrix<Scalar, NA, 1>& lam_a;
  const Eigen::Matrix<Scalar, NA, 1>& rn;
  const ConstraintState* ws;
};

/// The running maxima of a pass over a range of constraints. Per constraint a violation is divided
/// by the row's norm and a multiplier multiplied by it (the values of any scaling of the row); the
/// _abs maxima are as the data state them (reported).
template <typename Scalar>
struct ResidualScan {
  Scalar pscale = 1;  ///< max(1, |z_i| / |a_i|): the primal scale is 1 + this
  Scalar pr = 0;      ///< max violation, per constraint
  Scalar co = 0;      ///< complementarity residual, per constraint
  Scalar pr_abs = 0;  ///< max violation as the data state it
  Scalar co_abs = 0;  ///< complementarity residual as the data state it
  Scalar sd = 0;      ///< max wrong-sign multiplier on the working set, per constraint
  int isd = -1;       ///< its index (-1: none)
  Scalar pc = 0;      ///< max violation among constraints not active on the violated side
  int ipc = -1;       ///< its index (-1: none)
  ConstraintState spc = ConstraintState::inactive;  ///< the violated side

  /// Continues the pass over the constraints [from, to). finite: every entry it reads is finite
  /// (the caller checked them at once), so the per-entry test is skipped; otherwise a non-finite
  /// value or multiplier makes pr and pr_abs infinite.
  template <int NV, int NA>
  void pass(const ConstraintValues<Scalar, NV, NA>& c, int from, int to, bool finite);

  /// Continues with the pass over the constraints that follow this one's (later): a maximum moves
  /// to later's only when it is strictly larger, so the first index wins as in one pass.
  void merge(const ResidualScan& later) {
    pscale = std::max(pscale, later.pscale);
    pr = std::max(pr, later.pr);
    co = std::max(co, later.co);
    pr_abs = std::max(pr_abs, later.pr_abs);
    co_abs = std::max(co_abs, later.co_abs);
    if (later.sd > sd) {
      sd = later.sd;
      isd = later.isd;
    }
    if (later.pc > pc) {
      pc = later.pc;
      ipc = later.ipc;
      spc = later.spc;
    }
  }
};

template <typename Scalar>
template <int NV, int NA>
void ResidualScan<Scalar>::pass(const ConstraintValues<Scalar, NV, NA>& c, int from, int to,
                                bool finite) {
  using State = ConstraintState;
  constexpr Scalar inf = std::numeric_limits<Scalar>::infinity();
  // the maxima are kept in locals: the working set is int8_t, whose accesses may alias them
  Scalar ps = pscale, vmax = pr, cmax = co, vabs = pr_abs, cabs = co_abs, smax = sd, pmax = pc;
  int is = isd, ip = ipc;
  State side_p = spc;
  const State* w = c.ws;
  // one body for the bounds (n = 1, folded) and the rows: no branch on i < NV per constraint
  const auto visit = [&](auto check, int i, Scalar z, Scalar l, Scalar u, Scalar m, Scalar n) {
    if constexpr (decltype(check)::value) {
      if (!std::isfinite(z) || !std::isfinite(m)) {
        vmax = inf;
        vabs = inf;
        return;
      }
    }
    ps = std::max(ps, std::abs(z) / n);
    const Scalar vl = l - z, vu = z - u;
    const Scalar va = vl > vu ? vl : vu;
    if (va > vabs)
      vabs = va;
    const Scalar v = va / n;
    if (v > vmax)
      vmax = v;
    const State wi = w[i];
    if (v > 0) {
      const State side = vl > vu ? State::lower : State::upper;
      if (wi != side && wi != State::equality && v > pmax) {
        pmax = v;
        ip = i;
        side_p = side;
      }
    }
    if (m != 0) {
      const Scalar dist =
          m > 0 ? (u < inf ? std::abs(u - z) : inf) : (l > -inf ? std::abs(z - l) : inf);
      const Scalar am = std::abs(m);
      const Scalar cm = am < dist ? am : dist;
      if (cm > cabs)
        cabs = cm;
      const Scalar cn = std::min(am * n, dist / n);
      if (cn > cmax)
        cmax = cn;
    }
    if (wi == State::upper || wi == State::lower) {
      const Scalar wrong = -m * side_sign<Scalar>(wi) * n;
      if (wrong > smax) {
        smax = wrong;
        is = i;
      }
    }
  };
  const int bend = std::min(to, NV), rbeg = std::max(from, NV);
  const auto run = [&](auto check) {
    for (int i = from; i < bend; ++i)
      visit(check, i, c.x(i), c.lbx(i), c.ubx(i), c.lam_x(i), Scalar(1));
    for (int j = rbeg - NV; j < to - NV; ++j)
      visit(check, NV + j, c.za(j), c.lba(j), c.uba(j), c.lam_a(j), c.rn(j));
  };
  if (finite)
    run(std::false_type{});
  else
    run(std::true_type{});
  *this = ResidualScan{ps, vmax, cmax, vabs, cabs, smax, is, pmax, ip, side_p};
}

}  // namespace arbor::qp::detail
