// Contour-following NMPC of the Kinova Gen3 in closed loop (the paper's section 5.2; the task is
// ../../shared/CONTOUR.md, summarised in README.md here). One executable per compile-time
// configuration (CMake targets contour, contour_fd_ad, contour_fd_gen, contour_id, contour_id_ad,
// contour_id_gen, contour_fd_soft):
//   CONTOUR_ID        0: OCP-FD (u = [tau, sdd]), 1: OCP-ID (u = [qdd, sdd])
//   CONTOUR_AUTODIFF  0: analytical RBD derivatives, 1: AD through the RBD templates (dual
//                     numbers), 2: code-generated AD (gen/ad; the pose node by dual numbers)
//   CONTOUR_SOFT      0: hard tunnel, 1: soft tunnel (exact-penalty slack)
//   CONTOUR_MUJOCO    1: MuJoCo is available as the plant (the default, `--plant mujoco`;
//                     CONTOUR_URDF is the Gen3's URDF it loads); 0: arbor's plant only
//   CONTOUR_FROZEN_SENSITIVITY, CONTOUR_GENERATED_STAGE (task.hpp, mpc.hpp), CONTOUR_FLAGS (the
//                     compiler flags, printed): the configuration (CMakeLists.txt)
// Prints progress, a summary table, and writes a CSV log (plot it with plot.py). `--help`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#if CONTOUR_AUTODIFF == 2
#include <robots/kinova_gen3_ad.hpp>  // before closed_loop.hpp (task.hpp): GeneratedCode
#endif
#include "closed_loop.hpp"
#if CONTOUR_MUJOCO
#include "mujoco_plant.hpp"
#endif

#ifndef CONTOUR_ID
#define CONTOUR_ID 0
#endif
#ifndef CONTOUR_AUTODIFF
#define CONTOUR_AUTODIFF 0
#endif
#ifndef CONTOUR_SOFT
#define CONTOUR_SOFT 0
#endif
#ifndef CONTOUR_MUJOCO
#define CONTOUR_MUJOCO 0
#endif
#ifndef CONTOUR_CONFIGURATION
#define CONTOUR_CONFIGURATION "contour"
#endif
#ifndef CONTOUR_FLAGS
#define CONTOUR_FLAGS "(not given)"
#endif

namespace {

using namespace contour;
constexpr Formulation kForm = CONTOUR_ID ? Formulation::id : Formulation::fd;
using Tag = std::conditional_t<
    CONTOUR_AUTODIFF == 2, arbor::ad::Generated,
    std::conditional_t<CONTOUR_AUTODIFF == 1, arbor::ad::AutoDiff, arbor::ad::Analytical>>;
constexpr bool kSoft = CONTOUR_SOFT != 0;
constexpr const char* kTagName = CONTOUR_AUTODIFF == 2   ? "Generated"
                                 : CONTOUR_AUTODIFF == 1 ? "AutoDiff"
                                                         : "Analytical";
using Loop = ContourLoop<kForm, Tag, kSoft, double>;

void usage(const char* argv0) {
  std::printf(
      "usage: %s [options]\n"
      "Closed-loop contour following on the Kinova Gen3: %s, %s RBD derivatives, %s tunnel\n"
      "(compile-time choices; other executables: contour, contour_fd_ad, contour_fd_gen,\n"
      "contour_id, contour_id_ad, contour_id_gen, contour_fd_soft).\n"
      "  --csv FILE        write the per-sample log (default contour.csv; '-' for none)\n"
      "  --c C             progress-speed scale of sd_ref (default 0.2; the task code: 0.025, "
      "0.2)\n"
      "  --samples N       at most N samples of 0.02 s (default 4000)\n"
      "  --s-end S         stop when s > S (default 0.99)\n"
      "  --sqp [K]         paper's mode: full SQP per sample, at most K iterations (default 5)\n"
      "                    and CONTOUR.md's tolerances, scaled tunnel row (default: real-time\n"
      "                    iteration)\n"
      "  --plant P         the simulated plant: mujoco (default when built with MuJoCo: its own\n"
      "                    URDF parser and dynamics) or arbor (arbor's aba + RK4 at 1 ms)%s\n"
      "  --mismatch        plant carries 0.5 kg at the end effector (controller: nominal model)\n"
      "  --payload-at T    MuJoCo plant: the 0.5 kg payload attached at t = T s, in mid-motion\n"
      "                    (unknown to the controller; implies --mismatch)\n"
      "  --payload-release T  MuJoCo plant: the payload released at t = T s (implies --mismatch)\n"
      "  --push-at T       MuJoCo plant: a push on the forearm from t = T s (default 10 N along\n"
      "                    world +x for 0.1 s)\n"
      "  --push-force F    its force [N]    --push-duration D  its length [s]\n"
      "  --delay N         the measurement is the plant's state N plant steps (1 ms) before the\n"
      "                    sample's end (default 0; at most 15)\n"
      "  --known-payload   as --mismatch, the payload declared to the controller at run time\n"
      "                    (ad::set_payload on its workspace; the generated robot unchanged)\n"
      "  --damping D       MuJoCo plant: joint damping D [N m s/rad] on every joint (default 0;\n"
      "                    unknown to the controller)\n"
      "  --armature A      MuJoCo plant: armature A [kg m^2] on every joint (default 0; unknown)\n"
      "  --frictionloss F  MuJoCo plant: dry friction F [N m] on every joint (default 0; unknown)\n"
      "  --plant-dt DT     MuJoCo plant: its time step (default 0.001 s; divides 0.02 s)\n"
      "  --plant-integrator I  MuJoCo plant: rk4 (default) or euler (MuJoCo's semi-implicit)\n"
      "  --urdf FILE       MuJoCo plant: the Gen3's URDF (default the source tree's)\n"
      "  --noise SIGMA     measurement noise std. dev. on q [rad] (qd: 10 SIGMA), default 0\n"
      "  --seed N          noise seed (default 1)\n"
      "  --soft-weight W   slack weight of the soft tunnel (soft builds; default 100)\n"
      "  --scaled-tunnel   tunnel row |e_p / radius|^2 - 1 <= 0 (order one; default in RTI:\n"
      "                    |e_p|^2 - radius^2 <= 0, of order 1e-4 m^2; --sqp sets it, since\n"
      "                    CONTOUR.md's absolute 1e-3 primal tolerance admits |e_p| up to 33 mm\n"
      "                    on the unscaled row)\n"
      "  --backoff B       the controller's tunnel radius is rho - B (default 1e-3 m: margin for\n"
      "                    the disturbances and the linearisation error of real-time iteration)\n"
      "  --qp-iter N       at most N active-set iterations per QP (default: the library's)\n"
      "  --qp-tol T        QP tolerances in RTI mode (default 1e-8; 0: the library's)\n"
      "  --feedback-iter K RTI: bound the feedback's QP to K iterations, its step taken anyway\n"
      "                    (default 2; 0: no bound)\n"
      "  --no-presolve     RTI: the feedback computes its first QP step itself instead of moving\n"
      "                    the one prepare() computed (the library's default; more latency, less\n"
      "                    work per sample)\n"
      "  --shift-multipliers  shift() moves the multipliers with the plan (the QP's warm start\n"
      "                    one stage earlier; default: kept in place, see README)\n"
      "  --observer        generalized-momentum observer (arbor/nmpc/momentum_observer.hpp): the\n"
      "                    joint torque the model lacks, estimated and fed to the OCP (OCP-FD;\n"
      "                    the default)   --no-observer  without it\n"
      "  --observer-gain K its gain [1/s] (default 20)\n"
      "  --observer-rate R plant (default: after every plant step, the torque loop's rate) or\n"
      "                    sample (once per 0.02 s sample)\n"
      "  --hold T          start phase: hold the initial pose for T s before the task starts\n"
      "                    (default 0.5; the figures count from the task's start)\n"
      "  --qd-margin M     the controller's velocity bound is (1 - M) qd_max (default 0)\n"
      "  --state-filter A  the controller gets prediction + A (measurement - prediction) on q, qd\n"
      "                    (the last plan's x_1 as the prediction; default 0.3; 0: off)\n"
      "  --inner-loop      OCP-FD: a torque-rate inner loop at every plant step on the QP's own\n"
      "                    feedback gain (arbor/nmpc/inner_loop.hpp; with the observer also the\n"
      "                    estimate's change since the sample; the default)\n"
      "  --no-inner-loop   without it\n"
      "  --progress N      print a progress line every N samples (default 50; 0: none)\n"
      "  --help            this text\n",
      argv0, to_string(kForm), kTagName, kSoft ? "soft" : "hard",
      CONTOUR_MUJOCO ? "" : "\n                    (this build has no MuJoCo: arbor only)");
}

/// The widest x86 vector instruction set the program was compiled for.
const char* isa() {
#if defined(__AVX512F__)
  return "AVX-512";
#elif defined(__AVX2__) && defined(__FMA__)
  return "AVX2 + FMA";
#elif defined(__AVX__)
  return "AVX";
#elif defined(__SSE2__)
  return "SSE2";
#elif defined(__ARM_NEON)
  return "NEON";
#else
  return "scalar";
#endif
}

/// Quantile q of v (nearest rank; v is copied).
double quantile(std::vector<double> v, double q) {
  if (v.empty())
    return 0;
  std::sort(v.begin(), v.end());
  const auto i = std::size_t(std::ceil(q * double(v.size()))) - (q > 0 ? 1 : 0);
  return v[std::min(i, v.size() - 1)];
}

void write_csv(const char* path, const std::vector<Record>& log) {
  FILE* f = std::fopen(path, "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path);
    return;
  }
  std::fprintf(f, "t,s,sd,sd_ref,px,py,pz,px_ref,py_ref,pz_ref,e_p,e_R");
  for (const char* name : {"q", "qd", "tau", "tau_peak"})
    for (int i = 1; i <= nq; ++i)
      std::fprintf(f, ",%s%d", name, i);
  for (int i = 1; i <= nu; ++i)
    std::fprintf(f, ",u%d", i);
  std::fprintf(f, ",prepare_us,feedback_us,sqp_iterations,qp_iterations,status,qp_status,hold");
  for (int i = 1; i <= nq; ++i)
    std::fprintf(f, ",d%d", i);
  std::fprintf(f, ",e_p_step");  // the sample's peaks over its 1 ms plant steps
  for (int i = 1; i <= nq; ++i)
    std::fprintf(f, ",qd_step%d", i);
  std::fprintf(f, "\n");
  for (const Record& r : log) {
    std::fprintf(f, "%.4f,%.9g,%.9g,%.9g", r.t, r.x[14], r.x[15], r.sd_ref);
    for (int i = 0; i < 3; ++i)
      std::fprintf(f, ",%.9g", r.p[i]);
    for (int i = 0; i < 3; ++i)
      std::fprintf(f, ",%.9g", r.p_ref[i]);
    std::fprintf(f, ",%.6g,%.6g", r.e_p, r.e_R);
    for (int i = 0; i < 2 * nq; ++i)
      std::fprintf(f, ",%.9g", r.x[i]);
    for (int i = 0; i < nq; ++i)
      std::fprintf(f, ",%.6g", r.tau[i]);
    for (int i = 0; i < nq; ++i)
      std::fprintf(f, ",%.6g", r.tau_peak[i]);
    for (int i = 0; i < nu; ++i)
      std::fprintf(f, ",%.6g", r.u[i]);
    std::fprintf(f, ",%.2f,%.2f,%d,%d,%s,%s,%d", r.prepare_us, r.feedback_us, r.sqp_iterations,
                 r.qp_iterations, arbor::nmpc::to_string(r.status),
                 arbor::qp::to_string(r.qp_status), r.hold ? 1 : 0);
    for (int i = 0; i < nq; ++i)
      std::fprintf(f, ",%.6g", r.d_hat[i]);
    std::fprintf(f, ",%.6g", r.peaks.e_p);
    for (int i = 0; i < nq; ++i)
      std::fprintf(f, ",%.6g", r.peaks.qd[i]);
    std::fprintf(f, "\n");
  }
  std::fclose(f);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  o.hold = 0.5;  // the demo starts as a robot starts a task
  // The feedback's QP bounded to 2 iterations (its step taken anyway, step_limited): the worst
  // sample's cost near the median's, the closed loop the same (README.md, "Configurations")
  o.feedback_qp_iter = 2;
  // One configuration for the disturbances a robot meets (README.md, "Disturbances in the
  // middle of the task"): the torque-rate inner loop on the QP's feedback gain, the momentum
  // observer at the plant's rate, the state filter 0.3 and a 1 mm tunnel back-off; each part off
  // with --no-inner-loop, --no-observer, --state-filter 0 (and the back-off's size with --backoff;
  // task.hpp's default_backoff, 1 mm)
  o.inner_loop = true;
  o.observer = true;
  o.state_filter = 0.3;
  bool use_mujoco = CONTOUR_MUJOCO != 0;
#if CONTOUR_MUJOCO
  MujocoPlantOptions mo;
  mo.urdf = CONTOUR_URDF;
#endif
  double damping = 0, armature = 0, frictionloss = 0, plant_dt = 1e-3;
  double payload_on = -1, payload_off = -1, push_at = -1, push_force = 10, push_duration = 0.1;
  bool euler = false;
  std::string urdf;
  std::string csv = "contour.csv";
  int progress = 50;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* what) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs %s\n", a.c_str(), what);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage(argv[0]);
      return 0;
    } else if (a == "--csv") {
      csv = value("a file name");
    } else if (a == "--c") {
      o.c = std::atof(value("a number"));
    } else if (a == "--samples") {
      o.max_samples = std::atoi(value("a number"));
    } else if (a == "--s-end") {
      o.s_end = std::atof(value("a number"));
    } else if (a == "--sqp") {
      o.sqp = true;  // (ContourLoop then scales the tunnel row)
      if (i + 1 < argc && argv[i + 1][0] != '-')
        o.sqp_iter = std::atoi(argv[++i]);
    } else if (a == "--plant") {
      const std::string p = value("mujoco or arbor");
      if (p == "arbor") {
        use_mujoco = false;
      } else if (p == "mujoco") {
        if (!CONTOUR_MUJOCO) {
          std::fprintf(stderr, "this build has no MuJoCo (install libmujoco-dev, reconfigure)\n");
          return 2;
        }
        use_mujoco = true;
      } else {
        std::fprintf(stderr, "--plant: mujoco or arbor, not %s\n", p.c_str());
        return 2;
      }
    } else if (a == "--damping") {
      damping = std::atof(value("a number"));
    } else if (a == "--armature") {
      armature = std::atof(value("a number"));
    } else if (a == "--frictionloss") {
      frictionloss = std::atof(value("a number"));
    } else if (a == "--plant-dt") {
      plant_dt = std::atof(value("a number"));
    } else if (a == "--plant-integrator") {
      const std::string p = value("rk4 or euler");
      if (p != "rk4" && p != "euler") {
        std::fprintf(stderr, "--plant-integrator: rk4 or euler, not %s\n", p.c_str());
        return 2;
      }
      euler = p == "euler";
    } else if (a == "--urdf") {
      urdf = value("a file name");
    } else if (a == "--mismatch") {
      o.mismatch = true;
    } else if (a == "--payload-at") {
      o.mismatch = true;
      payload_on = std::atof(value("a time [s]"));
    } else if (a == "--payload-release") {
      o.mismatch = true;
      payload_off = std::atof(value("a time [s]"));
    } else if (a == "--push-at") {
      push_at = std::atof(value("a time [s]"));
    } else if (a == "--push-force") {
      push_force = std::atof(value("a force [N]"));
    } else if (a == "--push-duration") {
      push_duration = std::atof(value("a time [s]"));
    } else if (a == "--delay") {
      o.delay_steps = std::atoi(value("a number of plant steps"));
      if (o.delay_steps < 0 || o.delay_steps >= StepMonitor::kKeep) {
        std::fprintf(stderr, "--delay: 0 to %d plant steps\n", StepMonitor::kKeep - 1);
        return 2;
      }
    } else if (a == "--known-payload") {
      o.mismatch = true;
      o.known_payload = true;
    } else if (a == "--noise") {
      o.noise = std::atof(value("a number"));
    } else if (a == "--seed") {
      o.seed = std::uint32_t(std::atol(value("a number")));
    } else if (a == "--soft-weight") {
      o.soft_weight = std::atof(value("a number"));
    } else if (a == "--scaled-tunnel") {
      o.scaled_tunnel = true;
    } else if (a == "--backoff") {
      o.backoff = std::atof(value("a number"));
    } else if (a == "--qp-tol") {
      o.qp_tol = std::atof(value("a number"));
    } else if (a == "--qp-iter") {
      o.qp_max_iter = std::atoi(value("a number"));
    } else if (a == "--feedback-iter") {
      o.feedback_qp_iter = std::atoi(value("a number"));
    } else if (a == "--presolve") {  // (the default; kept for scripts that name it)
      o.presolve = true;
    } else if (a == "--no-presolve") {
      o.presolve = false;
    } else if (a == "--shift-multipliers") {
      o.shift_multipliers = true;
    } else if (a == "--observer") {
      o.observer = true;
    } else if (a == "--no-observer") {
      o.observer = false;
    } else if (a == "--observer-gain") {
      o.observer_gain = std::atof(value("a number"));
    } else if (a == "--observer-rate") {
      const std::string p = value("plant or sample");
      if (p != "plant" && p != "sample") {
        std::fprintf(stderr, "--observer-rate: plant or sample, not %s\n", p.c_str());
        return 2;
      }
      o.observer_plant_rate = p == "plant";
    } else if (a == "--hold") {
      o.hold = std::atof(value("a number"));
    } else if (a == "--state-filter") {
      o.state_filter = std::atof(value("a number"));
    } else if (a == "--qd-margin") {
      o.qd_margin = std::atof(value("a number"));
    } else if (a == "--inner-loop") {
      o.inner_loop = true;
    } else if (a == "--no-inner-loop") {
      o.inner_loop = false;
    } else if (a == "--progress") {
      progress = std::atoi(value("a number"));
    } else {
      std::fprintf(stderr, "unknown option %s (see --help)\n", a.c_str());
      return 2;
    }
  }

  const bool mujoco_only = damping != 0 || armature != 0 || frictionloss != 0 || euler ||
                           plant_dt != 1e-3 || !urdf.empty() || payload_on >= 0 ||
                           payload_off >= 0 || push_at >= 0;
  if (!use_mujoco && mujoco_only) {
    std::fprintf(stderr,
                 "--damping, --armature, --frictionloss, --plant-dt, --plant-integrator, --urdf, "
                 "--payload-at, --payload-release, --push-at need the MuJoCo plant%s\n",
                 CONTOUR_MUJOCO ? " (--plant mujoco)" : " (this build has none)");
    return 2;
  }

  static Loop loop(o);  // the controller is large: static storage
  std::string plant_name = "arbor (aba, RK4 at 1 ms)";
#if CONTOUR_MUJOCO
  static MujocoPlant mujoco;
  if (use_mujoco) {
    if (!urdf.empty())
      mo.urdf = urdf;
    mo.dt = plant_dt;
    mo.euler = euler;
    mo.payload = o.mismatch ? PayloadRobot::payload : 0.0;
    mo.joints = {damping, armature, frictionloss};
    mo.payload_on = payload_on;
    mo.payload_off = payload_off;
    mo.push_at = push_at;
    mo.push_force = push_force;
    mo.push_duration = push_duration;
    if (o.delay_steps >= int(std::lround(h / plant_dt))) {
      std::fprintf(stderr, "--delay: fewer plant steps than a sample has\n");
      return 2;
    }
    std::string err;
    if (!mujoco.init(mo, err)) {
      std::fprintf(stderr, "MuJoCo plant: %s\n", err.c_str());
      return 2;
    }
    loop.use_plant(mujoco);
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "MuJoCo %s (%s, %g ms; damping %g, armature %g, frictionloss %g)",
                  mj_versionString(), euler ? "Euler" : "RK4", 1e3 * plant_dt, damping, armature,
                  frictionloss);
    plant_name = buf;
    if (payload_on >= 0 || payload_off >= 0) {
      std::snprintf(buf, sizeof buf, "; payload attached at %g s", std::max(payload_on, 0.0));
      plant_name += buf;
      if (payload_off >= 0) {
        std::snprintf(buf, sizeof buf, ", released at %g s", payload_off);
        plant_name += buf;
      }
    }
    if (push_at >= 0) {
      std::snprintf(buf, sizeof buf, "; push %g N on the forearm at %g s for %g s", push_force,
                    push_at, push_duration);
      plant_name += buf;
    }
  }
#else
  std::printf("(built without MuJoCo: arbor's plant only; Debian: libmujoco-dev)\n");
#endif
  std::printf(
      "Kinova Gen3 contour following: %s, %s RBD derivatives, %s tunnel (rho = %g m), "
      "N = %d, h = %g s, %s\n",
      to_string(kForm), kTagName, kSoft ? "soft" : "hard", rho, horizon, h,
      o.sqp ? "SQP mode" : "real-time iteration");
  std::printf(
      "sizeof controller %zu bytes, RBD workspace %zu bytes; c = %g, back-off %g mm, plant: %s%s\n",
      sizeof(Loop::Controller), sizeof(Loop::W), o.c, 1e3 * Loop::backoff(o),
      !o.mismatch       ? "nominal model"
      : o.known_payload ? "+0.5 kg payload (known to the controller)"
                        : "+0.5 kg payload (unknown to the controller)",
      o.noise > 0 ? ", measurement noise" : "");
  std::printf("plant: %s\n", plant_name.c_str());
  std::printf(
      "configuration %s: RK4 sensitivities %s, stages from %s, feedback bound %s, presolved "
      "feedback %s; compiled with %s (%s)\n",
      CONTOUR_CONFIGURATION,
      rk4_sensitivity == arbor::ocp::Sensitivity::frozen ? "frozen" : "exact",
      loop.generated_stage() ? "generated code" : "the expression layer",
      o.feedback_qp_iter > 0 ? std::to_string(o.feedback_qp_iter).c_str() : "none",
      o.presolve ? "on" : "off", CONTOUR_FLAGS, isa());
  std::printf("stage linearisations: %s\n",
              loop.generated_stage()      ? "generated code (ocp/generated_stage.hpp)"
              : Loop::has_generated_stage ? "expression layer (these options are not the "
                                            "generated code's: stage_definition.hpp)"
                                          : "expression layer");
  if (o.observer)
    std::printf("momentum observer: gain %g 1/s, updated %s\n", o.observer_gain,
                o.observer_plant_rate ? "after every plant step" : "once per sample");
  if (o.hold > 0)
    std::printf("start phase: the initial pose held for %g s\n", o.hold);
  if (o.inner_loop)
    std::printf("torque-rate inner loop: the QP's feedback gain at every plant step%s\n",
                o.observer && o.observer_plant_rate ? ", with the estimate's change" : "");
  if (o.delay_steps > 0)
    std::printf("measurement delay: %d plant steps\n", o.delay_steps);
  const auto st0 = loop.start();
  {
    const auto& in = loop.controller().info();
    std::printf(
        "initial OCP: %s after %d SQP iterations (stationarity %.2g, primal %.2g, "
        "complementarity %.2g, last step %.2g)\n",
        arbor::nmpc::to_string(st0), loop.start_iterations(), double(in.stationarity),
        double(in.primal_residual), double(in.complementarity), double(in.step_norm));
  }

  std::vector<Record> log;
  log.reserve(std::size_t(o.max_samples));
  int failures = 0;
  while (!loop.done()) {
    Record r;
    loop.sample(r);
    if (!arbor::nmpc::succeeded(r.status) && r.status != arbor::nmpc::NmpcStatus::iteration_limit)
      ++failures;
    log.push_back(r);
    if (progress > 0 && (loop.samples() % progress == 0 || loop.done()))
      std::printf("  sample %5d  t %6.2f s  s %.4f  sd %.4f  |e_p| %.2f mm  step %6.0f us\n",
                  loop.samples(), r.t, r.x[14], r.x[15], 1e3 * r.e_p, r.prepare_us + r.feedback_us);
    if (!std::isfinite(r.x.sum())) {
      std::printf("plant state not finite: stop\n");
      break;
    }
  }

  // ---- summary ----------------------------------------------------------------------------------
  std::vector<double> prep, fb, step, sqp_it, qp_it, ep;
  // e_max, qd_ratio, q_ratio: over every 1 ms plant step, where the hardware checks the limits
  // (step_monitor.hpp); *_at_samples: at the 20 ms samples only
  double e_max = 0, e_sq = 0, eR_max = 0, qd_ratio = 0, q_ratio = 0;
  double e_at_samples = 0, qd_at_samples = 0;
  VecN<double, nq> tau_peak = VecN<double, nq>::Zero();
  int outside = 0;
  // the start phase (hold) separately: the goals count from the task's start
  double hold_e = 0, hold_qd = 0;
  int hold_n = 0;
  for (const Record& r : log) {
    if (!r.hold)
      continue;
    ++hold_n;
    hold_e = std::max(hold_e, r.peaks.e_p);
    hold_qd = std::max(hold_qd, r.peaks.qd.maxCoeff() / qd_max);
  }
  std::vector<Record> task;
  task.reserve(log.size());
  for (const Record& r : log)
    if (!r.hold)
      task.push_back(r);
  for (const Record& r : task) {
    prep.push_back(r.prepare_us);
    fb.push_back(r.feedback_us);
    step.push_back(r.prepare_us + r.feedback_us);
    sqp_it.push_back(r.sqp_iterations);
    qp_it.push_back(r.qp_iterations);
    e_max = std::max(e_max, r.peaks.e_p);
    e_at_samples = std::max(e_at_samples, r.e_p);
    eR_max = std::max(eR_max, r.e_R);
    e_sq += r.e_p * r.e_p;
    outside += r.peaks.e_p > rho ? 1 : 0;
    tau_peak = tau_peak.cwiseMax(r.tau_peak);
    qd_ratio = std::max(qd_ratio, r.peaks.qd.maxCoeff() / qd_max);
    for (int i = 0; i < nq; ++i) {
      qd_at_samples = std::max(qd_at_samples, std::fabs(r.x[nq + i]) / qd_max);
      if (std::isfinite(q_max[std::size_t(i)]))
        q_ratio = std::max(q_ratio, r.peaks.q[i] / q_max[std::size_t(i)]);
    }
  }
  double tau_ratio = 0;
  int tau_worst = 0;
  for (int i = 0; i < nq; ++i) {
    const double rr = tau_peak[i] / tau_max[std::size_t(i)];
    if (rr > tau_ratio) {
      tau_ratio = rr;
      tau_worst = i;
    }
  }
  const std::size_t n = task.size();
  const double rms = n ? std::sqrt(e_sq / double(n)) : 0.0;
  const double s_final = n ? task.back().x[14] : 0.0;
  std::printf("\nsummary (%s, %s, %s tunnel, %s; plant %s%s)\n", to_string(kForm), kTagName,
              kSoft ? "soft" : "hard", o.sqp ? "SQP mode" : "RTI", plant_name.c_str(),
              !o.mismatch       ? ""
              : o.known_payload ? ", +0.5 kg payload, known"
                                : ", +0.5 kg payload");
  std::printf("  %-34s %10s %10s %10s %10s\n", "", "median", "p95", "p99", "max");
  auto row = [](const char* name, const std::vector<double>& v, const char* fmt) {
    std::printf("  %-34s ", name);
    for (double q : {0.5, 0.95, 0.99, 1.0})
      std::printf(fmt, quantile(v, q));
    std::printf("\n");
  };
  row("SQP iterations per sample", sqp_it, "%10.0f ");
  row("QP iterations per sample", qp_it, "%10.0f ");
  if (!o.sqp) {
    row("preparation [us]", prep, "%10.1f ");
    row("feedback [us]", fb, "%10.1f ");
  }
  row(o.sqp ? "SQP solve per sample [us]" : "preparation + feedback [us]", step, "%10.1f ");
  if (hold_n > 0) {
    std::printf(
        "  %-34s %10d (%.2f s): tunnel max %.3f mm, max |qd| %.3f of the limit (1 ms steps)\n",
        "start phase (hold), samples", hold_n, hold_n * h, 1e3 * hold_e, hold_qd);
    if (o.observer && !log.empty()) {
      const Record& r = log[std::size_t(hold_n - 1)];
      std::printf("  %-34s   ", "observer estimate at the task start");
      for (int i = 0; i < nq; ++i)
        std::printf(" %.3f", r.d_hat[i]);
      std::printf(" N m\n");
    }
  }
  std::printf("  %-34s %10zu (%.2f s)\n", "samples (task)", n, n * h);
  std::printf(
      "  limits and tunnel over every 1 ms plant step (at the 20 ms samples in brackets):\n");
  std::printf("  %-34s %10.3f mm (rho = %.1f mm; %d samples with a step outside) [%.3f mm]\n",
              "tunnel error max", 1e3 * e_max, 1e3 * rho, outside, 1e3 * e_at_samples);
  std::printf("  %-34s %10.3f mm (at the samples)\n", "tunnel error RMS", 1e3 * rms);
  std::printf("  %-34s %10.4f rad\n", "rotation error max |e_R|", eR_max);
  std::printf("  %-34s %10.3f of the limit (joint %d: %.2f of %.0f N m)\n", "max |tau|", tau_ratio,
              tau_worst + 1, tau_peak[tau_worst], tau_max[std::size_t(tau_worst)]);
  std::printf("  %-34s %10.3f of the limit (%.4f rad/s) [%.3f]\n", "max |qd|", qd_ratio, qd_max,
              qd_at_samples);
  std::printf("  %-34s %10.3f of the limit\n", "max |q_i| / q_max (q2, q4, q6)", q_ratio);
  std::printf("  %-34s %10.4f (%s)\n", "final s", s_final,
              s_final > o.s_end ? "reached" : "NOT reached");
  std::printf("  %-34s %10d\n", "controller failures", failures);
  // after each plant event: the worst of the tunnel and qd until the next one, and how long the
  // tunnel error stayed above rho after it (to the end of the last sample with a step outside)
  {
    std::vector<std::pair<double, const char*>> events;
    if (payload_on > 0)
      events.push_back({payload_on, "payload attached"});
    if (payload_off >= 0)
      events.push_back({payload_off, "payload released"});
    if (push_at >= 0)
      events.push_back({push_at, "push"});
    std::sort(events.begin(), events.end());
    for (std::size_t e = 0; e < events.size(); ++e) {
      const double t0 = events[e].first;
      const double t1 = e + 1 < events.size() ? events[e + 1].first : 1e300;
      double worst = 0, qd_worst = 0, last_out = -1;
      for (const Record& r : log) {
        if (r.t <= t0 || r.t - h >= t1)
          continue;  // samples that end after the event and start before the next one
        worst = std::max(worst, r.peaks.e_p);
        qd_worst = std::max(qd_worst, r.peaks.qd.maxCoeff() / qd_max);
        if (r.peaks.e_p > rho)
          last_out = r.t;
      }
      char name[64], back[64] = "never outside rho";
      std::snprintf(name, sizeof name, "after the %s at %g s", events[e].second, t0);
      if (last_out >= 0)
        std::snprintf(back, sizeof back, "back inside rho after %.3f s", last_out - t0);
      std::printf("  %-34s tunnel max %.3f mm, max |qd| %.3f of the limit, %s\n", name, 1e3 * worst,
                  qd_worst, back);
    }
  }
  {
    int taken = 0, limited = 0, other = 0;
    for (const Record& r : task) {
      taken += r.status == arbor::nmpc::NmpcStatus::step_taken ? 1 : 0;
      limited += r.status == arbor::nmpc::NmpcStatus::step_limited ? 1 : 0;
    }
    other = int(n) - taken - limited;
    std::printf("  %-34s %10d step_taken, %d step_limited, %d other\n", "statuses", taken, limited,
                other);
  }
  if (csv != "-") {
    write_csv(csv.c_str(), log);
    std::printf("log: %s\n", csv.c_str());
  }
  const bool ok = s_final > o.s_end && failures == 0 && tau_ratio <= 1 + 1e-9;
  return ok ? 0 : 1;
}
