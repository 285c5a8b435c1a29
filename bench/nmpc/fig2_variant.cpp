// One variant of the paper's Fig. 2 (bench/nmpc/fig2.sh): the contour NMPC of examples/contour
// (formulation FIG2_ID, RBD derivative provider FIG2_AUTODIFF: 0 analytical, 1 dual-number AD,
// 2 code-generated AD (gen/ad; the pose node by dual numbers, ad::ProviderOf); hard tunnel,
// double) in closed loop
// against the example's plant, each controller call timed by phase. Compiled once per variant
// (the controller instantiation takes ~2 GB of compiler memory).
//
// The set-up is the example's own (ContourLoop::start(): first OCP solved to convergence from a
// gravity-compensating guess, then the mode's settings). Per sample the plant runs u_0 for h,
// then, timed:
//   RTI   shift(); prepare() [lin]; feedback(x) [qp]                   (ContourLoop::sample())
//   SQP   shift(); then solve(x)'s own sequence with the public phases: solve(x) with max_iter = 0
//         [lin: linearisation, embedding, KKT residuals, convergence test; it also sets x_0 = x
//         and restarts the merit history on a new x, as solve() does], solve_qp() [qp],
//         line_search(x) [rest], at most sqp_iter times, and the final convergence check
// which is exactly the sequence of calls solve(x) makes with max_iter = sqp_iter (check mode
// compares the controls with ContourLoop::sample() in lockstep).
// The RBD Jacobians inside a linearisation cannot be timed in place (they run inside the
// expression layer), so after each linearisation, outside the timed calls, the same RBD Jacobian
// calls (per path stage: FD x 4 (one RK4 step) or ID x 1, FramePose, the tunnel's position
// (ad::FramePosition on the workspace's PoseCache: analytical, it takes the pose's position rows
// cached at the same q);
// terminal: FramePose) are run on a workspace of the same type at the plan's points and timed.
#include <chrono>
#include <cmath>
#include <memory>
#include <type_traits>

#if FIG2_AUTODIFF == 2
#include <robots/kinova_gen3_ad.hpp>  // before closed_loop.hpp (task.hpp): GeneratedCode
#endif
#include "closed_loop.hpp"
#include "fig2.hpp"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define FIG2_CG_START CALLGRIND_START_INSTRUMENTATION
#define FIG2_CG_STOP CALLGRIND_STOP_INSTRUMENTATION
#define FIG2_CG_TOGGLE CALLGRIND_TOGGLE_COLLECT
#else
#define FIG2_CG_START
#define FIG2_CG_STOP
#define FIG2_CG_TOGGLE
#endif

#ifndef FIG2_ID
#error "FIG2_ID (0: OCP-FD, 1: OCP-ID) must be defined"
#endif
#ifndef FIG2_AUTODIFF
#error "FIG2_AUTODIFF (0: analytical, 1: dual-number AD, 2: generated AD) must be defined"
#endif

namespace {

using namespace contour;
using arbor::nmpc::NmpcStatus;
using Clock = std::chrono::steady_clock;
constexpr Formulation kForm = FIG2_ID ? Formulation::id : Formulation::fd;
using Tag = std::conditional_t<
    FIG2_AUTODIFF == 2, arbor::ad::Generated,
    std::conditional_t<FIG2_AUTODIFF == 1, arbor::ad::AutoDiff, arbor::ad::Analytical>>;
using Loop = ContourLoop<kForm, Tag, false, double>;
using Ctrl = Loop::Controller;

double us(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::micro>(b - a).count();
}

/// The RBD Jacobians of one linearisation, at the plan's points, on workspace ws; returns the
/// number of calls (sink: keeps the results alive).
int rbd_jacobians(Workspace<Tag, double>& ws, const Ctrl& c, double& sink) {
  const auto fd = ad::bind<Fd>(ws);
  const auto id = ad::bind<Id>(ws);
  const auto pose = ad::bind<Pose>(ws);
  const auto pos = ad::bind<Position>(ws);
  VecN<double, Fd::nout> y7;
  Eigen::Matrix<double, Fd::nout, Fd::nin> J7;
  VecN<double, Pose::nout> y12;
  Eigen::Matrix<double, Pose::nout, Pose::nin> J12;
  VecN<double, 3> y3;
  Eigen::Matrix<double, 3, Position::nin> J3;
  int calls = 0;
  for (int k = 0; k <= horizon; ++k) {
    const VecN<double, nx>& x = c.state(k);
    const VecN<double, nq> q = x.head<nq>();
    pose.value_and_jacobian<Tag>(q, y12, J12);  // (Generated: AutoDiff for the pose)
    sink += J12(0, 0);
    ++calls;
    if (k == horizon)
      break;
    VecN<double, 3 * nq> z;
    z << q, x.segment<nq>(nq), c.input(k).head<nq>();
    if constexpr (kForm == Formulation::fd) {
      for (int i = 0; i < 4; ++i) {  // the four stages of one RK4 step
        fd.value_and_jacobian<Tag>(z, y7, J7);
        sink += J7(0, i);
        ++calls;
      }
    } else {
      id.value_and_jacobian<Tag>(z, y7, J7);
      sink += J7(0, 0);
      ++calls;
    }
    pos.value_and_jacobian<Tag>(q, y3, J3);
    sink += J3(0, 0);
    ++calls;
  }
  return calls;
}

void run(const fig2::RunOptions& opt, fig2::Run& out) {
  Options lo;
  lo.sqp = opt.sqp;
  lo.sqp_iter = opt.sqp_iter;
  lo.max_samples = opt.samples;
  const auto loop = std::make_unique<Loop>(lo);  // the controller is large: heap, not stack
  const auto check = opt.check ? std::make_unique<Loop>(lo) : nullptr;
  const auto ws = std::make_unique<Workspace<Tag, double>>();
  const auto plant = std::make_unique<Loop::PlantModel>();
  Ctrl& ctrl = loop->controller();
  out.controller_bytes = sizeof(Ctrl);
  out.start_status = int(loop->start());
  out.start_iterations = loop->start_iterations();
  if (check)
    (void)check->start();
  for (Ctrl* c : {&ctrl, check ? &check->controller() : nullptr}) {
    if (!c)
      continue;
    auto& q = c->settings().qp;
    q.tol_primal = opt.qp_tol_primal > 0 ? opt.qp_tol_primal : q.tol_primal;
    q.tol_dual = opt.qp_tol_dual > 0 ? opt.qp_tol_dual : q.tol_dual;
    q.tol_comp = opt.qp_tol_comp > 0 ? opt.qp_tol_comp : q.tol_comp;
    q.reg_dual = opt.qp_reg_dual > 0 ? opt.qp_reg_dual : q.reg_dual;
    q.max_iter = opt.qp_max_iter > 0 ? opt.qp_max_iter : q.max_iter;
  }
  plant->x.setZero();
  plant->x.head<nq>() = initial_q();
  const int K = ctrl.settings().max_iter;  // sqp_iter in SQP mode (set by start())
  const bool cg = opt.cg_count > 0;
  double sink = 0;
  out.samples.clear();
  out.samples.reserve(std::size_t(opt.samples));

  for (int n = 0; n < opt.samples; ++n) {
    const bool collect = cg && n >= opt.cg_from && n < opt.cg_from + opt.cg_count;
    if (cg && n == opt.cg_from)
      FIG2_CG_START;
    fig2::Sample s;
    plant->step(kForm, ctrl.control());
    const VecN<double, nx> x0 = plant->x;
    double rbd = 0;
    auto time_rbd = [&] {  // outside the timed controller calls
      if (cg)
        return;
      const auto a = Clock::now();
      out.rbd_calls_per_linearization = rbd_jacobians(*ws, ctrl, sink);
      rbd += us(a, Clock::now());
    };
    NmpcStatus st = NmpcStatus::step_taken;
    if (collect)
      FIG2_CG_TOGGLE;
    const auto t0 = Clock::now();
    ctrl.shift();
    const auto t1 = Clock::now();
    s.rest_us += us(t0, t1);
    if (!opt.sqp) {
      st = ctrl.prepare();
      const auto t2 = Clock::now();
      time_rbd();  // (nothing under callgrind)
      const auto t3 = Clock::now();
      if (st == NmpcStatus::prepared)
        st = ctrl.feedback(x0);
      const auto t4 = Clock::now();
      s.lin_us = us(t1, t2);
      s.qp_us = us(t3, t4);
      s.linearizations = 1;
      s.sqp_iterations = ctrl.info().iterations;
      s.qp_iterations = ctrl.info().qp_iterations;
      s.qp_status = int(ctrl.info().qp_status);
    } else {
      const int keep = ctrl.settings().max_iter;
      ctrl.settings().max_iter = 0;  // solve(x0): one linearisation and the convergence test
      for (int it = 0;; ++it) {
        auto a = Clock::now();
        st = ctrl.solve(x0);
        auto b = Clock::now();
        s.lin_us += us(a, b);
        ++s.linearizations;
        time_rbd();
        if (st != NmpcStatus::iteration_limit)
          break;  // converged, or a failure of the linearisation
        if (it == K)
          break;  // iteration_limit, as solve()
        a = Clock::now();
        st = ctrl.solve_qp();
        b = Clock::now();
        s.qp_us += us(a, b);
        ++s.sqp_iterations;
        s.qp_iterations += ctrl.info().qp_iterations;
        s.qp_status = int(ctrl.info().qp_status);  // (the next solve(x0) resets info())
        if (st != NmpcStatus::step_taken)
          break;  // qp_failed
        a = Clock::now();
        st = ctrl.line_search(x0);
        b = Clock::now();
        s.rest_us += us(a, b);
        if (st != NmpcStatus::step_taken)
          break;  // line_search_failed
      }
      ctrl.settings().max_iter = keep;
    }
    if (collect) {
      FIG2_CG_TOGGLE;
      ++out.cg_controller_calls;
    }
    if (cg && n == opt.cg_from + opt.cg_count - 1)
      FIG2_CG_STOP;
    s.rbd_us = rbd;
    s.total_us = s.lin_us + s.qp_us + s.rest_us;
    s.status = int(st);
    s.failed = !(st == NmpcStatus::step_taken || st == NmpcStatus::prepared ||
                 st == NmpcStatus::converged || st == NmpcStatus::iteration_limit);
    s.e_p = (plant->ee_position() - p_ref(loop->reference(), x0[14])).norm();
    s.s = x0[14];
    if (check) {
      Record rec;
      check->sample(rec);
      s.check_du = (rec.u - ctrl.control()).cwiseAbs().maxCoeff();
    }
    out.samples.push_back(s);
    if (!x0.allFinite())
      break;
  }
  if (sink == 12345.678)  // keeps the isolated RBD calls from being optimised away
    out.name = "";
}

}  // namespace

namespace fig2 {
#if FIG2_ID && FIG2_AUTODIFF == 2
void run_id_generated(const RunOptions& o, Run& r) {
  r.name = "OCP-ID generated AD";
  run(o, r);
}
#elif FIG2_AUTODIFF == 2
void run_fd_generated(const RunOptions& o, Run& r) {
  r.name = "OCP-FD generated AD";
  run(o, r);
}
#elif FIG2_ID && FIG2_AUTODIFF
void run_id_autodiff(const RunOptions& o, Run& r) {
  r.name = "OCP-ID AD";
  run(o, r);
}
#elif FIG2_ID
void run_id_analytical(const RunOptions& o, Run& r) {
  r.name = "OCP-ID analytical";
  run(o, r);
}
#elif FIG2_AUTODIFF
void run_fd_autodiff(const RunOptions& o, Run& r) {
  r.name = "OCP-FD AD";
  run(o, r);
}
#else
void run_fd_analytical(const RunOptions& o, Run& r) {
  r.name = "OCP-FD analytical";
  run(o, r);
}
#endif
}  // namespace fig2
