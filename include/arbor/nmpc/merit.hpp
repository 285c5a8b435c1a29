// arbor::nmpc: the line search's memory (MeritHistory): the L1 merit's penalty weight nu (raised
// to a margin over the QP's multipliers, never lowered) and the merits of the last accepted
// points, whose largest is the non-monotone Armijo reference (Grippo, Lampariello, Lucidi 1986),
// so that full steps near a solution survive the Maratos effect. O(1) per call.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

namespace arbor::nmpc::detail {

/// Penalty and accepted merits of the full solves from one initial state x0 (nx states).
template <class Scalar, int nx>
class MeritHistory {
 public:
  using Vx = Eigen::Matrix<Scalar, nx, 1>;

  /// A solve from x0: the history restarts unless x0 is the last solve's (another problem).
  void start(const Vx& x0) {
    if (x0 != last_x0_)
      count_ = 0;
    last_x0_ = x0;
  }
  /// Raises the penalty to margin * lam_max when below it, restarting the history (merits of
  /// another penalty are not comparable); returns the penalty.
  Scalar raise_penalty(Scalar lam_max, Scalar margin) {
    if (margin * lam_max > penalty_) {
      penalty_ = margin * lam_max;
      count_ = 0;
    }
    return penalty_;
  }
  Scalar penalty() const { return penalty_; }
  /// The Armijo reference: the largest of phi_now and the merits of the last accepted points.
  Scalar reference(Scalar phi_now) const {
    const int n = count_ < int(recent_.size()) ? count_ : int(recent_.size());
    for (int i = 0; i < n; ++i)
      phi_now = std::fmax(phi_now, recent_[std::size_t(i)]);
    return phi_now;
  }
  /// Records an accepted point's merit.
  void accept(Scalar phi) {
    recent_[std::size_t(count_ % int(recent_.size()))] = phi;
    ++count_;
  }

 private:
  Scalar penalty_ = 0;              ///< nu
  std::array<Scalar, 4> recent_{};  ///< merits of the last accepted points (a ring)
  int count_ = 0;                   ///< points accepted since the last restart
  Vx last_x0_ = Vx::Constant(std::numeric_limits<Scalar>::quiet_NaN());  ///< x0 of the history
};

}  // namespace arbor::nmpc::detail
