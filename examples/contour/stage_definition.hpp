// The contour OCPs as problem definitions for generated stage code (arbor/ocp/generated_stage.hpp,
// CMake arbor_add_stage_ad): the problem mpc.hpp builds with the default options of a
// controller at scalar Scalar (c = 0.2, hard or soft tunnel of slack weight 100 and radius rho
// less default_backoff<Scalar>, the unscaled tunnel row), analytical RBD derivatives, RK4
// sensitivities as task.hpp's rk4_sensitivity. The generated code folds these constants in; a
// loop run with other values uses the expression layer (mpc.hpp checks).
#pragma once

#include "task.hpp"

namespace contour {

/// Formulation F, tunnel Soft, the back-off of a controller at scalar Scalar.
template <Formulation F, bool Soft = false, class Scalar = double>
struct StageDefinition {
  static constexpr double c = 0.2;                                 ///< sd_ref scale
  static constexpr double soft_weight = 100.0;                     ///< slack weight (Soft)
  static constexpr double radius = rho - default_backoff<Scalar>;  ///< the controller's tunnel
  template <class T>
  using Workspace = contour::Workspace<arbor::ad::Analytical, T>;
  template <class W>
  static auto problem(W& ws) {
    return make_problem<F, arbor::ad::Analytical, Soft>(ws, make_reference(c), soft_weight, radius,
                                                        false);
  }
};

using FdStage = StageDefinition<Formulation::fd>;  ///< the demo's OCP (double)
using IdStage = StageDefinition<Formulation::id>;  ///< OCP-ID (double): its torque rows are hard
using FdStageFloat = StageDefinition<Formulation::fd, false, float>;  ///< OCP-FD, float
using IdStageFloat = StageDefinition<Formulation::id, false, float>;  ///< OCP-ID, float

}  // namespace contour
