// arbor::qp::detail: PreparedStart, what real-time iteration's preparation leaves for the
// feedback's solve (ActiveSetCore::prepare_start() makes it, solve_from() takes it;
// active_set_prepared.hpp): the first iteration's pass over the constraints that the feedback does
// not move, and whether the core's step buffers and factorization hold that iteration's step. A
// value of O(NV) scalars; no code runs here.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "arbor/qp/residual_scan.hpp"

namespace arbor::qp::detail {

template <typename Scalar, int NV, int NA>
class ActiveSetCore;

/// The prepared first iteration of a solve from x = 0 whose QP differs from the prepared one only
/// in the targets of the first n bounds (the OCP's x_0). Valid while the core that made it records
/// no change (ActiveSetCore::note_change(): any write of its iterate, vectors or matrices, any
/// solve); the factorization and the step it refers to are the core's and its backend's. A
/// default-constructed one (or one made without a usable factorization) prepares nothing:
/// solve_from() then runs solve().
template <typename Scalar, int NV>
class PreparedStart {
 public:
  /// How much of the first iteration the preparation left.
  enum class Reuse : std::uint8_t {
    nothing,        ///< no factorization to reuse (not set up, or a pivot failure)
    factorization,  ///< the factorization only (the n bounds are not fixed equalities)
    pass,           ///< and the pass (the first iteration changes the working set)
    step,           ///< and the first step, moved to the targets by one forward solve
  };
  /// Which bounds after the n targets moved since the preparation (move_bound()).
  enum class Moved : std::uint8_t {
    none,     ///< none: the kept pass holds
    bounds,   ///< some: the first iteration passes over every constraint again
    targets,  ///< and targets of working bounds: their moves are in target_moves_
  };

  /// What the preparation left.
  Reuse reuse() const { return first_; }
  /// Blocks the preparation factorized, -1 when nothing will be reused.
  int stages_factorized() const { return first_ == Reuse::nothing ? -1 : stages_; }

 private:
  template <typename S, int V, int A>
  friend class ActiveSetCore;

  Reuse first_ = Reuse::nothing;
  Moved moved_ = Moved::none;
  int n_ = 0;                    ///< the targets: the first n bounds
  int stages_ = 0;               ///< blocks factorized by the preparation
  std::uint32_t revision_ = 0;   ///< the core's change count it belongs to
  Scalar reg_primal_ = 0;        ///< QpSettings::reg_primal it was made with
  Scalar reg_dual_ = 0;          ///< QpSettings::reg_dual
  bool relative_ = false;        ///< QpSettings::relative_regularisation
  bool finite_ = true;           ///< every entry the kept pass read was finite
  ResidualScan<Scalar> rest_{};  ///< the pass over the constraints after the n targets
  /// Moves of working bounds' targets since the preparation (Moved::targets; zero elsewhere).
  Eigen::Matrix<Scalar, NV, 1> target_moves_;
};

}  // namespace arbor::qp::detail
