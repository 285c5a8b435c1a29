// The paper's Fig. 2 reproduced (driver of bench/nmpc/fig2.sh): solve time per sample of the
// Kinova Gen3 contour NMPC (examples/contour; OCP-FD and OCP-ID, analytical vs AD RBD
// derivatives, AD both as dual numbers and as code-generated straight-line code) along its closed
// loop, in the paper's mode (full SQP, at most 5 iterations per sample, the tolerances of
// CONTOUR.md) and in real-time iteration. Each variant runs the closed loop itself from the same
// start for the same number of samples (fig2_variant.cpp). Writes a per-sample CSV (for fig2.py)
// and the Markdown tables of FIG2.md: time per sample (median/p95/max), AD/analytical ratios (both
// AD providers) next to the paper's, time split by phase, failures.
//
//   arbor_bench_fig2 [--samples N] [--sqp-iter K] [--csv FILE] [--md FILE] [--check]
//                    [--only VARIANT:MODE] [--qp-tol-primal|--qp-tol-dual|--qp-tol-comp|
//                    --qp-reg-dual X] [--qp-max-iter N]      (diagnostics of the QP settings)
//   arbor_bench_fig2 --cg <fd|id>_<analytical|autodiff|generated> <sqp|sqp_c|rti>
//                    FROM COUNT          (under callgrind: see fig2.sh)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "arbor/nmpc/status.hpp"
#include "arbor/qp/status.hpp"
#include "fig2.hpp"

namespace fig2 {
const char* status_name(int s) {
  return arbor::nmpc::to_string(arbor::nmpc::NmpcStatus(s));
}
const char* qp_status_name(int s) {
  return arbor::qp::to_string(arbor::qp::QpStatus(s));
}
}  // namespace fig2

namespace {

using fig2::Run;
using fig2::RunOptions;
using fig2::Sample;
using Runner = void (*)(const RunOptions&, Run&);

struct Variant {
  const char* key;
  const char* formulation;  // OCP-FD, OCP-ID
  const char* provider;     // analytical, AD (dual numbers), generated AD
  Runner fn;
};
constexpr Variant kVariants[] = {
    {"fd_analytical", "OCP-FD", "analytical", fig2::run_fd_analytical},
    {"fd_autodiff", "OCP-FD", "AD", fig2::run_fd_autodiff},
    {"id_analytical", "OCP-ID", "analytical", fig2::run_id_analytical},
    {"id_autodiff", "OCP-ID", "AD", fig2::run_id_autodiff},
    {"fd_generated", "OCP-FD", "generated AD", fig2::run_fd_generated},
    {"id_generated", "OCP-ID", "generated AD", fig2::run_id_generated},
};

/// Quantile q of v (nearest rank).
double quantile(std::vector<double> v, double q) {
  if (v.empty())
    return 0;
  std::sort(v.begin(), v.end());
  const auto i = std::size_t(std::ceil(q * double(v.size()))) - (q > 0 ? 1 : 0);
  return v[std::min(i, v.size() - 1)];
}

template <class F>
std::vector<double> column(const Run& r, F f) {
  std::vector<double> v;
  for (const Sample& s : r.samples)
    v.push_back(double(f(s)));
  return v;
}

double mean(const std::vector<double>& v) {
  double m = 0;
  for (double x : v)
    m += x;
  return v.empty() ? 0 : m / double(v.size());
}

/// The modes: the paper's (as the example runs it, and with the QP's complementarity tolerance
/// as loose as its dual one), and real-time iteration.
struct Mode {
  const char* key;
  const char* label;
  bool sqp;
  double qp_tol_comp;  // 0: the example's
};
constexpr Mode kModes[] = {
    {"sqp", "SQP", true, 0.0},
    {"sqp_c", "SQP, QP tol_comp 1e-1", true, 1e-1},
    {"rti", "RTI", false, 0.0},
};
constexpr int kNumModes = int(std::size(kModes));

struct Result {
  const Variant* v;
  int mode;  // index into kModes
  Run run;
};

void write_csv(const char* path, const std::vector<Result>& results) {
  FILE* f = std::fopen(path, "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path);
    std::exit(1);
  }
  std::fprintf(f,
               "variant,formulation,provider,mode,sample,total_us,lin_us,rbd_us,qp_us,rest_us,"
               "linearizations,sqp_iterations,qp_iterations,status,qp_status,failed,e_p,s\n");
  for (const Result& r : results)
    for (std::size_t i = 0; i < r.run.samples.size(); ++i) {
      const Sample& s = r.run.samples[i];
      std::fprintf(f, "%s,%s,%s,%s,%zu,%.3f,%.3f,%.3f,%.3f,%.3f,%d,%d,%d,%s,%s,%d,%.6g,%.6g\n",
                   r.v->key, r.v->formulation, r.v->provider, kModes[r.mode].key, i, s.total_us,
                   s.lin_us, s.rbd_us, s.qp_us, s.rest_us, s.linearizations, s.sqp_iterations,
                   s.qp_iterations, fig2::status_name(s.status), fig2::qp_status_name(s.qp_status),
                   int(s.failed), s.e_p, s.s);
    }
  std::fclose(f);
}

const Result* find(const std::vector<Result>& rs, const char* formulation, const char* provider,
                   int mode) {
  for (const Result& r : rs)
    if (!std::strcmp(r.v->formulation, formulation) && !std::strcmp(r.v->provider, provider) &&
        r.mode == mode)
      return &r;
  return nullptr;
}

void write_md(FILE* f, const std::vector<Result>& results, const RunOptions& o) {
  std::fprintf(f, "## Time per sample (controller calls only) [us]\n\n");
  std::fprintf(f,
               "| mode | variant | samples | median | p95 | max | mean | SQP iterations per "
               "sample (median / max) | QP iterations per sample (median / p95 / max) |\n");
  std::fprintf(f, "|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (int m = 0; m < kNumModes; ++m)
    for (const Result& r : results) {
      if (r.mode != m)
        continue;
      const auto t = column(r.run, [](const Sample& s) { return s.total_us; });
      const auto it = column(r.run, [](const Sample& s) { return s.sqp_iterations; });
      const auto qi = column(r.run, [](const Sample& s) { return s.qp_iterations; });
      std::fprintf(
          f,
          "| %s | %s %s | %zu | %.0f | %.0f | %.0f | %.0f | %.0f / %.0f | %.0f / %.0f / %.0f |\n",
          kModes[m].label, r.v->formulation, r.v->provider, t.size(), quantile(t, 0.5),
          quantile(t, 0.95), quantile(t, 1.0), mean(t), quantile(it, 0.5), quantile(it, 1.0),
          quantile(qi, 0.5), quantile(qi, 0.95), quantile(qi, 1.0));
    }

  std::fprintf(f, "\n## AD / analytical, same run\n\n");
  std::fprintf(f,
               "Ratio of each AD variant's time per sample to the analytical one's (> 1: "
               "analytical faster), next to the paper's speed-ups (SQP mode, CasADi with "
               "code-generated AD). *AD*: dual numbers through the RBD templates; *generated "
               "AD*: gen/ad's code-generated straight-line Jacobians (the paper's method).\n\n");
  std::fprintf(
      f,
      "| mode | formulation | AD provider | median ratio | mean ratio | p95 ratio | paper | "
      "linearisation only (median per linearisation) |\n");
  std::fprintf(f, "|---|---|---|---:|---:|---:|---:|---:|\n");
  for (int m = 0; m < kNumModes; ++m)
    for (const char* form : {"OCP-FD", "OCP-ID"})
      for (const char* prov : {"AD", "generated AD"}) {
        const Result* a = find(results, form, "analytical", m);
        const Result* d = find(results, form, prov, m);
        if (!a || !d)
          continue;
        const auto ta = column(a->run, [](const Sample& s) { return s.total_us; });
        const auto td = column(d->run, [](const Sample& s) { return s.total_us; });
        auto per_lin = [](const Sample& s) {
          return s.linearizations > 0 ? s.lin_us / s.linearizations : 0.0;
        };
        const auto la = column(a->run, per_lin), ld = column(d->run, per_lin);
        std::fprintf(f, "| %s | %s | %s | %.2fx | %.2fx | %.2fx | %s | %.2fx |\n", kModes[m].label,
                     form, prov, quantile(td, 0.5) / quantile(ta, 0.5), mean(td) / mean(ta),
                     quantile(td, 0.95) / quantile(ta, 0.95),
                     std::strcmp(form, "OCP-FD") ? "1.09x" : "1.29x",
                     quantile(ld, 0.5) / quantile(la, 0.5));
      }

  std::fprintf(
      f, "\n## Time split per sample [us] (mean over the samples; share of the mean total)\n\n");
  std::fprintf(f,
               "| mode | variant | linearisations per sample | RBD derivatives | other derivatives "
               "(rest of linearisation) | QP | rest | total |\n");
  std::fprintf(f, "|---|---|---:|---:|---:|---:|---:|---:|\n");
  for (int m = 0; m < kNumModes; ++m)
    for (const Result& r : results) {
      if (r.mode != m)
        continue;
      const double tot = mean(column(r.run, [](const Sample& s) { return s.total_us; }));
      const double lin = mean(column(r.run, [](const Sample& s) { return s.lin_us; }));
      const double rbd = mean(column(r.run, [](const Sample& s) { return s.rbd_us; }));
      const double qp = mean(column(r.run, [](const Sample& s) { return s.qp_us; }));
      const double rest = mean(column(r.run, [](const Sample& s) { return s.rest_us; }));
      const double nl = mean(column(r.run, [](const Sample& s) { return s.linearizations; }));
      auto cell = [tot](double x) {
        static char buf[4][64];
        static int i = 0;
        i = (i + 1) % 4;
        std::snprintf(buf[i], sizeof buf[i], "%.0f (%.0f %%)", x, 100 * x / tot);
        return buf[i];
      };
      std::fprintf(f, "| %s | %s %s | %.2f | %s | %s | %s | %s | %.0f |\n", kModes[m].label,
                   r.v->formulation, r.v->provider, nl, cell(rbd), cell(lin - rbd), cell(qp),
                   cell(rest), tot);
    }

  std::fprintf(f, "\n## Failures and tracking\n\n");
  std::fprintf(f,
               "| mode | variant | failed samples (status) | SQP: converged / iteration limit | "
               "QP status of failed samples | max \\|e_p\\| [mm] | s at the end | warm start |\n");
  std::fprintf(f, "|---|---|---:|---:|---|---:|---:|---|\n");
  for (int m = 0; m < kNumModes; ++m)
    for (const Result& r : results) {
      if (r.mode != m)
        continue;
      int failed = 0, conv = 0, limit = 0;
      std::string qs;
      std::vector<std::pair<std::string, int>> qcount;
      double ep = 0;
      for (const Sample& s : r.run.samples) {
        ep = std::max(ep, s.e_p);
        conv += s.status == int(arbor::nmpc::NmpcStatus::converged);
        limit += s.status == int(arbor::nmpc::NmpcStatus::iteration_limit);
        if (!s.failed)
          continue;
        ++failed;
        const std::string name =
            std::string(fig2::status_name(s.status)) + ": " + fig2::qp_status_name(s.qp_status);
        auto it = std::find_if(qcount.begin(), qcount.end(),
                               [&](const auto& p) { return p.first == name; });
        if (it == qcount.end())
          qcount.emplace_back(name, 1);
        else
          ++it->second;
      }
      for (const auto& [name, n] : qcount)
        qs += (qs.empty() ? "" : ", ") + name + " " + std::to_string(n);
      std::fprintf(
          f, "| %s | %s %s | %d of %zu | %s | %s | %.3f | %.4f | %s, %d iterations |\n",
          kModes[m].label, r.v->formulation, r.v->provider, failed, r.run.samples.size(),
          kModes[m].sqp ? (std::to_string(conv) + " / " + std::to_string(limit)).c_str() : "-",
          qs.empty() ? "-" : qs.c_str(), 1e3 * ep,
          r.run.samples.empty() ? 0.0 : r.run.samples.back().s,
          fig2::status_name(r.run.start_status), r.run.start_iterations);
    }
  int calls_fd = 0, calls_id = 0;
  std::size_t bytes_fd = 0, bytes_id = 0;
  for (const Result& r : results) {
    const bool fd = !std::strcmp(r.v->formulation, "OCP-FD");
    (fd ? calls_fd : calls_id) =
        std::max(fd ? calls_fd : calls_id, r.run.rbd_calls_per_linearization);
    (fd ? bytes_fd : bytes_id) = r.run.controller_bytes;
  }
  std::fprintf(f,
               "\nRBD Jacobian calls per linearisation: OCP-FD %d, OCP-ID %d. sizeof controller: "
               "OCP-FD %zu, OCP-ID %zu bytes. Samples per run: %d; SQP iterations per sample at "
               "most %d.\n",
               calls_fd, calls_id, bytes_fd, bytes_id, o.samples, o.sqp_iter);
}

}  // namespace

int main(int argc, char** argv) {
  RunOptions o;
  const char* csv = nullptr;
  const char* md = nullptr;
  std::string only;  // e.g. "fd_analytical:sqp" (diagnostics): one variant and mode
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--samples") {
      o.samples = std::atoi(next());
    } else if (a == "--sqp-iter") {
      o.sqp_iter = std::atoi(next());
    } else if (a == "--csv") {
      csv = next();
    } else if (a == "--md") {
      md = next();
    } else if (a == "--qp-tol-primal") {
      o.qp_tol_primal = std::atof(next());
    } else if (a == "--qp-tol-dual") {
      o.qp_tol_dual = std::atof(next());
    } else if (a == "--qp-tol-comp") {
      o.qp_tol_comp = std::atof(next());
    } else if (a == "--qp-reg-dual") {
      o.qp_reg_dual = std::atof(next());
    } else if (a == "--qp-max-iter") {
      o.qp_max_iter = std::atoi(next());
    } else if (a == "--only") {
      only = next();
    } else if (a == "--check") {
      o.check = true;
    } else if (a == "--cg") {  // one variant and mode, callgrind collecting COUNT samples
      const std::string key = next(), mode = next();
      o.sqp = mode != "rti";
      if (mode == "sqp_c")
        o.qp_tol_comp = 1e-1;
      o.cg_from = std::atoi(next());
      o.cg_count = std::atoi(next());
      o.samples = o.cg_from + o.cg_count;
      for (const Variant& v : kVariants)
        if (key == v.key) {
          Run r;
          v.fn(o, r);
          std::printf("calls %ld\n", r.cg_controller_calls);
          int failed = 0;
          for (const Sample& s : r.samples)
            failed += s.failed;
          std::printf("failed %d\n", failed);
          return 0;
        }
      std::fprintf(stderr, "unknown variant %s\n", key.c_str());
      return 2;
    } else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }

  std::vector<Result> results;
  for (int m = 0; m < kNumModes; ++m)
    for (const Variant& v : kVariants) {
      if (!only.empty() && only != std::string(v.key) + ":" + kModes[m].key)
        continue;
      Result r{&v, m, {}};
      RunOptions ro = o;
      ro.sqp = kModes[m].sqp;
      if (kModes[m].qp_tol_comp > 0)
        ro.qp_tol_comp = kModes[m].qp_tol_comp;
      v.fn(ro, r.run);
      const auto t = column(r.run, [](const Sample& s) { return s.total_us; });
      int failed = 0;
      double du = 0;
      for (const Sample& s : r.run.samples) {
        failed += s.failed;
        du = std::max(du, s.check_du);
      }
      std::printf("%-4s %-18s %zu samples: median %8.0f us, p95 %8.0f us, max %8.0f us, %d failed",
                  kModes[m].key, r.run.name, t.size(), quantile(t, 0.5), quantile(t, 0.95),
                  quantile(t, 1.0), failed);
      if (o.check)
        std::printf(", max |u - u_example| %.3g", du);
      std::printf("\n");
      std::fflush(stdout);
      results.push_back(std::move(r));
    }
  if (csv)
    write_csv(csv, results);
  FILE* f = md ? std::fopen(md, "w") : stdout;
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", md);
    return 1;
  }
  write_md(f, results, o);
  if (md)
    std::fclose(f);
  return 0;
}
