// Why the contour closed loop's QP takes its iterations (issues 14/15): the example's real-time
// iteration loop (OCP-FD, or OCP-ID in arbor_bench_rti_qp_diag_id; analytical RBD derivatives,
// hard tunnel, double) until s > 0.99, and per sample the QP's iterations, working-set changes and
// the difference between the working set the QP starts from (the signs of the multipliers it is
// given, as ActiveSetCore::begin() builds it) and the one it ends with, by kind of constraint
// (state bounds, input bounds, tunnel rows). Each sample's QP is also replayed, outside the loop,
// from other warm starts: the previous solution's multipliers shifted one stage (Nmpc's former
// shift()), unshifted (its default now), zero, and the better of the first two by a KKT residual.
// With --per-sample: one line per sample, the replay's sequence of working-set changes
// ("t7.0U": stage 7's row 0 (the tunnel) added on its upper side; "-": dropped; x/u: bounds of
// x_k/u_k) and the stages where the tunnel is active at the start and at the end.
// Instrumentation only: the controller runs unchanged (a logging copy of the default backend
// records the changes of the replays).
//
//   arbor_bench_rti_qp_diag[_id] [samples] [--shift] [--per-sample]
//     --shift: the loop shifts its multipliers (NmpcSettings::shift_multipliers)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "closed_loop.hpp"

namespace {

using namespace contour;
#ifndef DIAG_ID
#define DIAG_ID 0
#endif
using Loop =
    ContourLoop<DIAG_ID ? Formulation::id : Formulation::fd, arbor::ad::Analytical, false, double>;
using Ctrl = Loop::Controller;
using Qp = Ctrl::Qp;
using Solver = Ctrl::QpSolver;
constexpr int N = Qp::horizon, NX = Qp::nx, NU = Qp::nu, NG = Qp::ng;
constexpr double inf = std::numeric_limits<double>::infinity();

/// -1 lower, +1 upper, 0 inactive, 2 equality (ActiveSetCore::working_set_from_multipliers).
int side(double lb, double ub, double m) {
  if (lb == ub)
    return 2;
  if (m > 0 && ub < inf)
    return 1;
  if (m < 0 && lb > -inf)
    return -1;
  return 0;
}

struct Kinds {
  int state = 0, input = 0, tunnel = 0;
  int total() const { return state + input + tunnel; }
};

/// The default backend, logging each working-set change (index and new state, read from the
/// working set at the next factorize()).
struct Change {
  int index;
  int state;  // ConstraintState as int
};
std::vector<Change> g_log;
int g_pending = -1;
using Base = arbor::qp::detail::DefaultOcpBackend<Qp>::type;
struct LoggingBackend : Base {
  void mark_changed(int i) {
    g_pending = i;
    Base::mark_changed(i);
  }
  int factorize(const arbor::qp::detail::ConstraintState* ws, double delta, double w,
                const Eigen::Matrix<double, Qp::na, 1>& wa) {
    if (g_pending >= 0)
      g_log.push_back({g_pending, int(ws[g_pending])});
    g_pending = -1;
    return Base::factorize(ws, delta, w, wa);
  }
};
using LoggingSolver = arbor::qp::OcpQpSolver<Qp, LoggingBackend>;

/// "x3.7+" : kind (x state, u input, t tunnel, d dynamics), stage, index in the stage, new state.
void describe(const Change& c, char* out) {
  // inactive 0 -> "-", lower -1 -> "L", upper 1 -> "U", equality 2 -> "E"
  const char* st = c.state == 0 ? "-" : c.state < 0 ? "L" : c.state == 1 ? "U" : "E";
  if (c.index < Qp::nv) {
    const int k = c.index / Qp::nw, i = c.index % Qp::nw;
    std::snprintf(out, 24, "%c%d.%d%s", i < NX ? 'x' : 'u', k, i < NX ? i : i - NX, st);
  } else {
    const int j = c.index - Qp::nv, k = j / (NX + NG), i = j % (NX + NG);
    std::snprintf(out, 24, "%c%d.%d%s", k == N ? 't' : (i < NX ? 'd' : 't'), k,
                  k == N ? i : (i < NX ? i : i - NX), st);
  }
}

double median(std::vector<double> v) {
  if (v.empty())
    return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int samples = 400;
  bool per_sample = false;
  bool shift = false;  // the loop shifts its multipliers (NmpcSettings::shift_multipliers)
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--per-sample") == 0)
      per_sample = true;
    else if (std::strcmp(argv[i], "--shift") == 0)
      shift = true;
    else
      samples = std::atoi(argv[i]);
  }
  Options o;
  o.max_samples = samples;
  o.shift_multipliers = shift;
  auto loop = std::make_unique<Loop>(o);
  if (loop->start() != arbor::nmpc::NmpcStatus::converged) {
    std::printf("start failed\n");
    return 1;
  }
  Ctrl& c = loop->controller();
  std::vector<double> its_shifted, its_unshifted, its_cold, its_by_stat, its_by_comp, its_by_max,
      its_best;
  std::vector<double> its, changes, enter, leave, active, refine;
  Kinds sum_enter, sum_leave;
  int n = 0;
  if (per_sample)
    std::printf(
        "sample its changes active | entered state/input/tunnel | left state/input/tunnel"
        " | stage of changes\n");
  while (!loop->done()) {
    // the QP's candidate starts: the previous solution's multipliers, shifted or not
    Eigen::Matrix<double, Qp::nv, 1> lx = c.qp_solver().lam_x();
    Eigen::Matrix<double, Qp::na, 1> la = c.qp_solver().lam_a();
    const Eigen::Matrix<double, Qp::nv, 1> lx_unshifted = lx;
    const Eigen::Matrix<double, Qp::na, 1> la_unshifted = la;
    Solver::shift_variables(lx);
    Solver::shift_rows(la);
    Record rec;
    loop->sample(rec);

    {  // replays of the sample's QP from other warm starts (the loop goes on with its own)
      static LoggingSolver rs;  // (static: large)
      auto replay = [&](const auto& lxs, const auto& las) {
        if (rs.setup(c.qp(), c.settings().qp) != arbor::qp::QpStatus::accepted)
          return -1;
        rs.edit_warm_start([&](auto& x, auto& lx_, auto& la_) {
          x.setZero();
          lx_ = lxs;
          la_ = las;
        });
        return rs.solve() == arbor::qp::QpStatus::solved ? rs.info().iterations : -1000;
      };
      its_shifted.push_back(replay(lx, la));
      its_unshifted.push_back(replay(lx_unshifted, la_unshifted));
      const auto rs_ = arbor::nmpc::kkt_residuals(c.qp(), lx, la);
      const auto ru_ = arbor::nmpc::kkt_residuals(c.qp(), lx_unshifted, la_unshifted);
      const double a = its_shifted.back(), b = its_unshifted.back();
      its_by_stat.push_back(ru_.stationarity < rs_.stationarity ? b : a);
      its_by_comp.push_back(ru_.complementarity < rs_.complementarity ? b : a);
      its_by_max.push_back(std::fmax(ru_.stationarity, ru_.complementarity) <
                                   std::fmax(rs_.stationarity, rs_.complementarity)
                               ? b
                               : a);
      its_best.push_back(std::min(a < 0 ? 1e9 : a, b < 0 ? 1e9 : b));
      its_cold.push_back(replay(Eigen::Matrix<double, Qp::nv, 1>::Zero().eval(),
                                Eigen::Matrix<double, Qp::na, 1>::Zero().eval()));
    }
    if (!shift) {  // the loop's own start, for the start/end comparison below
      lx = lx_unshifted;
      la = la_unshifted;
    }
    const auto& q = c.qp();
    const auto& s = c.qp_solver();
    const auto& inf_ = s.info();
    Kinds in, out;
    int act = 0;
    char stages[N + 2] = {};
    for (int k = 0; k <= N; ++k)
      stages[k] = '.';
    auto compare = [&](int stage, int kind, double lb, double ub, double m0, double m1) {
      const int a = side(lb, ub, m0), b = side(lb, ub, m1);
      if (b != 0 && b != 2)
        ++act;
      if (a == b || a == 2)
        return;
      if (a != 0)
        (kind == 0 ? out.state : kind == 1 ? out.input : out.tunnel)++;
      if (b != 0)
        (kind == 0 ? in.state : kind == 1 ? in.input : in.tunnel)++;
      stages[stage] = stages[stage] == '.' ? '1' : (stages[stage] < '9' ? stages[stage] + 1 : '9');
    };
    for (int k = 0; k < N; ++k) {
      const auto& st = q.stage[std::size_t(k)];
      for (int i = 0; i < NX; ++i)
        compare(k, 0, st.lbx[i], st.ubx[i], lx[Qp::state_offset(k) + i],
                s.lam_x()[Qp::state_offset(k) + i]);
      for (int i = 0; i < NU; ++i)
        compare(k, 1, st.lbu[i], st.ubu[i], lx[Qp::input_offset(k) + i],
                s.lam_x()[Qp::input_offset(k) + i]);
      for (int i = 0; i < NG; ++i)
        compare(k, 2, st.lg[i], st.ug[i], la[Qp::constraint_offset(k) + i],
                s.lam_a()[Qp::constraint_offset(k) + i]);
    }
    for (int i = 0; i < NX; ++i)
      compare(N, 0, q.terminal.lbx[i], q.terminal.ubx[i], lx[Qp::state_offset(N) + i],
              s.lam_x()[Qp::state_offset(N) + i]);
    for (int i = 0; i < Qp::ngn; ++i)
      compare(N, 2, q.terminal.lg[i], q.terminal.ug[i], la[Qp::constraint_offset(N) + i],
              s.lam_a()[Qp::constraint_offset(N) + i]);
    its.push_back(inf_.iterations);
    changes.push_back(inf_.active_set_changes);
    enter.push_back(in.total());
    leave.push_back(out.total());
    active.push_back(act);
    refine.push_back(inf_.iterations - inf_.active_set_changes);
    sum_enter.state += in.state;
    sum_enter.input += in.input;
    sum_enter.tunnel += in.tunnel;
    sum_leave.state += out.state;
    sum_leave.input += out.input;
    sum_leave.tunnel += out.tunnel;
    if (per_sample)
      std::printf("%4d %3d %3d %3d | %2d %2d %2d | %2d %2d %2d | %s  e=%.2e r=%.1e %s\n", n,
                  inf_.iterations, inf_.active_set_changes, act, in.state, in.input, in.tunnel,
                  out.state, out.input, out.tunnel, stages, rec.e_p, inf_.primal_residual,
                  arbor::qp::to_string(rec.qp_status));
    if (per_sample) {           // replay: the same QP from the same start, with the change log
      static LoggingSolver rs;  // (static: large)
      g_log.clear();
      if (rs.setup(q, c.settings().qp) == arbor::qp::QpStatus::accepted) {
        rs.edit_warm_start([&](auto& x, auto& lx_, auto& la_) {
          x.setZero();
          lx_ = lx;
          la_ = la;
        });
        const auto st = rs.solve();
        std::printf("     replay %s its %d:", arbor::qp::to_string(st), rs.info().iterations);
        for (const auto& ch : g_log) {
          char b[24];
          describe(ch, b);
          std::printf(" %s", b);
        }
        std::printf("\n");
      }
      // tunnel rows active at the start (shifted) and at the end, per stage; state/input bounds
      char a0[N + 2] = {}, a1[N + 2] = {};
      for (int k = 0; k < N; ++k) {
        const int o = Qp::constraint_offset(k);
        const auto& st = q.stage[std::size_t(k)];
        a0[k] = side(st.lg[0], st.ug[0], la[o]) != 0 ? 'T' : '.';
        a1[k] = side(st.lg[0], st.ug[0], s.lam_a()[o]) != 0 ? 'T' : '.';
        for (int i = 0; i < Qp::nw; ++i) {
          const int v = Qp::state_offset(k) + i;
          const double lb = i < NX ? st.lbx[i] : st.lbu[i - NX];
          const double ub = i < NX ? st.ubx[i] : st.ubu[i - NX];
          if (side(lb, ub, lx[v]) == 1 || side(lb, ub, lx[v]) == -1)
            a0[k] = a0[k] == 'T' ? '#' : 'b';
          if (side(lb, ub, s.lam_x()[v]) == 1 || side(lb, ub, s.lam_x()[v]) == -1)
            a1[k] = a1[k] == 'T' ? '#' : 'b';
        }
      }
      a0[N] = a1[N] = '|';
      std::printf("     start %s end %s\n", a0, a1);
    }
    ++n;
  }
  double tot_it = 0, tot_ch = 0;
  for (std::size_t i = 0; i < its.size(); ++i) {
    tot_it += its[i];
    tot_ch += changes[i];
  }
  std::printf(
      "samples %d: QP iterations median %.0f max %.0f total %.0f; working-set changes "
      "median %.0f total %.0f; iterations without a change median %.0f\n",
      n, median(its), *std::max_element(its.begin(), its.end()), tot_it, median(changes), tot_ch,
      median(refine));
  std::printf(
      "net start->end difference per sample: entered median %.0f, left median %.0f; "
      "active at the end median %.0f\n",
      median(enter), median(leave), median(active));
  std::printf("entered in total: state %d input %d tunnel %d; left: state %d input %d tunnel %d\n",
              sum_enter.state, sum_enter.input, sum_enter.tunnel, sum_leave.state, sum_leave.input,
              sum_leave.tunnel);
  auto total = [](const std::vector<double>& v) {
    double t = 0;
    for (double x : v)
      t += x;
    return t;
  };
  auto report = [&](const char* name, const std::vector<double>& v) {
    std::printf("replay %-34s median %3.0f max %3.0f total %6.0f (negative: not solved)\n", name,
                median(v), *std::max_element(v.begin(), v.end()), total(v));
  };
  int worse = 0;
  for (std::size_t i = 0; i < its_shifted.size(); ++i) {
    if (its_unshifted[i] > its_shifted[i]) {
      ++worse;
      if (per_sample)
        std::printf("sample %zu: shifted %.0f, unshifted %.0f\n", i, its_shifted[i],
                    its_unshifted[i]);
    }
  }
  std::printf("samples where the unshifted start takes more iterations: %d\n", worse);
  report("shifted multipliers (the loop's)", its_shifted);
  report("unshifted (previous solution's)", its_unshifted);
  report("zero multipliers", its_cold);
  report("the smaller stationarity of the two", its_by_stat);
  report("the smaller complementarity", its_by_comp);
  report("the smaller max(stat, compl)", its_by_max);
  report("the better of the two (oracle)", its_best);
  return 0;
}
