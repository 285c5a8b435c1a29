// Prints the paper's Table 1 next to arbor's operation counts, and the counts of Table 2
// (Kinova Gen3 Hessians), as Markdown. Part of bench/ad/report.sh.
#include <cstdio>
#include <iterator>

#include "generated_counts.hpp"
#include "op_counts.hpp"

namespace {
struct Paper {
  const char* name;
  int n;
  double fd, jfd_c, jfd_a, id, jid_c, jid_a;
};
// DESIGN.md, Table 1 of the paper (CasADi counts of atomic operations).
constexpr Paper kPaper[] = {
    {"Double pendulum", 2, 85, 292, 327, 65, 162, 241},
    {"KUKA iiwa7", 7, 2675, 33160, 11874, 1150, 9472, 7739},
    {"Kinova Gen3", 7, 3424, 40051, 14565, 1492, 11955, 9426},
    {"ABB Yumi", 14, 6208, 99890, 36401, 2416, 26264, 22064},
    {"Atlas", 30, 11564, 703094, 164975, 4627, 74628, 52604},
};
}  // namespace

int main() {
  using namespace arbor::bench_ad;
  // The benchmark robots in list order; the paper's rows above are in the same order.
  const OpCounts ours[] = {
#define ARBOR_ROBOT(name, Struct) op_counts_##name(),
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT
  };
  const GeneratedCounts gen[] = {
#define ARBOR_ROBOT(name, Struct) generated_counts_##name(),
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT
  };
  static_assert(std::size(ours) == std::size(kPaper), "one paper row per benchmark robot");
  bool gen_below = true;
  std::printf("| Robot | n | FD | J_FD^c | J_FD^a | ID | J_ID^c | J_ID^a |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  bool below[2] = {true, true}, goal[2] = {true, true};
  for (int r = 0; r < 5; ++r) {
    const Paper& p = kPaper[r];
    const OpCounts& c = ours[r];
    const Count o[6] = {c.fd, c.jfd_c, c.jfd_a, c.id, c.jid_c, c.jid_a};
    const double q[6] = {p.fd, p.jfd_c, p.jfd_a, p.id, p.jid_c, p.jid_a};
    std::printf("| %s, paper | %d |", p.name, p.n);
    for (double v : q)
      std::printf(" %.0f |", v);
    for (int kind = 0; kind < 2; ++kind) {
      std::printf("\n| %s, arbor %s | %d |", p.name, kind == 0 ? "live" : "executed", p.n);
      for (int k = 0; k < 6; ++k) {
        const double v = double(kind == 0 ? o[k].live : o[k].executed);
        std::printf(" %.0f (%.2fx) |", v, v / q[k]);
        below[kind] = below[kind] && v < q[k];
        if (k == 2 || k == 5)
          goal[kind] = goal[kind] && v <= 0.6 * q[k];
      }
    }
    // The generated code (gen/ad): executed = live; no J^a columns.
    const GeneratedCounts& g = gen[r];
    const double gv[4] = {double(g.fd), double(g.jfd), double(g.id), double(g.jid)};
    const double gq[4] = {p.fd, p.jfd_c, p.id, p.jid_c};
    std::printf(
        "\n| %s, arbor generated (executed) | %d | %.0f (%.2fx) | %.0f (%.2fx) | - | "
        "%.0f (%.2fx) | %.0f (%.2fx) | - |",
        p.name, p.n, gv[0], gv[0] / gq[0], gv[1], gv[1] / gq[1], gv[2], gv[2] / gq[2], gv[3],
        gv[3] / gq[3]);
    if (p.n >= 7)
      gen_below = gen_below && gv[1] < gq[1] && gv[3] < gq[3];
    std::printf("\n");
  }
  std::printf(
      "\nGenerated code (gen/ad), executed J_FD^c and J_ID^c below the paper's on the 7-DoF "
      "arms, YuMi and Atlas (issue 16's goal): %s.\n",
      gen_below ? "yes" : "NO");
  for (int kind = 0; kind < 2; ++kind)
    std::printf(
        "\n%s counts: every one below the paper's: %s; J_FD^a and J_ID^a at most 0.6x "
        "the paper's: %s.\n",
        kind == 0 ? "Live" : "Executed", below[kind] ? "yes" : "NO", goal[kind] ? "yes" : "NO");
  const OpCounts& k = ours[2];
  std::printf("\nKinova Gen3 Hessians of lambda^T f (Table 2), operations:\n\n");
  std::printf(
      "| | AD (H^c) live / executed | analytical then AD (H^a) live / executed | "
      "H^a / H^c (live) |\n|---|---|---|---|\n");
  auto row = [](const char* name, const Count& c, const Count& a) {
    std::printf("| %s | %llu / %llu | %llu / %llu | %.2f |\n", name, (unsigned long long)c.live,
                (unsigned long long)c.executed, (unsigned long long)a.live,
                (unsigned long long)a.executed, double(a.live) / double(c.live));
  };
  row("H_FD", k.hfd_c, k.hfd_a);
  row("H_ID", k.hid_c, k.hid_a);
  std::printf("\nGenerated code (gen/ad), executed = live: H_FD %ld, H_ID %ld.\n", gen[2].hfd,
              gen[2].hid);
  std::printf(
      "\nAnalytical second-order routines (H^s: rnea/aba_second_order_derivatives, the "
      "SecondOrder provider), live / executed: H_FD %llu / %llu, H_ID %llu / %llu (issue 17's "
      "bar, the paper's operation counts: FD 84888, ID 30770).\n",
      (unsigned long long)k.hfd_s.live, (unsigned long long)k.hfd_s.executed,
      (unsigned long long)k.hid_s.live, (unsigned long long)k.hid_s.executed);
  return 0;
}
