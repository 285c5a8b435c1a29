// arbor::qp::detail: the primal-dual active-set logic shared by the dense and the OCP solvers.
//
// Problem (flat form; the OCP solver flattens its stages into it):
//   min 1/2 x'Hx + g'x   s.t.  lbx <= x <= ubx,  lba <= A x <= uba,   x in R^NV, A x in R^NA.
// Stack z = [x; A x] (NZ = NV + NA) with one multiplier lam = [lam_x; lam_a]; stationarity reads
// H x + g + lam_x + A' lam_a = 0; lam_i > 0 means "upper bound active", lam_i < 0 "lower active".
//
// Method (QRQP-style, see /work/shared/QRQP.md, our own implementation):
// - An explicit int8 working set ws (0 inactive, -1 lower, +1 upper, 2 equality) is built from
//   the multipliers' signs at the start of every solve (warm start = keep x and lam), and kept
//   consistent afterwards: an inactive constraint has lam_i == 0 exactly.
// - Each iteration evaluates the residuals and makes at most ONE working-set change: a pending
//   change from the last ratio test, else, if the (scaled) primal error dominates, the most
//   violated constraint is added on its violated side, else the active constraint whose
//   multiplier has the most wrong sign is dropped.
// - The step goes to the solution of the equality-constrained QP of the working set, with a
//   proximal regularisation centred at the current iterate (delta = reg_primal on x,
//   epsilon = reg_dual on the active multipliers):
//     (H + delta I + A_W' E A_W) dx = -(H x + g + A' lam) - A_W' E (A_W x - t_W)
//     dlam_W = E (A_W (x + dx) - t_W),   dlam_i = 0 off the working set,
//   with E = diag(1 / (eps |a_i|^2)) (rows normalised; |a_i| = 1 for bounds).
//   The matrix is positive definite for any convex H, whatever the working set: redundant or
//   linearly dependent active constraints and directions of zero curvature (states without
//   cost, LPs) never make it singular. Along a zero-curvature direction the step is long
//   (~ gradient / delta) and the ratio test stops it at the first blocking constraint: this is
//   QRQP's null-space step, obtained without predicting the singularity. Because the proximal
//   terms are centred at the iterate, a fixed point is an exact KKT point; repeated iterations
//   on an unchanged working set reuse the factorization and act as iterative refinement.
// - When the primal error stalls on an unchanged working set (a nearly inconsistent one), the
//   multipliers are moved along their step to the first active one that reaches zero, which is
//   dropped (QRQP's singular step in multiplier space).
// - Ratio test on tau in [0, 1]: inactive constraints may not cross their bound by more than
//   max(tol_primal, current max violation) (primal blocking -> pending add), active multipliers
//   of the right sign may not cross zero (dual break point -> pending drop).
// - Termination by an explicit check on the original data: primal feasibility, stationarity and
//   complementarity (min(|lam_i|, distance to its bound)), with tolerances relative to the data
//   scale (settings.hpp). A Farkas certificate (y = lam/|lam|
//   with A' y ~ 0 and negative support of the bounds) on three consecutive iterates gives
//   `infeasible` (an inconsistent working set makes lam grow like 1/epsilon); a full step along a
//   zero-curvature descent direction that no constraint blocks gives `unbounded`; the iteration
//   cap returns the best iterate seen, with its residuals.
// Memory of this part: about 11 NV + 8 NA scalars and NV + NA bytes. The linear algebra lives in
// a backend with this interface (sizes fixed, no allocation):
//   void hess_mul(const VecV& x, VecV& y) const;   // y = H x
//   void cons_mul(const VecV& x, VecA& y) const;   // y = A x
//   void cons_tmul(const VecA& l, VecV& y) const;  // y = A' l
//   void mark_changed(int i);                      // constraint i (flat z index) changed state
//   void mark_all();                               // everything must be refactorized
//   void row_norms_sq(VecA& n) const;              // n_j = |a_j|^2
//   int factorize(const std::int8_t* ws, Scalar delta, Scalar w, const VecA& wa);  // M with
//       bound weight w = 1/eps and row weights wa; returns blocks factorized, -1 on failure
//   void solve(VecV& b) const;                     // b <- M^-1 b
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "arbor/core/config.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp::detail {

/// Working-set states of a constraint.
enum : std::int8_t { kInactive = 0, kLower = -1, kUpper = 1, kEquality = 2 };

/// Iterate, bounds and workspace of the active-set method (sizes fixed at compile time).
template <typename Scalar, int NV, int NA>
class ActiveSetCore {
 public:
  static constexpr int nv = NV;       ///< number of variables
  static constexpr int na = NA;       ///< number of general constraint rows
  static constexpr int nz = NV + NA;  ///< number of constraints (bounds first)
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;

  VecV lbx, ubx;                     ///< variable bounds (may be +-inf)
  VecA lba, uba;                     ///< constraint-row bounds (may be +-inf)
  VecV g;                            ///< linear cost
  VecV x;                            ///< primal iterate (warm start in, solution out)
  VecV lam_x;                        ///< multipliers of the variable bounds
  VecA lam_a;                        ///< multipliers of the constraint rows
  std::array<std::int8_t, nz> ws{};  ///< working set (see enum above)

  /// x = projection of 0 onto the bounds, all multipliers zero.
  void cold_start() {
    for (int i = 0; i < NV; ++i)
      x(i) = clamp(Scalar(0), lbx(i), ubx(i));
    lam_x.setZero();
    lam_a.setZero();
  }

  /// Runs the method from the current (x, lam); fills info; returns the status.
  template <typename Backend>
  QpStatus solve(Backend& be, const QpSettings<Scalar>& s, SolveInfo<Scalar>& info);

 private:
  static constexpr Scalar inf() { return std::numeric_limits<Scalar>::infinity(); }
  static Scalar clamp(Scalar v, Scalar lo, Scalar hi) { return v < lo ? lo : (v > hi ? hi : v); }

  Scalar lb(int i) const { return i < NV ? lbx(i) : lba(i - NV); }
  Scalar ub(int i) const { return i < NV ? ubx(i) : uba(i - NV); }
  Scalar zval(int i) const { return i < NV ? x(i) : za_(i - NV); }
  Scalar dzval(int i) const { return i < NV ? dx_(i) : dza_(i - NV); }
  Scalar& lam(int i) { return i < NV ? lam_x(i) : lam_a(i - NV); }
  Scalar lam(int i) const { return i < NV ? lam_x(i) : lam_a(i - NV); }
  Scalar dlam(int i) const { return i < NV ? dlam_x_(i) : dlam_a_(i - NV); }
  /// Target value of an active constraint.
  Scalar target(int i) const { return ws[i] == kLower ? lb(i) : ub(i); }

  /// Working set from the multipliers' signs; zeroes multipliers that cannot be active.
  void working_set_from_multipliers();
  /// z = A x, hx = H x, r = H x + g + A' lam and the scalar residuals below.
  template <typename Backend>
  void evaluate(const Backend& be);
  bool infeasibility_certificate(const QpSettings<Scalar>& s) const;
  template <typename Backend>
  bool unboundedness_certificate(const Backend& be, const QpSettings<Scalar>& s);

  // residuals of the last evaluate()
  Scalar pr_ = 0;        ///< max violation
  Scalar du_ = 0;        ///< max |stationarity residual|
  Scalar co_ = 0;        ///< complementarity residual
  Scalar pr_scale_ = 1;  ///< 1 + |z|_inf (scale of the primal and complementarity tolerances)
  Scalar du_scale_ = 1;  ///< 1 + largest term of H x + g + A' lam (scale of the dual one)
  Scalar sd_ = 0;        ///< max wrong-sign multiplier on the working set
  int isd_ = -1;         ///< its index
  Scalar pc_ = 0;        ///< max violation among constraints that are not active on that side
  int ipc_ = -1;         ///< its index
  std::int8_t spc_ = 0;  ///< the violated side

  VecA za_;          ///< A x
  VecV hx_;          ///< H x
  VecV r_;           ///< stationarity residual
  VecV dx_;          ///< primal step (also the right-hand side)
  VecA dza_;         ///< A dx
  VecV dlam_x_;      ///< bound-multiplier step
  VecA dlam_a_;      ///< row-multiplier step
  VecA tmpa_;        ///< row workspace
  VecA wa_;          ///< regularisation weight of each row, 1 / (eps |a_j|^2)
  VecV best_x_;      ///< best iterate so far
  VecV best_lam_x_;  ///< its bound multipliers
  VecA best_lam_a_;  ///< its row multipliers
};

template <typename Scalar, int NV, int NA>
void ActiveSetCore<Scalar, NV, NA>::working_set_from_multipliers() {
  for (int i = 0; i < nz; ++i) {
    const Scalar l = lb(i), u = ub(i), m = lam(i);
    if (l == u) {
      ws[i] = kEquality;
    } else if (m > 0 && u < inf()) {
      ws[i] = kUpper;
    } else if (m < 0 && l > -inf()) {
      ws[i] = kLower;
    } else {
      ws[i] = kInactive;
      lam(i) = 0;
    }
  }
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
void ActiveSetCore<Scalar, NV, NA>::evaluate(const Backend& be) {
  be.cons_mul(x, za_);
  be.hess_mul(x, hx_);
  be.cons_tmul(lam_a, r_);
  r_ += hx_ + g + lam_x;
  du_ = r_.size() > 0 ? r_.cwiseAbs().maxCoeff() : Scalar(0);
  if (!std::isfinite(du_))
    du_ = inf();
  // scales of the relative tolerances: |z|_inf and the largest term of the stationarity sum
  du_scale_ = Scalar(1);
  for (int i = 0; i < NV; ++i) {
    du_scale_ = std::max(du_scale_, std::abs(hx_(i)));
    du_scale_ = std::max(du_scale_, std::abs(g(i)));
    du_scale_ = std::max(du_scale_, std::abs(r_(i) - hx_(i) - g(i)));
  }
  pr_scale_ = Scalar(1);
  pr_ = 0;
  co_ = 0;
  sd_ = 0;
  isd_ = -1;
  pc_ = 0;
  ipc_ = -1;
  spc_ = 0;
  for (int i = 0; i < nz; ++i) {
    const Scalar z = zval(i), l = lb(i), u = ub(i), m = lam(i);
    if (!std::isfinite(z) || !std::isfinite(m)) {
      pr_ = inf();
      continue;
    }
    pr_scale_ = std::max(pr_scale_, std::abs(z));
    const Scalar vl = l - z, vu = z - u;
    const Scalar v = vl > vu ? vl : vu;
    if (v > pr_)
      pr_ = v;
    if (v > 0) {
      const std::int8_t side = vl > vu ? kLower : kUpper;
      if (ws[i] != side && ws[i] != kEquality && v > pc_) {
        pc_ = v;
        ipc_ = i;
        spc_ = side;
      }
    }
    if (m != 0) {
      const Scalar dist =
          m > 0 ? (u < inf() ? std::abs(u - z) : inf()) : (l > -inf() ? std::abs(z - l) : inf());
      const Scalar am = std::abs(m);
      const Scalar c = am < dist ? am : dist;
      if (c > co_)
        co_ = c;
    }
    if (ws[i] == kUpper || ws[i] == kLower) {
      const Scalar wrong = -m * ws[i];
      if (wrong > sd_) {
        sd_ = wrong;
        isd_ = i;
      }
    }
  }
}

template <typename Scalar, int NV, int NA>
bool ActiveSetCore<Scalar, NV, NA>::infeasibility_certificate(const QpSettings<Scalar>& s) const {
  // y = lam / |lam|_inf; A' y + y_x = (r - H x - g) / |lam|_inf.
  Scalar nl = 0;
  for (int i = 0; i < nz; ++i)
    nl = std::max(nl, std::abs(lam(i)));
  if (!(nl > 0) || !std::isfinite(nl))
    return false;
  Scalar cert = 0;
  for (int i = 0; i < NV; ++i)
    cert = std::max(cert, std::abs(r_(i) - hx_(i) - g(i)));
  cert /= nl;
  if (cert > s.tol_certificate)
    return false;
  Scalar sigma = 0;
  for (int i = 0; i < nz; ++i) {
    const Scalar m = lam(i) / nl;
    if (m > 0) {
      if (!(ub(i) < inf()))
        return false;
      sigma += ub(i) * m;
    } else if (m < 0) {
      if (!(lb(i) > -inf()))
        return false;
      sigma += lb(i) * m;
    }
  }
  return sigma < -Scalar(10) * (s.tol_primal + s.tol_certificate);
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
bool ActiveSetCore<Scalar, NV, NA>::unboundedness_certificate(const Backend& be,
                                                              const QpSettings<Scalar>& s) {
  // d = dx / |dx|_inf must have H d ~ 0, g'd < 0 and stay in the recession cone of the bounds.
  const Scalar nd = dx_.cwiseAbs().maxCoeff();
  if (!(nd > 0) || !std::isfinite(nd))
    return false;
  const Scalar tol = s.tol_certificate;
  for (int i = 0; i < nz; ++i) {
    const Scalar d = dzval(i) / nd;
    if (ub(i) < inf() && d > tol)
      return false;
    if (lb(i) > -inf() && d < -tol)
      return false;
  }
  VecV& hd = dlam_x_;  // reused as workspace: the step has been applied already
  be.hess_mul(dx_, hd);
  if (hd.cwiseAbs().maxCoeff() / nd > tol * (Scalar(1) + hx_.cwiseAbs().maxCoeff()))
    return false;
  return g.dot(dx_) / nd < -tol * (Scalar(1) + g.cwiseAbs().maxCoeff());
}

template <typename Scalar, int NV, int NA>
template <typename Backend>
QpStatus ActiveSetCore<Scalar, NV, NA>::solve(Backend& be, const QpSettings<Scalar>& s,
                                              SolveInfo<Scalar>& info) {
  info = SolveInfo<Scalar>{};
  ARBOR_ASSERT(s.reg_primal > 0 && s.reg_dual > 0, "regularisations must be positive");
  for (int i = 0; i < NV; ++i) {
    if (!std::isfinite(x(i)) || !std::isfinite(lam_x(i))) {
      cold_start();
      break;
    }
  }
  for (int i = 0; i < NA; ++i) {
    if (!std::isfinite(lam_a(i))) {
      cold_start();
      break;
    }
  }
  working_set_from_multipliers();
  Scalar delta = s.reg_primal;
  const Scalar w = Scalar(1) / s.reg_dual;
  // row weights 1 / (eps |a_j|^2): the regularisation acts on normalised rows, so rows with
  // small coefficients (a linearised path constraint) converge as fast as bounds
  be.row_norms_sq(wa_);
  for (int j = 0; j < NA; ++j)
    wa_(j) = wa_(j) > 0 ? w / wa_(j) : w;
  QpStatus status = QpStatus::iteration_limit;
  bool refactor = true;
  be.mark_all();
  int pending = -1;                    // index of a pending change from the ratio test
  std::int8_t pending_ws = kInactive;  // its next working-set state
  Scalar best = inf();
  bool have_best = false;
  bool unbounded_candidate = false;
  int certificate_count = 0;
  bool refining = false;  // the previous iteration left the working set unchanged
  Scalar pr_prev = inf();

  for (int it = 0;; ++it) {
    evaluate(be);
    if (!std::isfinite(pr_) || !std::isfinite(du_)) {
      status = QpStatus::non_finite;
      break;
    }
    const Scalar merit =
        std::max(std::max(pr_ / (s.tol_primal * pr_scale_), du_ / (s.tol_dual * du_scale_)),
                 co_ / (s.tol_comp * pr_scale_));
    if (merit < best) {
      best = merit;
      have_best = true;
      best_x_ = x;
      best_lam_x_ = lam_x;
      best_lam_a_ = lam_a;
    }
    if (merit <= 1) {
      status = QpStatus::solved;
      break;
    }
    if (unbounded_candidate && pr_ <= s.tol_primal) {
      status = QpStatus::unbounded;
      break;
    }
    unbounded_candidate = false;
    // a certificate that holds on several consecutive iterates (transients do not count)
    certificate_count = infeasibility_certificate(s) ? certificate_count + 1 : 0;
    if (certificate_count >= 3) {
      status = QpStatus::infeasible;
      break;
    }
    if (it >= s.max_iter)
      break;
    info.iterations = it + 1;

    // ---- at most one working-set change
    int change = -1;
    std::int8_t change_ws = kInactive;
    if (pending >= 0) {
      change = pending;
      change_ws = pending_ws;
    } else if (ipc_ >= 0 && pc_ > s.tol_primal && pc_ / s.tol_primal >= sd_ / s.tol_dual) {
      change = ipc_;
      change_ws = spc_;
    } else if (isd_ >= 0 && sd_ > s.tol_dual) {
      change = isd_;
      change_ws = kInactive;
    }
    pending = -1;
    bool changed = false;
    if (change >= 0 && ws[change] != change_ws && ws[change] != kEquality) {
      changed = true;
      ws[change] = change_ws;
      const bool had_multiplier = lam(change) != 0;
      lam(change) = 0;
      if (had_multiplier)
        evaluate(be);  // r must not keep the dropped multiplier
      be.mark_changed(change);
      refactor = true;
      ++info.active_set_changes;
    }
    if (refactor) {
      for (;;) {
        const int done = be.factorize(ws.data(), delta, w, wa_);
        if (done >= 0) {
          info.stages_factorized += done;
          break;
        }
        delta *= Scalar(10);
        ++info.regularization_bumps;
        be.mark_all();
        if (delta > s.reg_primal_max) {
          status = QpStatus::non_convex;
          break;
        }
      }
      if (status == QpStatus::non_convex)
        break;
      ++info.factorizations;
      refactor = false;
    }

    // ---- step to the regularised equality-constrained QP of the working set
    tmpa_.setZero();
    for (int j = 0; j < NA; ++j) {
      if (ws[NV + j] != kInactive)
        tmpa_(j) = wa_(j) * (za_(j) - target(NV + j));
    }
    be.cons_tmul(tmpa_, dx_);
    dx_ = -(dx_ + r_);
    for (int i = 0; i < NV; ++i) {
      if (ws[i] != kInactive)
        dx_(i) -= w * (x(i) - target(i));
    }
    be.solve(dx_);
    be.cons_mul(dx_, dza_);
    for (int i = 0; i < nz; ++i) {
      const Scalar wi = i < NV ? w : wa_(i - NV);
      const Scalar d = ws[i] != kInactive ? wi * (zval(i) - target(i) + dzval(i)) : -lam(i);
      if (i < NV) {
        dlam_x_(i) = d;
      } else {
        dlam_a_(i - NV) = d;
      }
    }

    // ---- ratio test
    Scalar tau = 1;
    const Scalar e = std::max(s.tol_primal, pr_);
    for (int i = 0; i < nz; ++i) {
      const Scalar dz = dzval(i);
      if (ws[i] == kInactive) {
        if (dz > 0 && ub(i) < inf()) {
          const Scalar t = std::max(Scalar(0), ub(i) + e - zval(i)) / dz;
          if (t < tau) {
            tau = t;
            pending = i;
            pending_ws = kUpper;
          }
        } else if (dz < 0 && lb(i) > -inf()) {
          const Scalar t = std::min(Scalar(0), lb(i) - e - zval(i)) / dz;
          if (t < tau) {
            tau = t;
            pending = i;
            pending_ws = kLower;
          }
        }
      } else if (ws[i] == kUpper || ws[i] == kLower) {
        const Scalar m = lam(i) * ws[i], dm = dlam(i) * ws[i];
        if (m > 0 && dm < 0) {
          const Scalar t = m / -dm;
          if (t < tau) {
            tau = t;
            pending = i;
            pending_ws = kInactive;
          }
        }
      }
    }
    // Stagnation on an unchanged working set: the primal error does not fall although full
    // steps are taken, so the working set is (nearly) inconsistent and the multipliers drift
    // along a null-space direction of A_W'. Follow that direction to the first active multiplier
    // that reaches zero and drop its constraint (QRQP's singular step, in multiplier space).
    Scalar tau_dual = tau;
    if (tau == Scalar(1) && pending < 0 && !changed && refining && pr_ > s.tol_primal &&
        pr_ > Scalar(0.5) * pr_prev) {
      Scalar tmin = inf();
      for (int i = 0; i < nz; ++i) {
        if (ws[i] != kUpper && ws[i] != kLower)
          continue;
        const Scalar m = lam(i) * ws[i], dm = dlam(i) * ws[i];
        if (m >= 0 && dm < 0 && m / -dm < tmin) {
          tmin = m / -dm;
          pending = i;
          pending_ws = kInactive;
        }
      }
      if (pending >= 0)
        tau_dual = tmin > tau ? tmin : tau;
    }
    refining = !changed;
    pr_prev = pr_;
    x += tau * dx_;
    lam_x += tau_dual * dlam_x_;
    lam_a += tau_dual * dlam_a_;
    if (pending >= 0 && pending_ws == kInactive)
      lam(pending) = 0;
    if (tau == Scalar(1) && delta * dx_.cwiseAbs().maxCoeff() > s.tol_dual &&
        unboundedness_certificate(be, s)) {
      unbounded_candidate = true;  // confirmed if the next iterate is primal feasible
    }
  }

  if (status != QpStatus::solved && status != QpStatus::infeasible &&
      status != QpStatus::unbounded && have_best) {
    x = best_x_;
    lam_x = best_lam_x_;
    lam_a = best_lam_a_;
    working_set_from_multipliers();
    evaluate(be);
  }
  // explicit final check on the original data (residuals of the returned iterate)
  info.primal_residual = pr_;
  info.dual_residual = du_;
  info.complementarity = co_;
  info.objective = Scalar(0.5) * x.dot(hx_) + g.dot(x);
  int na_ws = 0;
  for (int i = 0; i < nz; ++i)
    na_ws += ws[i] != kInactive ? 1 : 0;
  info.active_constraints = na_ws;
  if (status == QpStatus::solved &&
      !(pr_ <= s.tol_primal * pr_scale_ && du_ <= s.tol_dual * du_scale_ &&
        co_ <= s.tol_comp * pr_scale_)) {
    status = QpStatus::iteration_limit;
  }
  return status;
}

}  // namespace arbor::qp::detail
