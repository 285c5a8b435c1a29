// Optimality reference for the contour-following NMPC (examples/contour; OCP-FD, analytical RBD
// derivatives, hard tunnel, double): along a short real-time-iteration closed loop, at three
// samples, the OCP at the plant's state is solved to tight tolerance by our full SQP (SCQP) and by
// IPOPT, from the same guess (the closed-loop controller's plan at that sample). Our objective
// must be within 1e-6 (relative) of IPOPT's, both solutions feasible to 1e-6, and our KKT
// residuals, recomputed from the plain functions, small. Measured (2026-12-02): relative gaps
// 5e-10 to 8e-10, every tunnel row of stages 1..15 active in IPOPT's solutions; ~35 s, almost all
// of it IPOPT's finite-difference Hessians (~0.7 s per IPOPT iteration).
//
// IPOPT solves the NLP of tests/nmpc/plain_ocp.hpp, with the OCP written here in plain code from
// ../shared/CONTOUR.md (not from examples/contour/task.hpp): RK4 of [qd, FD(q, qd, tau), sd, sdd]
// over h = 0.02 s, the weighted squares of the stage and terminal costs, the tunnel row
// |p_ee - p_ref(s)|^2 <= r^2 on stages 1..N-1 (r = rho - 1 mm, the controller's radius; none
// on stage 0, whose state is the measurement), the Gen3's bounds. Its derivatives are finite
// differences of those plain functions (plain_ocp.hpp), and its Hessian IPOPT's finite
// differences. The RBD values inside the plain functions (FD, end-effector pose) come from arbor's
// double-precision aba and forward kinematics: the textbook RBD (support/textbook_rbd.hpp) is ~20x
// slower, which times the ~10^5 stage evaluations per IPOPT iteration is minutes. They are anchored
// to the textbook RBD at every stage of IPOPT's solutions (to 1e-9), so the NLP IPOPT solves is the
// independent model's up to that tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>

#include "alloc_guard.hpp"
#include "closed_loop.hpp"
#include "plain_ocp.hpp"
#include "problems.hpp"
#include "status_names.hpp"
#include "textbook_rbd.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}

namespace {

using nmpc_test::MatX;
using nmpc_test::PlainOcp;
using nmpc_test::VecX;
using Robot = arbor::robots::KinovaGen3;
using Loop = contour::ContourLoop<contour::Formulation::fd, arbor::ad::Analytical, false, double>;
using Ctrl = Loop::Controller;

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kN = 16, kNx = 16, kNu = 8, kNq = 7;
constexpr double kH = 0.02;
constexpr double kRadius = 0.01 - 1e-3;  // the controller's tunnel: rho less the default back-off
constexpr double kSdScale = 0.2;         // c of sd_ref (the example's default)
constexpr int kSamples[] = {5, 20, 40};  // where the OCPs are compared
constexpr double kObjectiveTol = 1e-6;   // relative
constexpr double kPrimalTol = 1e-6;

// ---- the OCP in plain code (CONTOUR.md) ---------------------------------------------------------
struct Pose {
  Eigen::Vector3d p;
  Eigen::Matrix3d R;
};

/// The plain model: arbor's double-precision RBD values (see the top of this file).
struct PlainModel {
  arbor::Data<Robot, double> data;
  Pose pose(const VecX& q) {
    arbor::forward_kinematics<Robot>(data, Eigen::Matrix<double, kNq, 1>(q));
    const auto& M = arbor::frame_placement<Robot>(data, Robot::frame_id::end_effector_link);
    return {M.p, M.R};
  }
  VecX fd(const VecX& q, const VecX& v, const VecX& tau) {
    using V = Eigen::Matrix<double, kNq, 1>;
    return arbor::aba<Robot>(data, V(q), V(v), V(tau));
  }
};

struct Task {
  Eigen::Vector3d p0;
  Eigen::Matrix3d R0;
};

double sd_ref(double s) {
  return kSdScale *
             ((((5.777783e-13 * s - 34.6153846154) * s + 69.2307692308) * s - 46.7307692308) * s +
              12.1153846154) *
             s +
         kSdScale * 0.0515384615;
}

Eigen::Vector3d p_ref(const Task& t, double s) {
  return t.p0 + Eigen::Vector3d(0.05 * std::sin(4 * kPi * s), 0.15 * std::sin(2 * kPi * s),
                                0.15 * std::sin(2 * kPi * s) * std::cos(2 * kPi * s));
}

/// e_R = 1/2 sum_i n_i x r_i (columns of R and of R_ref).
Eigen::Vector3d rotation_error(const Eigen::Matrix3d& R, const Eigen::Matrix3d& Rref) {
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i)
    e += 0.5 * Eigen::Vector3d(R.col(i)).cross(Eigen::Vector3d(Rref.col(i)));
  return e;
}

/// OCP-FD from x0 (CONTOUR.md), in the layout of plain_ocp.hpp.
PlainOcp plain_contour(const Task& task, const VecX& x0) {
  const auto model = std::make_shared<PlainModel>();
  PlainOcp o;
  o.nx = kNx;
  o.nu = kNu;
  o.N = kN;
  o.nc = 1;
  o.F = [model](const VecX& x, const VecX& u) {
    using X = Eigen::Matrix<double, kNx, 1>;
    using U = Eigen::Matrix<double, kNu, 1>;
    auto ode = [&](const X& y, const U& v) {
      X d;
      d.head<kNq>() = y.segment<kNq>(kNq);
      d.segment<kNq>(kNq) = model->fd(y.head<kNq>(), y.segment<kNq>(kNq), v.head<kNq>());
      d[14] = y[15];
      d[15] = v[7];
      return d;
    };
    return VecX(nmpc_test::rk4_plain(ode, X(x), U(u), kH, 1));
  };
  o.stage_cost = [model, task](const VecX& x, const VecX& u) {
    const Pose P = model->pose(x.head<kNq>());
    const double s = x[14], sd = x[15];
    const double e_sd = sd - sd_ref(s);
    return 20 * e_sd * e_sd + 0.1 * (P.p - p_ref(task, s)).squaredNorm() +
           0.1 * rotation_error(P.R, task.R0).squaredNorm() + 4e-5 * u.head<kNq>().squaredNorm() +
           4e-5 * u[7] * u[7] + 1e-2 * x.head<kNq>().squaredNorm() +
           1e-2 * x.segment<kNq>(kNq).squaredNorm();
  };
  o.terminal_cost = [model, task](const VecX& x) {
    const Pose P = model->pose(x.head<kNq>());
    const double s = x[14], sd = x[15];
    return 1e-5 *
           (1e-4 * x.head<kNq>().squaredNorm() + 100 * x.segment<kNq>(kNq).squaredNorm() +
            1e-4 * (1 - s) * (1 - s) + 100 * sd * sd + 100 * (P.p - p_ref(task, s)).squaredNorm() +
            100 * rotation_error(P.R, task.R0).squaredNorm());
  };
  o.path_constraint = [model, task](const VecX& x, const VecX&) {
    return VecX::Constant(1, (model->pose(x.head<kNq>()).p - p_ref(task, x[14])).squaredNorm());
  };
  o.lc = VecX::Constant(1, -kInf);
  o.uc = VecX::Constant(1, kRadius * kRadius);
  o.lbx = VecX::Constant(kNx, -kInf);
  o.ubx = VecX::Constant(kNx, kInf);
  const double q_max[kNq] = {kInf, 2.2, kInf, 2.5656, kInf, 2.05, kInf};
  const double tau_max[kNq] = {39, 39, 39, 39, 9, 9, 9};
  o.lbu = VecX::Constant(kNu, -kInf);
  o.ubu = VecX::Constant(kNu, kInf);
  for (int i = 0; i < kNq; ++i) {
    o.lbx[i] = -q_max[i];
    o.ubx[i] = q_max[i];
    o.lbx[kNq + i] = -0.8727;
    o.ubx[kNq + i] = 0.8727;
    o.lbu[i] = -tau_max[i];
    o.ubu[i] = tau_max[i];
  }
  o.lbx[14] = 0;
  o.ubx[14] = 1;
  o.lbx[15] = 0;
  o.x0 = x0;
  return o;
}

/// Largest violation of the NLP's constraints and bounds at w (the tunnel row of stage 0, the
/// measured state, excluded).
double primal_violation(const PlainOcp& o, const VecX& w) {
  const VecX g = o.constraints(w);
  double v = g.head(o.nx).cwiseAbs().maxCoeff();
  for (int k = 0; k < o.N; ++k) {
    v = std::max(v, g.segment(o.dyn_row(k), o.nx).cwiseAbs().maxCoeff());
    if (k > 0)
      v = std::max(v, g[o.con_row(k)] - o.uc[0]);
  }
  for (int k = 0; k <= o.N; ++k) {
    const VecX x = o.x_of(w, k);
    if (k > 0)
      v = std::max({v, (o.lbx - x).maxCoeff(), (x - o.ubx).maxCoeff()});
    if (k < o.N) {
      const VecX u = o.u_of(w, k);
      v = std::max({v, (o.lbu - u).maxCoeff(), (u - o.ubu).maxCoeff()});
    }
  }
  return v;
}

/// Max relative difference of arbor's aba and end-effector placement against the textbook RBD
/// at every stage of w (the anchor of the plain model).
double textbook_gap(const PlainOcp& o, const VecX& w) {
  static const arbor::textbook::Model tb = arbor::textbook::make_model<Robot>();
  PlainModel m;
  double gap = 0;
  for (int k = 0; k < o.N; ++k) {
    const VecX x = o.x_of(w, k), u = o.u_of(w, k);
    const VecX q = x.head(kNq), v = x.segment(kNq, kNq), tau = u.head(kNq);
    const VecX a = m.fd(q, v, tau);
    const VecX a_tb = arbor::textbook::aba(tb, q, v, tau, Eigen::Vector3d(0, 0, -9.81));
    gap = std::max(gap, (a - a_tb).cwiseAbs().maxCoeff() / (1 + a_tb.cwiseAbs().maxCoeff()));
    const Pose P = m.pose(q);
    const auto T = arbor::textbook::frame_placements(tb, q)[Robot::frame_id::end_effector_link];
    gap = std::max({gap, (P.p - T.p).cwiseAbs().maxCoeff(), (P.R - T.R).cwiseAbs().maxCoeff()});
  }
  return gap;
}

/// IPOPT on the plain NLP from w0 (FD Hessian, tolerance 1e-9), without the tunnel row of
/// stage 0.
arbor::test::IpoptResult solve_ipopt(const PlainOcp& o, const VecX& w0) {
  arbor::test::Nlp nlp = nmpc_test::make_nlp(o, w0);
  nlp.g_l[std::size_t(o.con_row(0))] = -kInf;
  nlp.g_u[std::size_t(o.con_row(0))] = kInf;
  arbor::test::IpoptOptions opt;
  opt.tol = 1e-9;
  opt.max_iter = 200;
  // the guess (the closed-loop plan) is close to the solution: a small initial barrier
  // parameter (IPOPT's default 0.1 takes 22-30 iterations, this 16-18; same solutions)
  opt.number_options.push_back({"mu_init", 1e-5});
  return arbor::test::solve_with_ipopt(nlp, opt);
}

TEST(ContourIpopt, SqpObjectiveMatchesIpoptAlongTheLoop) {
  contour::Options options;
  options.max_samples = kSamples[std::size(kSamples) - 1];
  const auto loop = std::make_unique<Loop>(options);
  ASSERT_EQ(loop->start(), arbor::nmpc::NmpcStatus::converged);
  const contour::Reference& ref = loop->reference();
  Task task;
  task.p0 = Eigen::Vector3d(ref.p0[0], ref.p0[1], ref.p0[2]);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i)
      task.R0(i, c) = ref.R0[std::size_t(3 * c + i)];
  // the reference's p0, R0 against the textbook forward kinematics at q0
  {
    static const arbor::textbook::Model tb = arbor::textbook::make_model<Robot>();
    const auto T = arbor::textbook::frame_placements(
        tb, VecX(contour::initial_q()))[Robot::frame_id::end_effector_link];
    EXPECT_LE((T.p - task.p0).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((T.R - task.R0).cwiseAbs().maxCoeff(), 1e-12);
  }

  // our tight solver: a second controller of the same problem type
  auto ws = std::make_unique<Loop::W>();
  const auto problem =
      contour::make_problem<contour::Formulation::fd, arbor::ad::Analytical, false>(
          *ws, ref, options.soft_weight, kRadius);
  const auto ctrl = std::make_unique<Ctrl>(problem);
  for (int k = 0; k <= kN; ++k) {
    Ctrl::Vp p = Ctrl::Vp::Zero();  // [tunnel weight, disturbance d = 0]
    p[0] = k == 0 ? 0.0 : 1.0;
    ctrl->set_parameter(k, p);
  }

  int compared = 0;
  for (int n = 1; n <= options.max_samples; ++n) {
    contour::Record rec;
    loop->sample(rec);
    ASSERT_TRUE(arbor::nmpc::succeeded(rec.status)) << "sample " << n;
    if (std::find(std::begin(kSamples), std::end(kSamples), n) == std::end(kSamples))
      continue;
    const VecX x0 = loop->plant_x();
    const PlainOcp o = plain_contour(task, x0);
    VecX w0(o.n());  // the common guess: the closed-loop controller's plan
    for (int k = 0; k <= kN; ++k) {
      w0.segment(o.x_index(k), kNx) = loop->controller().state(k);
      if (k < kN)
        w0.segment(o.u_index(k), kNu) = loop->controller().input(k);
    }
    const arbor::test::IpoptResult ip = solve_ipopt(o, w0);
    const auto run = nmpc_test::solve_nmpc(*ctrl, o, w0, 100, 1e-9, 1e-10);
    ASSERT_EQ(ip.status, 0) << ip.status_name;
    const VecX w_ip = Eigen::Map<const VecX>(ip.w.data(), Eigen::Index(ip.w.size()));
    const double f_ours = o.objective(run.point.w), f_ip = o.objective(w_ip);
    const double f_rel = std::abs(f_ours - f_ip) / std::abs(f_ip);
    const double viol_ours = primal_violation(o, run.point.w), viol_ip = primal_violation(o, w_ip);
    const auto gap = nmpc_test::trajectory_gap(o, run.point.w, w_ip);
    const nmpc_test::Kkt kkt = nmpc_test::kkt_residuals(o, run.point);
    const double anchor = textbook_gap(o, w_ip);
    const int active_ip = nmpc_test::active_count(o, nmpc_test::point_of(ip), 1e-6);
    const int active_ours = nmpc_test::active_count(o, run.point, 1e-6);
    int tunnel_active = 0;  // tunnel rows with a multiplier (IPOPT's)
    for (int k = 1; k < kN; ++k)
      tunnel_active += std::abs(ip.lambda_g[std::size_t(o.con_row(k))]) > 1e-6;
    std::printf(
        "[contour-ipopt] sample %d (s = %.4f): ours %s, %d SQP iterations (%d QP iterations), "
        "%.3f s | IPOPT %s, %d iterations, %.1f s\n"
        "[contour-ipopt]   objective %.12g vs IPOPT %.12g (rel %.2e); violation %.1e vs %.1e; "
        "max |dx| %.1e, |du| %.1e; our KKT (FD): stationarity %.1e, complementarity %.1e; "
        "arbor vs textbook RBD %.1e; active bounds and rows %d vs IPOPT's %d (tunnel rows %d)\n",
        n, x0[14], arbor::nmpc::to_string(run.status), run.info.iterations, run.info.qp_iterations,
        run.seconds, ip.status_name.c_str(), ip.iterations, ip.seconds, f_ours, f_ip, f_rel,
        viol_ours, viol_ip, gap.x, gap.u, kkt.stationarity, kkt.complementarity, anchor,
        active_ours, active_ip, tunnel_active);
    EXPECT_EQ(run.status, arbor::nmpc::NmpcStatus::converged) << "sample " << n;
    EXPECT_LE(f_rel, kObjectiveTol) << "sample " << n;
    EXPECT_LE(viol_ours, kPrimalTol) << "sample " << n;
    EXPECT_LE(viol_ip, kPrimalTol) << "sample " << n;
    EXPECT_LE(kkt.stationarity, 1e-5) << "sample " << n;
    EXPECT_LE(kkt.complementarity, 1e-6) << "sample " << n;
    EXPECT_LE(anchor, 1e-9) << "sample " << n;
    ++compared;
  }
  EXPECT_EQ(compared, int(std::size(kSamples)));
}

}  // namespace
