// arbor against acados (SQP / RTI with HPIPM) on one OCP, in one run: the Kinova Gen3 reaching task
// of issue 57 item 2b (reach_task.hpp: x = [q, v], u = tau, RK4 at h = 0.02 s, N = 16 and 30,
// node costs on the end-effector position, v and tau, torque bounds only).
//
// acados gets the OCP through its C interface (acados_c/ocp_nlp_interface.h), as a discrete model
// (DISCRETE_MODEL) with nonlinear-least-squares costs (NONLINEAR_LS, Gauss-Newton Hessian) and
// box constraints (BGH), its functions as acados external functions written here in C++ on
// Pinocchio (no CasADi): the dynamics one RK4 step of [v, ABA(q, v, tau)] with its exact Jacobian
// (pinocchio::computeABADerivatives at the four stage states, chained), the residuals
// y = [p_ee(q), v, tau] (terminal [p_ee(q), v]) with the frame Jacobian, y_ref = [p*, 0, 0],
// W = 2 diag(w) (acados' cost is 1/2 |y - y_ref|_W^2). The QP: PARTIAL_CONDENSING_HPIPM (acados'
// default), no condensing (qp_cond_N = N).
//
// What it prints (per N): the full SQP solves from the same guess (x0 and the gravity torque on
// every node) with each framework's cost by one independent evaluator and the largest trajectory
// difference, time per solve and per iteration, and the closed loop: arbor's real-time iteration
// against acados' SQP_RTI (preparation phase + feedback phase), per sample median / p99 / max, on
// the same plant and target sequence. A run takes about a minute (`--quick`: a smoke run;
// `--N 16|30`: one horizon; `--cpu`: this thread's CPU time instead of wall time).
#include <cstdlib>
#include <cstring>

#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/jacobian.hpp>

extern "C" {
#include "acados/utils/external_function_generic.h"
#include "acados_c/ocp_nlp_interface.h"
#include "blasfeo_d_aux.h"
}

#include "reach_task.hpp"

namespace {
using namespace reach;
constexpr int nw = nx + n;  // [u; x], acados' order of a stage's variables

// ---- the external functions -------------------------------------------------------------------
/// An acados external function: the three public members of external_function_generic first
/// (acados calls evaluate(self, ...) with self the pointer it was given), then our context.
struct ExtFun {
  void (*evaluate)(void*, ext_fun_arg_t*, void**, ext_fun_arg_t*, void**);
  std::size_t (*get_external_workspace_requirement)(void*);
  void (*set_external_workspace)(void*, void*);
  const pinocchio::Model* model;
  pinocchio::Data* data;
  pinocchio::FrameIndex frame;
  bool terminal;  ///< residuals: the terminal stage's (no u)
  bool jacobian;  ///< dynamics: value and Jacobian
};
std::size_t no_workspace(void*) {
  return 0;
}
void set_no_workspace(void*, void*) {}

Eigen::VectorXd read(void* arg, int size) {
  const auto* a = static_cast<blasfeo_dvec_args*>(arg);
  Eigen::VectorXd v(size);
  if (size > 0)
    blasfeo_unpack_dvec(size, a->x, a->xi, v.data(), 1);
  return v;
}

/// RK4 over h of f(x, u) = [v, ABA(q, v, u)] and, when wanted, d x+ / d[u; x] (exact).
struct Rk4 {
  const pinocchio::Model& model;
  pinocchio::Data& data;
  Vx f(const Vx& x, const Vu& u) {
    Vx r;
    r.head<n>() = x.tail<n>();
    r.tail<n>() = pinocchio::aba(model, data, Vq(x.head<n>()), Vq(x.tail<n>()), u);
    return r;
  }
  /// f and df/d[u; x] at (x, u)
  Vx f_jac(const Vx& x, const Vu& u, Eigen::Matrix<double, nx, nw>& J) {
    Eigen::Matrix<double, n, n> a_q, a_v, minv;
    pinocchio::computeABADerivatives(model, data, Vq(x.head<n>()), Vq(x.tail<n>()), u, a_q, a_v,
                                     minv);
    minv.triangularView<Eigen::StrictlyLower>() =
        minv.transpose().triangularView<Eigen::StrictlyLower>();
    J.setZero();
    J.block<n, n>(0, n + n).setIdentity();  // d q' / d v
    J.block<n, n>(n, 0) = minv;             // d a / d u
    J.block<n, n>(n, n) = a_q;
    J.block<n, n>(n, n + n) = a_v;
    Vx r;
    r.head<n>() = x.tail<n>();
    r.tail<n>() = data.ddq;
    return r;
  }
  Vx step(const Vx& x, const Vu& u, Eigen::Matrix<double, nx, nw>* S) {
    if (!S) {
      const Vx k1 = f(x, u), k2 = f(x + h / 2 * k1, u), k3 = f(x + h / 2 * k2, u),
               k4 = f(x + h * k3, u);
      return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    Eigen::Matrix<double, nx, nw> I0 = Eigen::Matrix<double, nx, nw>::Zero(), J, D1, D2, D3, D4;
    I0.rightCols<nx>().setIdentity();  // d x / d[u; x]
    const auto chain = [&](const Eigen::Matrix<double, nx, nw>& dxs) {
      // d f(xs(w), u) / dw = f_x dxs + f_u [I 0]
      Eigen::Matrix<double, nx, nw> D = J.rightCols<nx>() * dxs;
      D.leftCols<n>() += J.leftCols<n>();
      return D;
    };
    const Vx k1 = f_jac(x, u, J);
    D1 = chain(I0);
    const Vx k2 = f_jac(x + h / 2 * k1, u, J);
    D2 = chain(I0 + h / 2 * D1);
    const Vx k3 = f_jac(x + h / 2 * k2, u, J);
    D3 = chain(I0 + h / 2 * D2);
    const Vx k4 = f_jac(x + h * k3, u, J);
    D4 = chain(I0 + h * D3);
    *S = I0 + h / 6 * (D1 + 2 * D2 + 2 * D3 + D4);
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
};

/// disc_dyn_fun (out: x+) and disc_dyn_fun_jac (out: x+, (d x+ / d[u; x])' of (nu + nx) x nx)
void dyn_eval(void* self, ext_fun_arg_t*, void** in, ext_fun_arg_t*, void** out) {
  auto* e = static_cast<ExtFun*>(self);
  const Vx x = read(in[0], nx);
  const Vu u = read(in[1], n);
  Rk4 rk{*e->model, *e->data};
  auto* fo = static_cast<blasfeo_dvec_args*>(out[0]);
  if (e->jacobian) {
    Eigen::Matrix<double, nx, nw> S;
    const Vx xn = rk.step(x, u, &S);
    blasfeo_pack_dvec(nx, const_cast<double*>(xn.data()), 1, fo->x, fo->xi);
    auto* jo = static_cast<blasfeo_dmat_args*>(out[1]);
    const Eigen::Matrix<double, nw, nx> St = S.transpose();
    blasfeo_pack_dmat(nw, nx, const_cast<double*>(St.data()), nw, jo->A, jo->ai, jo->aj);
  } else {
    const Vx xn = rk.step(x, u, nullptr);
    blasfeo_pack_dvec(nx, const_cast<double*>(xn.data()), 1, fo->x, fo->xi);
  }
}

/// nls_y_fun (out: y) and nls_y_fun_jac (out: y, (dy / d[u; x])'); y = [p_ee, v, u] or [p_ee, v]
template <bool jac>
void cost_eval(void* self, ext_fun_arg_t*, void** in, ext_fun_arg_t*, void** out) {
  auto* e = static_cast<ExtFun*>(self);
  const int nu = e->terminal ? 0 : n, ny = e->terminal ? 3 + n : 3 + 2 * n;
  const Vx x = read(in[0], nx);
  const Eigen::VectorXd u = read(in[1], nu);
  const Vq q = x.head<n>();
  Eigen::VectorXd y(ny);
  Eigen::Matrix<double, 6, n> Jf = Eigen::Matrix<double, 6, n>::Zero();
  if (jac) {
    pinocchio::computeFrameJacobian(*e->model, *e->data, q, e->frame,
                                    pinocchio::LOCAL_WORLD_ALIGNED, Jf);
    pinocchio::updateFramePlacement(*e->model, *e->data, e->frame);
  } else {
    pinocchio::forwardKinematics(*e->model, *e->data, q);
    pinocchio::updateFramePlacement(*e->model, *e->data, e->frame);
  }
  y.head<3>() = e->data->oMf[e->frame].translation();
  y.segment<n>(3) = x.tail<n>();
  if (nu)
    y.tail(nu) = u;
  blasfeo_pack_dvec(ny, y.data(), 1, static_cast<blasfeo_dvec*>(out[0]), 0);
  if (jac) {
    Eigen::MatrixXd Jt = Eigen::MatrixXd::Zero(nu + nx, ny);  // rows [u; x]
    Jt.block(nu, 0, n, 3) = Jf.topRows<3>().transpose();
    Jt.block(nu + n, 3, n, n).setIdentity();
    if (nu)
      Jt.block(0, 3 + n, n, n).setIdentity();
    blasfeo_pack_dmat(nu + nx, ny, Jt.data(), nu + nx, static_cast<blasfeo_dmat*>(out[1]), 0, 0);
  }
}

// ---- the OCP in acados --------------------------------------------------------------------------
struct Acados {
  int N;
  ocp_nlp_plan_t* plan = nullptr;
  ocp_nlp_config* config = nullptr;
  ocp_nlp_dims* dims = nullptr;
  ocp_nlp_in* in = nullptr;
  ocp_nlp_out* out = nullptr;
  void* opts = nullptr;
  ocp_nlp_solver* solver = nullptr;
  std::vector<pinocchio::Data> datas;  // one per external function (no sharing across stages)
  std::vector<ExtFun> funs;

  Acados(const Task& t, int N_, bool rti) : N(N_) {
    plan = ocp_nlp_plan_create(N);
    plan->nlp_solver = rti ? SQP_RTI : SQP;
    plan->ocp_qp_solver_plan.qp_solver = PARTIAL_CONDENSING_HPIPM;
    plan->relaxed_ocp_qp_solver_plan.qp_solver = PARTIAL_CONDENSING_HPIPM;
    plan->regularization = NO_REGULARIZE;
    plan->globalization = rti ? FIXED_STEP : MERIT_BACKTRACKING;
    for (int i = 0; i <= N; ++i) {
      plan->nlp_cost[i] = NONLINEAR_LS;
      plan->nlp_constraints[i] = BGH;
    }
    for (int i = 0; i < N; ++i) {
      plan->nlp_dynamics[i] = DISCRETE_MODEL;
      plan->sim_solver_plan[i].sim_solver = INVALID_SIM_SOLVER;
    }
    config = ocp_nlp_config_create(*plan);
    dims = ocp_nlp_dims_create(config);
    std::vector<int> vnx(N + 1, nx), vnu(N + 1, n), vz(N + 1, 0), vny(N + 1, 3 + 2 * n);
    vnu[N] = 0;
    vny[N] = 3 + n;
    ocp_nlp_dims_set_opt_vars(config, dims, "nx", vnx.data());
    ocp_nlp_dims_set_opt_vars(config, dims, "nu", vnu.data());
    ocp_nlp_dims_set_opt_vars(config, dims, "nz", vz.data());
    ocp_nlp_dims_set_opt_vars(config, dims, "ns", vz.data());
    int nbx0 = nx, nbu = n, zero = 0;
    for (int i = 0; i <= N; ++i) {
      ocp_nlp_dims_set_cost(config, dims, i, "ny", &vny[i]);
      ocp_nlp_dims_set_constraints(config, dims, i, "nbx", i == 0 ? &nbx0 : &zero);
      ocp_nlp_dims_set_constraints(config, dims, i, "nbu", i < N ? &nbu : &zero);
      ocp_nlp_dims_set_constraints(config, dims, i, "ng", &zero);
      ocp_nlp_dims_set_constraints(config, dims, i, "nh", &zero);
    }
    ocp_nlp_dims_set_constraints(config, dims, 0, "nbxe", &nbx0);
    in = ocp_nlp_in_create(config, dims);
    // external functions: per stage a dynamics value, a dynamics Jacobian, a residual, its
    // Jacobian (each with its own Pinocchio data)
    datas.assign(std::size_t(4 * (N + 1)), pinocchio::Data(t.model));
    funs.resize(std::size_t(4 * (N + 1)));
    for (int i = 0; i <= N; ++i) {
      ExtFun* f = &funs[std::size_t(4 * i)];
      for (int j = 0; j < 4; ++j)
        f[j] = {nullptr,
                no_workspace,
                set_no_workspace,
                &t.model,
                &datas[std::size_t(4 * i + j)],
                t.frame,
                i == N,
                false};
      f[0].evaluate = cost_eval<false>;
      f[1].evaluate = cost_eval<true>;
      ocp_nlp_cost_model_set(config, dims, in, i, "nls_y_fun", &f[0]);
      ocp_nlp_cost_model_set(config, dims, in, i, "nls_y_fun_jac", &f[1]);
      if (i < N) {
        f[2].evaluate = dyn_eval;
        f[3].evaluate = dyn_eval, f[3].jacobian = true;
        ocp_nlp_dynamics_model_set(config, dims, in, i, "disc_dyn_fun", &f[2]);
        ocp_nlp_dynamics_model_set(config, dims, in, i, "disc_dyn_fun_jac", &f[3]);
      }
      const int ny = vny[std::size_t(i)];
      Eigen::MatrixXd W = Eigen::MatrixXd::Zero(ny, ny);
      W.diagonal().head<3>().setConstant(2 * (i < N ? w_p : w_pT));
      W.diagonal().segment<n>(3).setConstant(2 * (i < N ? w_v : w_vT));
      if (i < N)
        W.diagonal().tail<n>().setConstant(2 * w_u);
      ocp_nlp_cost_model_set(config, dims, in, i, "W", W.data());
    }
    out = ocp_nlp_out_create(config, dims);
    std::vector<int> idxbu(n), idxbx(nx);
    for (int j = 0; j < nx; ++j)
      idxbx[std::size_t(j)] = j;
    Vu lbu, ubu;
    for (int j = 0; j < n; ++j)
      idxbu[std::size_t(j)] = j, lbu[j] = -tau_max[j], ubu[j] = tau_max[j];
    for (int i = 0; i < N; ++i) {
      ocp_nlp_constraints_model_set(config, dims, in, out, i, "idxbu", idxbu.data());
      ocp_nlp_constraints_model_set(config, dims, in, out, i, "lbu", lbu.data());
      ocp_nlp_constraints_model_set(config, dims, in, out, i, "ubu", ubu.data());
    }
    ocp_nlp_constraints_model_set(config, dims, in, out, 0, "idxbx", idxbx.data());
    ocp_nlp_constraints_model_set(config, dims, in, out, 0, "idxbxe", idxbx.data());
    opts = ocp_nlp_solver_opts_create(config, dims);
    int max_iter = 200, cond_n = N, print = 0;
    double tol = 1e-8;
    if (!rti)
      ocp_nlp_solver_opts_set(config, opts, "max_iter", &max_iter);
    ocp_nlp_solver_opts_set(config, opts, "tol_stat", &tol);
    ocp_nlp_solver_opts_set(config, opts, "tol_eq", &tol);
    ocp_nlp_solver_opts_set(config, opts, "tol_ineq", &tol);
    ocp_nlp_solver_opts_set(config, opts, "tol_comp", &tol);
    ocp_nlp_solver_opts_set(config, opts, "qp_cond_N", &cond_n);
    ocp_nlp_solver_opts_set(config, opts, "print_level", &print);
    solver = ocp_nlp_solver_create(config, dims, opts, in);
    (void)ocp_nlp_precompute(solver, in, out);
  }
  ~Acados() {
    ocp_nlp_solver_destroy(solver);
    ocp_nlp_solver_opts_destroy(opts);
    ocp_nlp_out_destroy(out);
    ocp_nlp_in_destroy(in);
    ocp_nlp_dims_destroy(dims);
    ocp_nlp_config_destroy(config);
    ocp_nlp_plan_destroy(plan);
  }
  void set_x0(const Vx& x0) {
    ocp_nlp_constraints_model_set(config, dims, in, out, 0, "lbx", const_cast<double*>(x0.data()));
    ocp_nlp_constraints_model_set(config, dims, in, out, 0, "ubx", const_cast<double*>(x0.data()));
  }
  void set_target(const Eigen::Vector3d& p) {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(3 + 2 * n);
    y.head<3>() = p;
    for (int i = 0; i <= N; ++i)
      ocp_nlp_cost_model_set(config, dims, in, i, "yref", y.data());
  }
  void set_guess(const std::vector<Vx>& xs, const std::vector<Vu>& us) {
    for (int i = 0; i <= N; ++i)
      ocp_nlp_out_set(config, dims, out, in, i, "x",
                      const_cast<double*>(xs[std::size_t(i)].data()));
    for (int i = 0; i < N; ++i)
      ocp_nlp_out_set(config, dims, out, in, i, "u",
                      const_cast<double*>(us[std::size_t(i)].data()));
  }
  Vx x(int i) {
    Vx v;
    ocp_nlp_out_get(config, dims, out, i, "x", v.data());
    return v;
  }
  Vu u(int i) {
    Vu v;
    ocp_nlp_out_get(config, dims, out, i, "u", v.data());
    return v;
  }
  int iterations() {
    int it = 0;
    ocp_nlp_get(solver, "sqp_iter", &it);
    return it;
  }
  int solve() { return ocp_nlp_solve(solver, in, out); }
  int phase(int p) {
    ocp_nlp_solver_opts_set(config, opts, "rti_phase", &p);
    return ocp_nlp_solve(solver, in, out);
  }
};

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
  const std::vector<Vx> xs_guess(N + 1, x0);
  const std::vector<Vu> us_guess(N, g0);

  auto& ac = A::controller();
  A::set_target(ac, target);
  auto arbor_solve = [&] {
    (void)ac.set_initial_guess(x0, g0);
    return ac.solve(x0);
  };
  const nmpc::NmpcStatus st = arbor_solve();
  const int arbor_iter = ac.info().iterations;
  std::vector<Vx> axs(N + 1), cxs(N + 1);
  std::vector<Vu> aus(N), cus(N);
  for (int k = 0; k <= N; ++k)
    axs[k] = ac.state(k);
  for (int k = 0; k < N; ++k)
    aus[k] = ac.input(k);

  Acados sqp(t, N, false);
  sqp.set_target(target);
  sqp.set_x0(x0);
  auto acados_solve = [&] {
    sqp.set_guess(xs_guess, us_guess);
    return sqp.solve();
  };
  const int ast = acados_solve();
  const int acados_iter = sqp.iterations();
  for (int k = 0; k <= N; ++k)
    cxs[k] = sqp.x(k);
  for (int k = 0; k < N; ++k)
    cus[k] = sqp.u(k);
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
  std::printf(
      "full solves from the same guess (cost by one evaluator; torque bounds active at "
      "the arbor optimum: %d of %d)\n",
      active, N * n);
  std::printf("  arbor SQP        %-18s %3d iterations  cost %.12g\n", nmpc::to_string(st),
              arbor_iter, objective(t, pd, axs, aus, target));
  std::printf(
      "  acados SQP       status %-11d %3d iterations  cost %.12g  max |x diff| %.2e  "
      "max |u diff| %.2e\n",
      ast, acados_iter, objective(t, pd, cxs, cus, target), maxdiff(axs, cxs), maxdiff(aus, cus));

  std::vector<double> ta, tc;
  for (int r = 0; r < o.reps; ++r) {
    auto t0 = Clock::now();
    (void)arbor_solve();
    ta.push_back(us_since(t0));
    t0 = Clock::now();
    (void)acados_solve();
    tc.push_back(us_since(t0));
  }
  const Stats sa = stats(ta), sc = stats(tc);
  std::printf("time per full solve, median / p99 / max [us] (%d solves each):\n", o.reps);
  std::printf("  arbor SQP    %9.0f %9.0f %9.0f   per iteration %7.1f\n", sa.median, sa.p99, sa.max,
              sa.median / arbor_iter);
  std::printf("  acados SQP   %9.0f %9.0f %9.0f   per iteration %7.1f\n", sc.median, sc.p99, sc.max,
              sc.median / acados_iter);
  std::printf("  ratio acados / arbor: per solve %.2f, per iteration %.2f\n", sc.median / sa.median,
              (sc.median / acados_iter) / (sa.median / arbor_iter));

  // closed loop
  Acados rti(t, N, true);
  auto& afc = AF::controller();
  std::vector<double> t_arbor, t_frozen, t_acados, t_prep, t_fb;
  double err_arbor = 0, err_frozen = 0, err_acados = 0;
  int arbor_fail = 0, acados_fail = 0;
  auto arbor_loop = [&](auto& c, auto set_target, std::vector<double>& times, double& err) {
    arbor_fail += arbor_closed_loop(t, o, pd, c, set_target, x0, g0, times, err);
  };
  auto acados_loop = [&] {
    Vx x = x0;
    // start from the converged plan, as the others
    sqp.set_target(t.targets[0]);
    sqp.set_x0(x0);
    (void)acados_solve();
    std::vector<Vx> xs(N + 1);
    std::vector<Vu> us(N);
    for (int k = 0; k <= N; ++k)
      xs[k] = sqp.x(k);
    for (int k = 0; k < N; ++k)
      us[k] = sqp.u(k);
    rti.set_guess(xs, us);
    for (int s = 0; s < o.samples; ++s) {
      const Eigen::Vector3d& p = t.targets[std::size_t(s / 50) % t.targets.size()];
      rti.set_target(p);
      // shift: drop the first node, repeat the last (outside the timing, as arbor's shift())
      for (int k = 0; k < N; ++k)
        xs[k] = rti.x(k + 1);
      xs[N] = rti.x(N);
      for (int k = 0; k + 1 < N; ++k)
        us[k] = rti.u(k + 1);
      us[N - 1] = rti.u(N - 1);
      rti.set_guess(xs, us);
      const auto t0 = Clock::now();
      (void)rti.phase(1);  // its status is ACADOS_READY: the QP is prepared
      const auto t1 = Clock::now();
      rti.set_x0(x);
      const int s1 = rti.phase(2);
      const double tf = us_since(t1);
      t_prep.push_back(t1 - t0);
      t_fb.push_back(tf);
      t_acados.push_back(us_since(t0));
      acados_fail += s1 != 0;
      x = plant_step(t, pd, x, rti.u(0));
      if (s % 50 == 49)
        err_acados = std::max(err_acados, tip_error(t, pd, x, p));
    }
  };
  for (int r = 0; r < o.rounds; ++r) {
    arbor_loop(ac, A::set_target, t_arbor, err_arbor);
    acados_loop();
    arbor_loop(afc, AF::set_target, t_frozen, err_frozen);
  }
  const Stats ra = stats(t_arbor), rf = stats(t_frozen), rc = stats(t_acados), rp = stats(t_prep),
              rb = stats(t_fb);
  print_loop_heading(o);
  print_loop_row("arbor RTI (prepare + feedback), exact RK4 sens.", ra, err_arbor);
  print_loop_row("arbor RTI (prepare + feedback), frozen RK4 sens.", rf, err_frozen);
  print_loop_row("acados SQP_RTI (preparation + feedback)", rc, err_acados);
  std::printf("    of which preparation %8.1f %8.1f %8.1f, feedback %8.1f %8.1f %8.1f\n", rp.median,
              rp.p99, rp.max, rb.median, rb.p99, rb.max);
  std::printf(
      "  ratio acados / arbor RTI sample (exact): median %.2f, max %.2f; (frozen): median "
      "%.2f, max %.2f\n",
      rc.median / ra.median, rc.max / ra.max, rc.median / rf.median, rc.max / rf.max);
  std::printf("  samples not succeeded: arbor %d, acados %d\n", arbor_fail, acados_fail);
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
