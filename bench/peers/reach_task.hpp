// The Kinova Gen3 reaching task of issue 57 item 2b, shared by the peer programs (one per peer):
// the task's data on a Pinocchio model of the same URDF, the OCP in arbor's API, one independent
// evaluator of the objective, the plant, the model check and the timing statistics.
//   x = [q, v] (14), u = tau (7); one RK4 step of forward dynamics over h = 0.02 s per interval;
//   stage cost (k < N)  w_p |p_ee(q) - p*|^2 + w_v |v|^2 + w_u |tau|^2,
//   terminal cost       w_pT |p_ee(q_N) - p*|^2 + w_vT |v_N|^2,
//   |tau_j| <= the URDF's effort, nothing else.
// Weights multiply squares (arbor's least_squares); a peer whose quadratic is 1/2 r' W r takes
// W = 2 w. The cost is charged at the nodes (not integrated along the RK4 stages).
// Costs: everything here is setup or checking, outside the timed calls.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <arbor/arbor.hpp>
#include <robots/kinova_gen3.hpp>

namespace reach {

namespace ad = arbor::ad;
namespace ocp = arbor::ocp;
namespace nmpc = arbor::nmpc;
using Robot = arbor::robots::KinovaGen3;
using VecX = Eigen::VectorXd;
constexpr int n = Robot::nv, nx = 2 * n, ee = Robot::frame_id::end_effector_link;
constexpr double h = 0.02;
constexpr double w_p = 100, w_v = 0.1, w_u = 1e-3, w_pT = 1000, w_vT = 1;
constexpr double tau_max[n] = {39, 39, 39, 39, 9, 9, 9};
using Vx = Eigen::Matrix<double, nx, 1>;
using Vu = Eigen::Matrix<double, n, 1>;
using Vq = Eigen::Matrix<double, n, 1>;

// ---- the task's data, shared by both frameworks -------------------------------------------------
struct Task {
  pinocchio::Model model;  // the same URDF; continuous joints read as revolute (nq = nv = 7)
  pinocchio::FrameIndex frame = 0;
  Vq q0;
  std::vector<Eigen::Vector3d> targets;
};

inline Task make_task(const char* urdf_path) {
  Task t;
  std::ifstream f(urdf_path);
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  // Pinocchio maps a continuous joint to (cos, sin) (nq = 2); arbor to its angle. Same dynamics.
  for (std::size_t at; (at = xml.find("type=\"continuous\"")) != std::string::npos;)
    xml.replace(at, 17, "type=\"revolute\"");
  pinocchio::urdf::buildModelFromXML(xml, t.model);
  t.frame = t.model.getFrameId("end_effector_link");
  const double pi = 3.14159265358979323846;
  t.q0 << 0, pi / 6, 0, 2 * pi / 3, 0, -pi / 3, -pi / 2;  // the contour demo's start
  pinocchio::Data d(t.model);
  pinocchio::framesForwardKinematics(t.model, d, t.q0);
  const Eigen::Vector3d p0 = d.oMf[t.frame].translation();
  t.targets = {p0 + Eigen::Vector3d(0.10, 0.10, -0.05), p0 + Eigen::Vector3d(-0.05, 0.15, 0.05),
               p0 + Eigen::Vector3d(0.05, -0.10, 0.10)};
  return t;
}

/// The OCP's objective of a trajectory, evaluated independently of both frameworks.
inline double objective(const Task& t, pinocchio::Data& d, const std::vector<Vx>& xs,
                        const std::vector<Vu>& us, const Eigen::Vector3d& target) {
  const int N = int(us.size());
  double J = 0;
  for (int k = 0; k <= N; ++k) {
    pinocchio::framesForwardKinematics(t.model, d, Vq(xs[k].head<n>()));
    const double e = (d.oMf[t.frame].translation() - target).squaredNorm();
    const double v = xs[k].tail<n>().squaredNorm();
    J += k < N ? w_p * e + w_v * v + w_u * us[k].squaredNorm() : w_pT * e + w_vT * v;
  }
  return J;
}

// ---- statistics -------------------------------------------------------------------------------
struct Stats {
  double median, p99, max;
};
inline Stats stats(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const auto at = [&](double f) { return v[std::min(v.size() - 1, std::size_t(f * v.size()))]; };
  return {at(0.5), at(0.99), v.back()};
}
/// The clock of every timed call [us]: wall time by default; with `--cpu`, this thread's CPU time
/// (CLOCK_THREAD_CPUTIME_ID), which leaves out the time the scheduler gave other processes: on a
/// shared machine a wall-clock maximum measures the neighbours as much as the call.
inline bool use_cpu_clock = false;
struct Clock {
  using time_point = double;
  static double now() {
    timespec ts;
    clock_gettime(use_cpu_clock ? CLOCK_THREAD_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
    return double(ts.tv_sec) * 1e6 + double(ts.tv_nsec) * 1e-3;
  }
};
inline double us_since(double t0) {
  return Clock::now() - t0;
}

/// The programs' options: `--cpu` (use_cpu_clock), `--quick` (a short run), `--N 16|30` (one
/// horizon only).
struct Options {
  int reps = 30;      ///< full solves timed per framework
  int samples = 300;  ///< closed-loop samples per loop
  int rounds = 3;     ///< loops per framework, alternated
  int only_n = 0;     ///< 0: every horizon
  bool runs(int n) const { return only_n == 0 || only_n == n; }
};
inline Options parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--cpu"))
      use_cpu_clock = true;
    else if (!std::strcmp(argv[i], "--quick"))
      o.reps = 3, o.samples = 100, o.rounds = 1;
    else if (!std::strcmp(argv[i], "--N") && i + 1 < argc)
      o.only_n = std::atoi(argv[++i]);
  }
  return o;
}

// ---- arbor: the OCP in arbor's API (docs/tutorial.md's shape) ---------------------------------
template <int N, ocp::Sensitivity S>
struct ArborReach {
  using D = ocp::Dims<nx, n, 3, N>;  // p = the target
  using Tag = ad::Analytical;
  static constexpr auto H = ocp::HessianKind::gauss_newton;
  using Fd = ad::ForwardDynamics<Robot>;
  using Tip = ad::FramePosition<Robot, ee>;
  using Workspace = nmpc::Workspace<D, Tag, double, H, nmpc::PathOnly<Fd>, Tip>;
  static auto make_problem(Workspace& ws) {
    const auto q = ad::segment<0, n>(D::x);
    const auto v = ad::segment<n, n>(D::x);
    const auto ode = ad::cat(v, ad::call<Tag>(ad::bind<Fd>(ws), q, v, D::u));
    const auto e_p = ad::call<Tag>(ad::bind<Tip>(ws), q) - D::p;
    auto problem = ocp::make_problem<D>(
        ocp::rk4<1, S>(ode, h),
        ocp::path_costs(ocp::least_squares(e_p, w_p), ocp::least_squares(v, w_v),
                        ocp::least_squares(D::u, w_u)),
        ocp::terminal_costs(ocp::least_squares(e_p, w_pT), ocp::least_squares(v, w_vT)));
    for (int j = 0; j < n; ++j)
      problem.lbu[j] = -tau_max[j], problem.ubu[j] = tau_max[j];
    return problem;
  }
  using Problem = decltype(make_problem(std::declval<Workspace&>()));
  using Ctrl = nmpc::Nmpc<Problem, double, H>;
  // static storage: the controller is large and must outlive nothing else
  static Ctrl& controller() {
    static Workspace ws;
    static Problem problem = make_problem(ws);
    static Ctrl ctrl(problem);
    return ctrl;
  }
  static void set_target(Ctrl& c, const Eigen::Vector3d& p) {
    for (int k = 0; k <= N; ++k)
      c.set_parameter(k, p);
  }
};

// ---- checks -------------------------------------------------------------------------------------
/// Largest difference of arbor's and Pinocchio's frame position and ABA at random states.
inline void check_models(const Task& t) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  pinocchio::Data pd(t.model);
  static arbor::Data<Robot, double> adata;
  double dp = 0, da = 0;
  for (int i = 0; i < 20; ++i) {
    Vq q, v, tau;
    for (int j = 0; j < n; ++j)
      q[j] = 2 * U(rng), v[j] = U(rng), tau[j] = 5 * U(rng);
    pinocchio::framesForwardKinematics(t.model, pd, q);
    arbor::forward_kinematics<Robot>(adata, q);
    arbor::update_frame_placements<Robot>(adata);
    dp = std::max(dp, (pd.oMf[t.frame].translation() - adata.oMf[ee].p).cwiseAbs().maxCoeff());
    const Vq a_pin = pinocchio::aba(t.model, pd, q, v, tau);
    const Vq a_arb = arbor::aba<Robot>(adata, q, v, tau);
    da = std::max(da, (a_pin - a_arb).cwiseAbs().maxCoeff() / (1 + a_pin.cwiseAbs().maxCoeff()));
  }
  std::printf("model check (20 random states): max |p_ee diff| %.2e m, max rel |FD diff| %.2e\n",
              dp, da);
}

/// The closed-loop table's heading, and one row: a framework's time per sample (median / p99 / max
/// [us]) and its worst tip error [mm].
inline void print_loop_heading(const Options& o) {
  std::printf(
      "closed loop, %d x %d samples each (target moves every 50): time per sample, "
      "median / p99 / max [us], worst tip error at the end of a target's 1 s [mm]\n",
      o.rounds, o.samples);
}
inline void print_loop_row(const char* name, const Stats& r, double err) {
  std::printf("  %-48s %8.1f %8.1f %8.1f   %6.2f\n", name, r.median, r.p99, r.max, 1e3 * err);
}

/// The plant's tip error [m] against the target p at state x (Pinocchio's kinematics).
inline double tip_error(const Task& t, pinocchio::Data& d, const Vx& x, const Eigen::Vector3d& p) {
  pinocchio::framesForwardKinematics(t.model, d, Eigen::Matrix<double, n, 1>(x.head<n>()));
  return (d.oMf[t.frame].translation() - p).norm();
}

/// arbor's closed loop of the reach, the baseline of every program: the controller c (target set
/// by set_target(c, p)) from a plan converged at the first target, then o.samples real-time
/// iterations (shift, prepare, feedback; the target moved every 50 samples) against
/// plant_step; the time of prepare + feedback per sample into times (with prep and fb, the two
/// phases apart too), the worst tip error at the end of a target's second into err. Returns the
/// samples whose status did not succeed.
template <class C, class SetTarget>
int arbor_closed_loop(const Task& t, const Options& o, pinocchio::Data& d, C& c,
                      SetTarget set_target, const Vx& x0, const Vu& g0, std::vector<double>& times,
                      double& err, std::vector<double>* prep = nullptr,
                      std::vector<double>* fb = nullptr) {
  int failed = 0;
  Vx x = x0;
  (void)c.set_initial_guess(x0, g0);
  set_target(c, t.targets[0]);
  (void)c.solve(x0);  // the loop starts from a converged plan, as the peers' do
  for (int s = 0; s < o.samples; ++s) {
    const Eigen::Vector3d& p = t.targets[std::size_t(s / 50) % t.targets.size()];
    set_target(c, p);
    c.shift();
    const auto t0 = Clock::now();
    nmpc::NmpcStatus st = c.prepare();
    const auto t1 = Clock::now();
    if (st == nmpc::NmpcStatus::prepared)
      st = c.feedback(x);
    times.push_back(us_since(t0));
    if (prep != nullptr && fb != nullptr)
      prep->push_back(t1 - t0), fb->push_back(us_since(t1));
    failed += !nmpc::succeeded(st);
    x = plant_step(t, d, x, c.control());
    if (s % 50 == 49)
      err = std::max(err, tip_error(t, d, x, p));
  }
  return failed;
}

/// The task of the URDF at urdf_path, its models checked against each other, the clock named.
inline Task start_task(const char* urdf_path) {
  Task t = make_task(urdf_path);
  check_models(t);
  std::printf("times: %s\n", use_cpu_clock ? "this thread's CPU time (--cpu)" : "wall clock");
  return t;
}

/// The plant: Pinocchio's ABA, semi-implicit Euler at 1 ms over one sample.
inline Vx plant_step(const Task& t, pinocchio::Data& d, Vx x, const Vu& tau) {
  for (int s = 0; s < 20; ++s) {
    x.tail<n>() += 1e-3 * pinocchio::aba(t.model, d, Vq(x.head<n>()), Vq(x.tail<n>()), tau);
    x.head<n>() += 1e-3 * x.tail<n>();
  }
  return x;
}

}  // namespace reach
