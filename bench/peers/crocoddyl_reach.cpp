// arbor against Crocoddyl (DDP on Pinocchio) on one OCP, in one run: the Kinova Gen3 reaching task
// of issue 57 item 2b (reach_task.hpp: x = [q, v], u = tau, RK4 at h = 0.02 s, N = 16 and 30,
// node costs on the end-effector position, v and tau, torque bounds only).
//
// Crocoddyl's IntegratedActionModelRK integrates a differential model's cost along the four RK
// stages (dt/6 (l0 + 2 l1 + 2 l2 + l3)); arbor, like acados' discrete OCPs, charges the stage
// cost at the node. To solve the same OCP, Crocoddyl's nodes are a small action model (NodeModel
// below) that takes the dynamics from IntegratedActionModelRK (RK4, over a
// DifferentialActionModelFreeFwdDynamics without costs) and the cost from a CostModelSum at
// (x_k, u_k): one forward kinematics and one joint-Jacobian pass per node, fewer than its
// RK4-integrated cost would take (four cost evaluations and their chain rule).
//
// What it prints (per N): the model check (arbor's and Pinocchio's FK and FD at random states), the
// full solves from the same guess (x0 and the gravity torque on every node; dynamically feasible)
// with each framework's cost by one independent evaluator and the largest trajectory difference,
// the time per solve and per iteration (median over repetitions, the frameworks alternated), and
// the closed loop: arbor's real-time iteration (prepare + feedback; exact and frozen RK4
// sensitivities, and frozen with the feedback's QP capped at 2 iterations) against Crocoddyl's one
// warm-started (Box)FDDP iteration from the shifted plan (Kleff et al., ICRA 2021), per sample
// median / p99 / max, on the same plant (Pinocchio's ABA, semi-implicit Euler at 1 ms) and the
// same target sequence. A run takes about a minute (`--quick`: a smoke run; `--N 16|30`: one
// horizon; `--cpu`: this thread's CPU time instead of wall time).
#include <cstdlib>
#include <cstring>
#include <memory>

#include <pinocchio/algorithm/jacobian.hpp>

#include <crocoddyl/core/activations/weighted-quadratic.hpp>
#include <crocoddyl/core/costs/cost-sum.hpp>
#include <crocoddyl/core/costs/residual.hpp>
#include <crocoddyl/core/integrator/rk.hpp>
#include <crocoddyl/core/optctrl/shooting.hpp>
#include <crocoddyl/core/residuals/control.hpp>
#include <crocoddyl/core/solvers/box-fddp.hpp>
#include <crocoddyl/core/solvers/fddp.hpp>
#include <crocoddyl/multibody/actions/free-fwddyn.hpp>
#include <crocoddyl/multibody/actuations/full.hpp>
#include <crocoddyl/multibody/data/multibody.hpp>
#include <crocoddyl/multibody/residuals/frame-translation.hpp>
#include <crocoddyl/multibody/residuals/state.hpp>
#include <crocoddyl/multibody/states/multibody.hpp>

#include "reach_task.hpp"

namespace {
using namespace reach;

// ---- Crocoddyl: RK4 dynamics from IntegratedActionModelRK, the node cost from a CostModelSum ----
template <typename Scalar>
struct NodeDataTpl;

template <typename Scalar>
class NodeModelTpl : public crocoddyl::ActionModelAbstractTpl<Scalar> {
 public:
  using Base = crocoddyl::ActionModelAbstractTpl<Scalar>;
  using Data = crocoddyl::ActionDataAbstractTpl<Scalar>;
  using VectorXs = typename Base::VectorXs;
  /// rk: the dynamics (nullptr for the terminal node); costs: this node's cost at (x, u) or x.
  NodeModelTpl(std::shared_ptr<crocoddyl::StateMultibodyTpl<Scalar>> state,
               std::shared_ptr<crocoddyl::ActionModelAbstractTpl<Scalar>> rk,
               std::shared_ptr<crocoddyl::CostModelSumTpl<Scalar>> costs)
      : Base(state, costs->get_nu(), costs->get_nr()), ms_(state), rk_(rk), costs_(costs) {}
  void calc(const std::shared_ptr<Data>& data, const Eigen::Ref<const VectorXs>& x,
            const Eigen::Ref<const VectorXs>& u) override {
    auto* d = static_cast<NodeDataTpl<Scalar>*>(data.get());
    rk_->calc(d->rk, x, u);
    d->xnext = d->rk->xnext;
    pinocchio::forwardKinematics(*ms_->get_pinocchio(), d->pin, x.head(n));
    costs_->calc(d->costs, x, u);
    d->cost = d->costs->cost;
  }
  void calc(const std::shared_ptr<Data>& data, const Eigen::Ref<const VectorXs>& x) override {
    auto* d = static_cast<NodeDataTpl<Scalar>*>(data.get());
    d->xnext = x;
    pinocchio::forwardKinematics(*ms_->get_pinocchio(), d->pin, x.head(n));
    costs_->calc(d->costs, x);
    d->cost = d->costs->cost;
  }
  void calcDiff(const std::shared_ptr<Data>& data, const Eigen::Ref<const VectorXs>& x,
                const Eigen::Ref<const VectorXs>& u) override {
    auto* d = static_cast<NodeDataTpl<Scalar>*>(data.get());
    rk_->calcDiff(d->rk, x, u);
    d->Fx = d->rk->Fx;
    d->Fu = d->rk->Fu;
    pinocchio::computeJointJacobians(*ms_->get_pinocchio(), d->pin, x.head(n));
    costs_->calcDiff(d->costs, x, u);
    d->Lx = d->costs->Lx, d->Lu = d->costs->Lu;
    d->Lxx = d->costs->Lxx, d->Lxu = d->costs->Lxu, d->Luu = d->costs->Luu;
  }
  void calcDiff(const std::shared_ptr<Data>& data, const Eigen::Ref<const VectorXs>& x) override {
    auto* d = static_cast<NodeDataTpl<Scalar>*>(data.get());
    pinocchio::computeJointJacobians(*ms_->get_pinocchio(), d->pin, x.head(n));
    costs_->calcDiff(d->costs, x);
    d->Lx = d->costs->Lx, d->Lxx = d->costs->Lxx;
  }
  std::shared_ptr<Data> createData() override {
    return std::allocate_shared<NodeDataTpl<Scalar>>(
        Eigen::aligned_allocator<NodeDataTpl<Scalar>>(), this);
  }
  const pinocchio::ModelTpl<Scalar>& pin_model() const { return *ms_->get_pinocchio(); }
  const std::shared_ptr<crocoddyl::ActionModelAbstractTpl<Scalar>>& rk() const { return rk_; }
  const std::shared_ptr<crocoddyl::CostModelSumTpl<Scalar>>& costs() const { return costs_; }

 private:
  std::shared_ptr<crocoddyl::StateMultibodyTpl<Scalar>> ms_;
  std::shared_ptr<crocoddyl::ActionModelAbstractTpl<Scalar>> rk_;
  std::shared_ptr<crocoddyl::CostModelSumTpl<Scalar>> costs_;
};

template <typename Scalar>
struct NodeDataTpl : crocoddyl::ActionDataAbstractTpl<Scalar> {
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
  explicit NodeDataTpl(NodeModelTpl<Scalar>* m)
      : crocoddyl::ActionDataAbstractTpl<Scalar>(m), pin(m->pin_model()), collector(&pin) {
    if (m->rk())
      rk = m->rk()->createData();
    costs = m->costs()->createData(&collector);
  }
  pinocchio::DataTpl<Scalar> pin;
  crocoddyl::DataCollectorMultibodyTpl<Scalar> collector;
  std::shared_ptr<crocoddyl::ActionDataAbstractTpl<Scalar>> rk;
  std::shared_ptr<crocoddyl::CostDataSumTpl<Scalar>> costs;
};
using NodeModel = NodeModelTpl<double>;

struct CrocReach {
  std::shared_ptr<crocoddyl::StateMultibody> state;
  std::shared_ptr<crocoddyl::ResidualModelFrameTranslation> tip_run, tip_term;
  std::shared_ptr<crocoddyl::ShootingProblem> problem;
  void set_target(const Eigen::Vector3d& p) {
    tip_run->set_reference(p);
    tip_term->set_reference(p);
  }
};

CrocReach make_crocoddyl(const Task& t, int N) {
  using namespace crocoddyl;
  CrocReach c;
  c.state = std::make_shared<StateMultibody>(std::make_shared<pinocchio::Model>(t.model));
  auto actuation = std::make_shared<ActuationModelFull>(c.state);
  auto no_costs = std::make_shared<CostModelSum>(c.state, n);
  auto dyn = std::make_shared<DifferentialActionModelFreeFwdDynamics>(c.state, actuation, no_costs);
  auto rk4 = std::make_shared<IntegratedActionModelRK>(dyn, RKType::four, h, false);
  VecX v_only = VecX::Zero(nx);
  v_only.tail(n).setOnes();
  const VecX xref = VecX::Zero(nx);
  auto v_act = std::make_shared<ActivationModelWeightedQuad>(v_only);
  c.tip_run = std::make_shared<ResidualModelFrameTranslation>(c.state, t.frame, t.targets[0], n);
  c.tip_term = std::make_shared<ResidualModelFrameTranslation>(c.state, t.frame, t.targets[0], n);
  auto run = std::make_shared<CostModelSum>(c.state, n);
  run->addCost("tip", std::make_shared<CostModelResidual>(c.state, c.tip_run), 2 * w_p);
  run->addCost("v",
               std::make_shared<CostModelResidual>(
                   c.state, v_act, std::make_shared<ResidualModelState>(c.state, xref, n)),
               2 * w_v);
  run->addCost("tau",
               std::make_shared<CostModelResidual>(
                   c.state, std::make_shared<ResidualModelControl>(c.state, n)),
               2 * w_u);
  auto term = std::make_shared<CostModelSum>(c.state, n);
  term->addCost("tip", std::make_shared<CostModelResidual>(c.state, c.tip_term), 2 * w_pT);
  term->addCost("v",
                std::make_shared<CostModelResidual>(
                    c.state, v_act, std::make_shared<ResidualModelState>(c.state, xref, n)),
                2 * w_vT);
  auto running = std::make_shared<NodeModel>(c.state, rk4, run);
  VecX lb(n), ub(n);
  for (int j = 0; j < n; ++j)
    lb[j] = -tau_max[j], ub[j] = tau_max[j];
  running->set_u_lb(lb);
  running->set_u_ub(ub);
  auto terminal = std::make_shared<NodeModel>(c.state, nullptr, term);
  VecX x0 = VecX::Zero(nx);
  x0.head(n) = t.q0;
  c.problem = std::make_shared<ShootingProblem>(
      x0, std::vector<std::shared_ptr<ActionModelAbstract>>(std::size_t(N), running), terminal);
  return c;
}

template <int N>
void run(const Task& t, const Options& o) {
  using A = ArborReach<N, ocp::Sensitivity::exact>;
  using AF = ArborReach<N, ocp::Sensitivity::frozen>;
  std::printf("\n==== N = %d (h = %.2f s, RK4; x = [q, v], u = tau, torque bounds) ====\n", N, h);
  pinocchio::Data pd(t.model);
  Vx x0 = Vx::Zero();
  x0.head<n>() = t.q0;
  const Vu g0 = pinocchio::computeGeneralizedGravity(t.model, pd, t.q0);
  const Eigen::Vector3d& target = t.targets[0];

  // -- arbor: full SQP solve (Gauss-Newton, line search) from the guess
  auto& ac = A::controller();
  A::set_target(ac, target);
  auto arbor_solve = [&] {
    (void)ac.set_initial_guess(x0, g0);
    return ac.solve(x0);
  };
  nmpc::NmpcStatus st = arbor_solve();
  const int arbor_iter = ac.info().iterations;
  std::vector<Vx> axs(N + 1);
  std::vector<Vu> aus(N);
  for (int k = 0; k <= N; ++k)
    axs[k] = ac.state(k);
  for (int k = 0; k < N; ++k)
    aus[k] = ac.input(k);

  // -- Crocoddyl: BoxFDDP and FDDP from the same guess (feasible: x0 held by its gravity torque)
  CrocReach cr = make_crocoddyl(t, N);
  cr.set_target(target);
  const std::vector<VecX> xs_guess(N + 1, VecX(x0)), us_guess(N, VecX(g0));
  crocoddyl::SolverBoxFDDP box(cr.problem);
  crocoddyl::SolverFDDP fddp(cr.problem);
  box.set_th_stop(1e-12);
  fddp.set_th_stop(1e-12);
  const bool box_ok = box.solve(xs_guess, us_guess, 200, true);
  const int box_iter = int(box.get_iter());
  const bool fddp_ok = fddp.solve(xs_guess, us_guess, 200, true);
  const int fddp_iter = int(fddp.get_iter());
  auto to_vec = [](const std::vector<VecX>& v, auto& out) {
    for (std::size_t k = 0; k < out.size(); ++k)
      out[k] = v[k];
  };
  std::vector<Vx> bxs(N + 1), fxs(N + 1);
  std::vector<Vu> bus(N), fus(N);
  to_vec(box.get_xs(), bxs), to_vec(box.get_us(), bus);
  to_vec(fddp.get_xs(), fxs), to_vec(fddp.get_us(), fus);
  auto maxdiff = [](const auto& a, const auto& b) {
    double m = 0;
    for (std::size_t k = 0; k < a.size(); ++k)
      m = std::max(m, (a[k] - b[k]).cwiseAbs().maxCoeff());
    return m;
  };
  int active = 0;
  for (int k = 0; k < N; ++k)
    for (int j = 0; j < n; ++j)
      active += std::abs(aus[k][j]) > tau_max[j] - 1e-6;
  const double Ja = objective(t, pd, axs, aus, target), Jb = objective(t, pd, bxs, bus, target),
               Jf = objective(t, pd, fxs, fus, target);
  std::printf(
      "full solves from the same guess (cost by one evaluator; torque bounds active at "
      "the arbor optimum: %d of %d)\n",
      active, N * n);
  std::printf("  arbor SQP       %-16s %3d iterations  cost %.12g\n", nmpc::to_string(st),
              arbor_iter, Ja);
  std::printf(
      "  Crocoddyl BoxFDDP %-14s %3d iterations  cost %.12g (its own %.12g)  "
      "max |x diff| %.2e  max |u diff| %.2e\n",
      box_ok ? "converged" : "not converged", box_iter, Jb, box.get_cost(), maxdiff(axs, bxs),
      maxdiff(aus, bus));
  std::printf(
      "  Crocoddyl FDDP  %-16s %3d iterations  cost %.12g  max |x diff| %.2e  max |u "
      "diff| %.2e (no bounds)\n",
      fddp_ok ? "converged" : "not converged", fddp_iter, Jf, maxdiff(axs, fxs), maxdiff(aus, fus));

  // -- time per solve (each from the same guess, to its own default-free tolerance above) and per
  //    iteration; the two alternate so that a busy core hits both
  std::vector<double> ta, tb, tf;
  for (int r = 0; r < o.reps; ++r) {
    auto t0 = Clock::now();
    (void)arbor_solve();
    ta.push_back(us_since(t0));
    t0 = Clock::now();
    box.solve(xs_guess, us_guess, 200, true);
    tb.push_back(us_since(t0));
    t0 = Clock::now();
    fddp.solve(xs_guess, us_guess, 200, true);
    tf.push_back(us_since(t0));
  }
  const Stats sa = stats(ta), sb = stats(tb), sf = stats(tf);
  std::printf("time per full solve, median / p99 / max [us] (%d solves each):\n", o.reps);
  std::printf("  arbor SQP          %9.0f %9.0f %9.0f   per iteration %7.1f\n", sa.median, sa.p99,
              sa.max, sa.median / arbor_iter);
  std::printf("  Crocoddyl BoxFDDP  %9.0f %9.0f %9.0f   per iteration %7.1f\n", sb.median, sb.p99,
              sb.max, sb.median / box_iter);
  std::printf("  Crocoddyl FDDP     %9.0f %9.0f %9.0f   per iteration %7.1f\n", sf.median, sf.p99,
              sf.max, sf.median / fddp_iter);
  std::printf(
      "  ratio per solve: BoxFDDP / arbor %.2f, FDDP / arbor %.2f; per iteration: %.2f, "
      "%.2f\n",
      sb.median / sa.median, sf.median / sa.median,
      (sb.median / box_iter) / (sa.median / arbor_iter),
      (sf.median / fddp_iter) / (sa.median / arbor_iter));

  // -- closed loop: the target moves every 50 samples; each framework its own loop on the plant
  auto& afc = AF::controller();
  std::vector<double> t_arbor, t_arbor_frozen, t_bounded, t_box, t_fddp, t_prep, t_fb;
  double err_arbor = 0, err_frozen = 0, err_bounded = 0, err_box = 0, err_fddp = 0;  // per target
  int arbor_fail = 0;
  // bounded: the feedback's QP capped at 2 iterations (the contour demo's default); its
  // preparation and feedback times are kept apart
  auto arbor_loop = [&](auto& c, auto set_target, std::vector<double>& times, double& err,
                        bool bounded = false) {
    c.settings().feedback_qp_iterations = bounded ? 2 : 0;
    arbor_fail += arbor_closed_loop(t, o, pd, c, set_target, x0, g0, times, err,
                                    bounded ? &t_prep : nullptr, bounded ? &t_fb : nullptr);
    c.settings().feedback_qp_iterations = 0;
  };
  auto croc_loop = [&](crocoddyl::SolverFDDP& solver, std::vector<double>& times, double& err) {
    Vx x = x0;
    cr.problem->set_x0(x0);
    cr.set_target(t.targets[0]);
    solver.solve(xs_guess, us_guess, 200, true);
    std::vector<VecX> xs(N + 1), us(N);
    for (int s = 0; s < o.samples; ++s) {
      const Eigen::Vector3d& p = t.targets[std::size_t(s / 50) % t.targets.size()];
      cr.set_target(p);
      // the shifted plan (Kleff et al.): drop the first node, repeat the last
      const auto& sx = solver.get_xs();
      const auto& su = solver.get_us();
      for (int k = 0; k < N; ++k)
        xs[k] = sx[k + 1];
      xs[N] = sx[N];
      for (int k = 0; k + 1 < N; ++k)
        us[k] = su[k + 1];
      us[N - 1] = su[N - 1];
      xs[0] = x;
      const auto t0 = Clock::now();
      cr.problem->set_x0(x);
      solver.solve(xs, us, 1, false);
      times.push_back(us_since(t0));
      x = plant_step(t, pd, x, Vu(solver.get_us()[0]));
      if (s % 50 == 49)
        err = std::max(err, tip_error(t, pd, x, p));
    }
  };
  auto& ac_set = A::set_target;
  auto& af_set = AF::set_target;
  for (int r = 0; r < o.rounds; ++r) {
    arbor_loop(ac, ac_set, t_arbor, err_arbor);
    croc_loop(box, t_box, err_box);
    arbor_loop(afc, af_set, t_arbor_frozen, err_frozen);
    croc_loop(fddp, t_fddp, err_fddp);
    arbor_loop(afc, af_set, t_bounded, err_bounded, true);
  }
  const Stats ra = stats(t_arbor), rf = stats(t_arbor_frozen), rb = stats(t_box),
              rd = stats(t_fddp), rg = stats(t_bounded), rp = stats(t_prep), rq = stats(t_fb);
  print_loop_heading(o);
  print_loop_row("arbor RTI (prepare + feedback), exact RK4 sens.", ra, err_arbor);
  print_loop_row("arbor RTI (prepare + feedback), frozen RK4 sens.", rf, err_frozen);
  print_loop_row("arbor RTI, frozen sens., feedback QP <= 2 iter.", rg, err_bounded);
  std::printf("    of which prepare %8.1f %8.1f %8.1f, feedback %8.1f %8.1f %8.1f\n", rp.median,
              rp.p99, rp.max, rq.median, rq.p99, rq.max);
  print_loop_row("Crocoddyl BoxFDDP, 1 warm iteration", rb, err_box);
  print_loop_row("Crocoddyl FDDP, 1 warm iteration", rd, err_fddp);
  std::printf(
      "  ratio BoxFDDP iteration / arbor RTI sample (exact): median %.1f, max %.1f; "
      "(frozen): median %.1f, max %.1f\n",
      rb.median / ra.median, rb.max / ra.max, rb.median / rf.median, rb.max / rf.max);
  std::printf(
      "  ratio FDDP iteration / arbor RTI sample (exact): median %.1f, max %.1f; "
      "(frozen): median %.1f, max %.1f\n",
      rd.median / ra.median, rd.max / ra.max, rd.median / rf.median, rd.max / rf.max);
  std::printf(
      "  ratio BoxFDDP / FDDP iteration / arbor RTI sample (frozen, bounded): median %.1f / %.1f, "
      "max %.1f / %.1f\n",
      rb.median / rg.median, rd.median / rg.median, rb.max / rg.max, rd.max / rg.max);
  std::printf("  arbor samples not succeeded: %d\n", arbor_fail);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_options(argc, argv);
  const Task t = start_task(PEERS_KINOVA_URDF);
  if (o.runs(16))
    run<16>(t, o);
  if (o.runs(30))
    run<30>(t, o);
  return 0;
}
