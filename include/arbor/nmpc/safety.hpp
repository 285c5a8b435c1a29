// arbor::nmpc: the controller's safety policy (SafetyPolicy): recovery from a measured state
// outside its bounds (the violated state bounds of the first stages relaxed to a straight line
// back to the bound, NmpcSettings::recovery_stages) and the fallback of a QP that keeps failing
// (NmpcSettings::fallback: the relaxed QP, or the user's stop law clipped to the input bounds).
// Cost: O(recovery_stages nx) per recovery, O(N (nx + ng)) to relax a QP; no allocation.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

#include "arbor/nmpc/settings.hpp"

namespace arbor::nmpc::detail {

/// What a call whose QP failed does next (SafetyPolicy::qp_failed).
enum class Fallback : unsigned char {
  none,   ///< report qp_failed: control() replays the stale plan
  relax,  ///< solve the relaxed QP (relax_qp); if that fails too, the stop law if one is set
  stop,   ///< the stop law
};

/// Recovery and fallback of an Nmpc controller with nx states and nu inputs. Its state is the
/// count of consecutive calls whose QP failed and the user's stop law.
template <class Scalar, int nx, int nu>
class SafetyPolicy {
 public:
  using Vx = Eigen::Matrix<Scalar, nx, 1>;
  using Vu = Eigen::Matrix<Scalar, nu, 1>;
  using StopLaw = Vu (*)(const Vx& x, void* user);

  void set_stop_law(StopLaw law, void* user) {
    stop_law_ = law;
    stop_user_ = user;
  }

  /// Relaxes, on stages 1..K of qp (K = min(recovery_stages, N)), the state bounds that the
  /// measured x0 violates (judged against the plan's bounds of stage 0, lbx[0], ubx[0]) to the
  /// straight line from x0's value back to the bound at stage K + 1; qp's bounds are in delta
  /// form around the planned states x. Writes the violation to `violation`; returns K, or 0
  /// when nothing was relaxed (no violation beyond tol_primal, or recovery_stages <= 0).
  template <class Qp, std::size_t M>
  static int relax_violated_bounds(const NmpcSettings<Scalar>& s, const Vx& x0,
                                   const std::array<Vx, M>& lbx, const std::array<Vx, M>& ubx,
                                   const std::array<Vx, M>& x, Qp& qp, Scalar& violation) {
    constexpr int N = int(M) - 1;
    const Vx over = (x0 - ubx[0]).cwiseMax(Scalar(0));
    const Vx under = (lbx[0] - x0).cwiseMax(Scalar(0));
    violation = std::fmax(over.maxCoeff(), under.maxCoeff());
    const int K = s.recovery_stages < N ? s.recovery_stages : N;
    if (K <= 0 || !(violation > s.tol_primal))
      return 0;
    for (int k = 1; k <= K; ++k) {
      const std::size_t i = std::size_t(k);
      const Scalar frac = Scalar(K + 1 - k) / Scalar(K + 1);
      auto& lb = k < N ? qp.stage[i].lbx : qp.terminal.lbx;
      auto& ub = k < N ? qp.stage[i].ubx : qp.terminal.ubx;
      for (int j = 0; j < nx; ++j) {
        if (over[j] > s.tol_primal)
          ub[j] = std::fmax(ub[j], ubx[i][j] + frac * over[j] - x[i][j]);
        if (under[j] > s.tol_primal)
          lb[j] = std::fmin(lb[j], lbx[i][j] - frac * under[j] - x[i][j]);
      }
    }
    return K;
  }

  /// A call's QP gave a step: the count of consecutive failures restarts.
  void qp_succeeded() { failed_samples_ = 0; }
  /// Counts a call whose QP failed; from the max_failed_samples-th consecutive one (>= 1), the
  /// fallback of settings s (relax when the stop policy has no stop law).
  Fallback qp_failed(const NmpcSettings<Scalar>& s) {
    ++failed_samples_;
    const int after = s.max_failed_samples > 1 ? s.max_failed_samples : 1;
    if (s.fallback == FallbackPolicy::stale_plan || failed_samples_ < after)
      return Fallback::none;
    return s.fallback == FallbackPolicy::relax || stop_law_ == nullptr ? Fallback::relax
                                                                       : Fallback::stop;
  }
  /// Consecutive calls whose QP failed.
  int failed_samples() const { return failed_samples_; }

  /// The relaxed QP: the state bounds of stages >= 1 and every constraint row dropped (x_0's
  /// bounds, the measurement, and the input bounds kept: always feasible).
  template <class Qp>
  static void relax_qp(Qp& qp) {
    constexpr Scalar inf = std::numeric_limits<Scalar>::infinity();
    for (std::size_t k = 0; k < qp.stage.size(); ++k) {
      auto& st = qp.stage[k];
      if (k > 0) {
        st.lbx.setConstant(-inf);
        st.ubx.setConstant(inf);
      }
      st.lg.setConstant(-inf);
      st.ug.setConstant(inf);
    }
    qp.terminal.lbx.setConstant(-inf);
    qp.terminal.ubx.setConstant(inf);
    qp.terminal.lg.setConstant(-inf);
    qp.terminal.ug.setConstant(inf);
  }

  /// The stop law's control at x0 clipped to [lb, ub] into u; false (u unchanged) when no law
  /// is set or its value is not finite.
  bool stop_control(const Vx& x0, const Vu& lb, const Vu& ub, Vu& u) const {
    if (stop_law_ == nullptr)
      return false;
    const Vu v = stop_law_(x0, stop_user_).cwiseMax(lb).cwiseMin(ub);
    if (!v.allFinite())
      return false;
    u = v;
    return true;
  }

 private:
  StopLaw stop_law_ = nullptr;  ///< the stop law (nullptr: none)
  void* stop_user_ = nullptr;   ///< its user pointer
  int failed_samples_ = 0;      ///< consecutive calls whose QP failed
};

}  // namespace arbor::nmpc::detail
