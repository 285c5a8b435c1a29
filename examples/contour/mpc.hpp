// The contour example's controller (ContourMpc<F, Tag, Soft, Scalar>): the OCP of task.hpp on its
// RBD workspace, with generated stage code where it was built and applies, the NMPC on it, and
// the run options' settings: the start phase's bounds (hold), the stage parameters (the tunnel's
// weight, the observer's estimate), the payload declared on the controller's model
// (known_payload), and the first OCP solved to convergence before the loop's tolerances are set
// (real-time iteration, or the paper's SQP mode). Storage: the workspace and the controller
// (hundreds of KB in double: static storage); nothing here allocates.
#pragma once

#include <Eigen/Core>
#include <type_traits>

#include "arbor/dynamics/payload.hpp"
#include "arbor/nmpc/controller.hpp"
#include "options.hpp"
#include "plant.hpp"
#include "stage_definition.hpp"
#include "task.hpp"

/// 1: the loops use generated stage code where it exists (ContourMpc::has_generated_stage).
#ifndef CONTOUR_GENERATED_STAGE
#define CONTOUR_GENERATED_STAGE 0
#endif
#if CONTOUR_GENERATED_STAGE
#include "contour_stages_ad.hpp"  // (arbor_add_stage_ad: ARBOR_CONTOUR_GENERATED_STAGE)
#endif

namespace contour {

/// QP primal tolerance of float controllers in real-time iteration. The float QP's default, 1e-4,
/// is a distance relative to 1 + max(1, |x|_inf, ...) over the QP's variables, torques of ~10 N m
/// among them: the tunnel row may end ~0.1-1.5 mm outside. Tighter tolerances cost QP iterations
/// and, in OCP-ID, make the float QP stall (1e-6: 24 of 320 samples): 3e-5 with a larger back-off
/// (default_backoff) holds rho in both formulations with 2 QP iterations per sample (README.md,
/// "Float").
constexpr double float_qp_tol_primal = 3e-5;

template <Formulation F, class Tag, bool Soft, class Scalar = double>
class ContourMpc {
 public:
  using W = Workspace<Tag, Scalar>;
  using ExprProblem = decltype(make_problem<F, Tag, Soft>(std::declval<W&>(), Reference{}));
  /// The problem definition of generated stage code (stage_definition.hpp) for this controller.
  using StageDef = StageDefinition<F, Soft, Scalar>;
  /// The Gauss-Newton stages come from generated code (built with CONTOUR_GENERATED_STAGE=1, the
  /// analytical provider and the definition's header included: CMake
  /// ARBOR_CONTOUR_GENERATED_STAGE) when the run's options are the definition's
  /// (generated_stage_applies), else from the expression layer.
  static constexpr bool has_generated_stage = CONTOUR_GENERATED_STAGE &&
                                              std::is_same_v<Tag, arbor::ad::Analytical> &&
                                              arbor::ocp::GeneratedStage<StageDef>::available;
  using Problem =
      std::conditional_t<has_generated_stage, arbor::ocp::WithGeneratedStage<ExprProblem, StageDef>,
                         ExprProblem>;
  using Controller = arbor::nmpc::Nmpc<Problem, Scalar>;
  static constexpr bool is_float = std::is_same_v<Scalar, float>;

  explicit ContourMpc(const Options& o)
      : options_(o),
        ref_(make_reference(o.c)),
        problem_(with_generated(
            with_margin(make_problem<F, Tag, Soft>(ws_, ref_, o.soft_weight, rho - backoff(o),
                                                   o.scaled_tunnel || o.sqp),
                        o.qd_margin),
            o)),
        ctrl_(problem_) {
    if (o.known_payload) {
      const bool ok =
          arbor::ad::set_payload(ws_, ee_frame, PayloadRobot::payload, arbor::Vec3<double>::Zero(),
                                 arbor::Mat3<double>::Zero());
      ARBOR_ASSERT(ok, "the end-effector frame takes a payload");
      (void)ok;
    }
  }
  ContourMpc(const ContourMpc&) = delete;
  ContourMpc& operator=(const ContourMpc&) = delete;

  /// Declares the plant's payload on a Data of the controller's model (known_payload: the
  /// observer's model, the plants' computed-torque models).
  static bool declare_payload(arbor::Data<Robot, double>& d) {
    return arbor::set_payload(d, ee_frame, PayloadRobot::payload, arbor::Vec3<double>::Zero(),
                              arbor::Mat3<double>::Zero());
  }

  /// The back-off the controller runs with: o.backoff, or the scalar's default if it is < 0.
  static double backoff(const Options& o) {
    return o.backoff < 0 ? default_backoff<Scalar> : o.backoff;
  }

  /// The generated stage code sees the definition's constants and the robot as generated: it
  /// applies when the run's reference, tunnel and slack weight are the definition's and no
  /// payload is declared on the controller's model.
  static bool generated_stage_applies(const Options& o) {
    return has_generated_stage && o.c == StageDef::c && rho - backoff(o) == StageDef::radius &&
           !(o.scaled_tunnel || o.sqp) && (!Soft || o.soft_weight == StageDef::soft_weight) &&
           !o.known_payload;
  }
  /// True when the controller's stages come from generated code.
  bool generated_stage() const {
    if constexpr (has_generated_stage)
      return problem_.generated;
    else
      return false;
  }

  /// Start phase (hold): s and sd bounded to 0 on every stage, sdd to 0; else the problem's.
  void set_hold(bool hold) {
    using Vx = typename Controller::Vx;
    using Vu = typename Controller::Vu;
    Vx lb = problem_.lbx.template cast<Scalar>(), ub = problem_.ubx.template cast<Scalar>();
    Vu lbu = problem_.lbu.template cast<Scalar>(), ubu = problem_.ubu.template cast<Scalar>();
    if (hold) {
      ub[14] = ub[15] = 0;
      lbu[7] = ubu[7] = 0;
    }
    for (int k = 0; k <= horizon; ++k) {
      ctrl_.set_state_bounds(k, lb, ub);
      if (k < horizon)
        ctrl_.set_input_bounds(k, lbu, ubu);
    }
    holding_ = hold;
  }
  /// The start phase's bounds are set.
  bool holding() const { return holding_; }

  /// Stage parameters: the tunnel's weight (0 on stage 0) and the disturbance estimate d (null:
  /// zero).
  void set_parameters(const VecN<double, nq>* d) {
    for (int k = 0; k <= horizon; ++k) {
      typename Controller::Vp p = Controller::Vp::Zero();
      p[0] = Scalar(k == 0 ? 0 : 1);  // the tunnel is not imposed on the measured x_0
      if (d)
        p.template tail<nq>() = d->template cast<Scalar>();
      ctrl_.set_parameter(k, p);
    }
  }

  /// The first OCP at x0, solved to convergence (at most 100 SQP iterations, the library's
  /// tolerances) from a gravity-compensating guess on the controller's model `model`; then the
  /// run's settings (real-time iteration or the SQP mode).
  arbor::nmpc::NmpcStatus start(const VecN<double, nx>& x0, arbor::Data<Robot, double>& model) {
    VecN<double, nu> u0 = VecN<double, nu>::Zero();
    if constexpr (F == Formulation::fd)  // gravity compensation at q0
      u0.head<nq>() = arbor::rnea<Robot>(model, VecN<double, nq>(x0.head<nq>()),
                                         VecN<double, nq>::Zero(), VecN<double, nq>::Zero());
    auto st = ctrl_.set_initial_guess(x0.cast<Scalar>(), u0.cast<Scalar>());
    if (st != arbor::nmpc::NmpcStatus::accepted)
      return st;
    auto& set = ctrl_.settings();
    set.shift_multipliers = options_.shift_multipliers;
    if (options_.qp_max_iter > 0)
      set.qp.max_iter = options_.qp_max_iter;
    set.feedback_qp_iterations = options_.feedback_qp_iter;
    set.presolve_feedback = options_.presolve;
    const auto keep = set;  // the first solve runs with the library's defaults
    set.max_iter = 100;
    st = ctrl_.solve(x0.cast<Scalar>());
    set = keep;
    if constexpr (!is_float) {
      if (!options_.sqp && options_.qp_tol > 0)
        set.qp.tol_primal = set.qp.tol_dual = set.qp.tol_comp = Scalar(options_.qp_tol);
    } else if (!options_.sqp) {  // float keeps its dual and complementarity defaults (1e-4)
      set.qp.tol_primal = Scalar(float_qp_tol_primal);
    }
    if (options_.sqp) {
      // CONTOUR.md: primal 1e-3, dual 1e-1, at most 3 line-search steps; QP 1e-3 / 1e-1
      set.max_iter = options_.sqp_iter;
      set.tol_primal = Scalar(1e-3);
      set.tol_stationarity = Scalar(1e-1);
      set.tol_complementarity = Scalar(1e-1);
      set.max_line_search = 3;
      // The QP judges a row's violation as a distance, |a_i' z - b_i| / |a_i| (issue 15: invariant
      // to scaling a row), not in the row's units as CONTOUR.md's QRQP did: its 1e-3 then lets
      // the scaled tunnel row (|a_i| ~ 1e2) end 10 % outside (max 10.36 mm, 16 line-search
      // failures, every sample at the SQP cap). 1e-6 as a distance keeps the rows within ~1e-3
      // in their units: 0 failures, 9.902 mm.
      set.qp.tol_primal = Scalar(1e-6);
      set.qp.tol_dual = Scalar(1e-1);
      // CONTOUR.md gives no complementarity tolerance: as loose as the dual one. At the QP's
      // default 1e-8 the working-set rule, which follows the loose tolerances, runs out of
      // changes before termination: 112 of 250 OCP-FD samples ended at the iteration cap.
      set.qp.tol_comp = Scalar(1e-1);
    }
    return st;
  }

  Controller& controller() { return ctrl_; }
  const Controller& controller() const { return ctrl_; }
  const Reference& reference() const { return ref_; }
  W& workspace() { return ws_; }

 private:
  /// The problem, with generated stages where they exist and apply (generated_stage_applies).
  static Problem with_generated(const ExprProblem& p, const Options& o) {
    if constexpr (has_generated_stage)
      return Problem(p, generated_stage_applies(o));
    else
      return p;
  }

  /// The problem with the velocity bounds (1 - margin) qd_max.
  static ExprProblem with_margin(ExprProblem p, double margin) {
    for (int i = 0; i < nq; ++i) {
      p.lbx[nq + i] = -(1 - margin) * qd_max;
      p.ubx[nq + i] = (1 - margin) * qd_max;
    }
    return p;
  }

  Options options_;
  Reference ref_;
  W ws_{};  // declared before problem_: the problem's handles point here
  Problem problem_;
  Controller ctrl_;
  bool holding_ = false;
};

}  // namespace contour
