#!/usr/bin/env python3
"""Writes bench/ad/RESULTS.md and fig1.png from the op counts (Markdown printed by
arbor_ad_op_counts) and the timings (Google Benchmark JSON of arbor_bench_ad).

usage: report.py counts.md times.json out-dir
"""
import json
import os
import platform
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROBOTS = [("double_pendulum", "Double pendulum"), ("iiwa7", "KUKA iiwa7"),
          ("kinova_gen3", "Kinova Gen3"), ("yumi_no_grippers", "ABB Yumi"), ("atlas", "Atlas")]
# The paper's Table 2 (Kinova Gen3, microseconds).
PAPER_T2 = {"H_FD": (58.8, 84.3), "H_ID": (38.3, 56.8)}


def median_times(path):
    with open(path) as f:
        data = json.load(f)
    out = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        name = b["run_name"]
        unit = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}[b["time_unit"]]
        out[name] = b["cpu_time"] * unit  # microseconds
    return out, data.get("context", {})


def user_function_section(fn_md, fn_json):
    """Table 3 (ours): the contour example's tracking residual differentiated three ways
    (bench/ad/fn_counts.cpp): its operation table as printed, and median CPU times."""
    out = ["## Table 3 (ours): a user's OCP function, dense, structure-aware and generated\n",
           "The contour example's tracking residual (9 outputs of the end-effector pose and the "
           "path parameter) in a path stage's Jacobian (24 directions) and the Hessian of its sum: "
           "`fn_dense` runs the body at the full dual, `fn` at the directions its arguments depend "
           "on, `call<Generated>` runs the Jacobian arbor_add_function_ad generated "
           "(docs/ad_generated.md, \"Your own functions\"). Tick counts every executed operation, "
           "Counted folds, the tape gives the live ones.\n"]
    out.append(fn_md.strip() + "\n")
    with open(fn_json) as f:
        data = json.load(f)
    rows = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") == "median":
            rows[b["run_name"]] = b["cpu_time"] / (1000.0 if b["time_unit"] == "ns" else 1.0)
    out.append("| evaluation | dense (fn_dense) | structure-aware (fn) | generated |")
    out.append("|---|---:|---:|---:|")
    for what in ("track_jacobian", "track_hessian"):
        vals = [rows.get(f"{what}/{m}") for m in ("dense", "structure", "generated")]
        if None in vals:
            continue
        out.append(f"| {what} CPU time [us], median of 5 | "
                   + " | ".join(f"{v:.3g}" for v in vals) + " |")
    out.append("")
    return out


def main():
    counts_md, times_json, out_dir = sys.argv[1:4]
    fn_md, fn_json = (sys.argv[4:6] + [None, None])[:2]
    counts = open(counts_md).read()
    t, ctx = median_times(times_json)

    lines = []
    lines.append("# AD layer: the paper's Table 1, Fig. 1 and Table 2, reproduced\n")
    lines.append("Regenerate with `bash bench/ad/report.sh` (this file and `fig1.png`). Counts are "
                 "atomic operations of `arbor::ad::Counted` (folding rules in "
                 "`tests/support/op_count.hpp`): exact and repeatable. Times are medians of 5 "
                 "repetitions of Google Benchmark CPU time on a shared machine: compare ratios "
                 "within one run, not absolute values across machines.\n")
    lines.append("J^a: analytical derivative routines (`aba_derivatives`, `rnea_derivatives`). "
                 "J^c: `Dual<T, 3 nv>` through `aba` / `rnea` in one pass. Both return the value "
                 "too. Jacobians are with respect to all inputs (q, v, tau) or (q, v, a). "
                 "J^g (and H^g): the `Generated` provider, straight-line code that gen/ad "
                 "(arbor-adgen) generates at build time by symbolic differentiation of the same "
                 "`aba` / `rnea` templates (graph with folding and hash-consing, forward or reverse "
                 "mode per function, whichever executes fewer operations; Hessians by one reverse "
                 "sweep then forward or reverse): the paper's CasADi method. Its executed count "
                 "is its live count.\n")
    lines.append("## Table 1: atomic operations (paper vs arbor)\n")
    lines.append(counts.split("\nKinova Gen3 Hessians")[0].strip() + "\n")

    lines.append("## Fig. 1: evaluation time of J^a, J^c and J^g (us, median)\n")
    lines.append("| Robot | J_FD^a | J_FD^c | J_FD^c / J_FD^a | J_FD^g | J_FD^g / J_FD^a | J_ID^a | "
                 "J_ID^c | J_ID^c / J_ID^a | J_ID^g | J_ID^g / J_ID^a |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|")
    within = True
    for key, label in ROBOTS:
        fa, fc, fg = t.get(f"J_FD_a/{key}"), t.get(f"J_FD_c/{key}"), t.get(f"J_FD_g/{key}")
        ia, ic, ig = t.get(f"J_ID_a/{key}"), t.get(f"J_ID_c/{key}"), t.get(f"J_ID_g/{key}")
        if None in (fa, fc, ia, ic):
            continue
        g = lambda v, a: ("-", "-") if v is None else (f"{v:.3g}", f"{v / a:.2f}")
        (fgs, fgr), (igs, igr) = g(fg, fa), g(ig, ia)
        within = within and fg is not None and ig is not None and fg <= 2 * fa and ig <= 2 * ia
        lines.append(f"| {label} | {fa:.3g} | {fc:.3g} | {fc / fa:.2f} | {fgs} | {fgr} | "
                     f"{ia:.3g} | {ic:.3g} | {ic / ia:.2f} | {igs} | {igr} |")
    lines.append("")
    lines.append(f"Issue 16's goal, J^g within 2x of J^a for FD and ID on every robot: "
                 f"{'yes' if within else 'NO'}.\n")
    lines.append("![Fig. 1](fig1.png)\n")

    lines.append("## Table 2: Hessians of lambda^T FD and lambda^T ID, Kinova Gen3\n")
    lines.append("H^c: nested `Dual<Dual<double, 21>, 7>` through `aba` / `rnea` (three passes "
                 "of 7 outer directions). H^a: `Dual<double, 21>` through `aba_derivatives` / "
                 "`rnea_derivatives`, contracted with lambda.\n")
    lines.append("H^s: the analytical second-order routines (`rnea_second_order_derivatives`, "
                 "`aba_second_order_derivatives`: the `SecondOrder` provider), no AD.\n")
    lines.append("| | AD (H^c) us | analytical then AD (H^a) us | H^a / H^c | generated AD (H^g) "
                 "us | analytical second order (H^s) us | paper AD us | "
                 "paper analytical then AD us | H^g <= paper AD | H^s <= paper AD / 2 |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|")
    for q in ("H_FD", "H_ID"):
        c, a = t.get(f"{q}_c/kinova_gen3"), t.get(f"{q}_a/kinova_gen3")
        gg, ss = t.get(f"{q}_g/kinova_gen3"), t.get(f"{q}_s/kinova_gen3")
        if None in (c, a):
            continue
        pc, pa = PAPER_T2[q]
        gs = "-" if gg is None else f"{gg:.4g}"
        ok = "-" if gg is None else ("yes" if gg <= pc else "NO")
        s_s = "-" if ss is None else f"{ss:.4g}"
        s_ok = "-" if ss is None else ("yes" if ss <= pc / 2 else "NO")
        lines.append(f"| {q} | {c:.4g} | {a:.4g} | {a / c:.2f} | {gs} | {s_s} | {pc} | {pa} | "
                     f"{ok} | {s_ok} |")
    lines.append("")
    lines.append("Operation counts of the same Hessians:\n")
    lines.append(counts.split("Hessians of lambda^T f (Table 2), operations:")[1].strip() + "\n")
    if fn_md and fn_json:
        lines.extend(user_function_section(open(fn_md).read(), fn_json))
    cpu = ctx.get("host_name", platform.node())
    lines.append(f"Machine: {ctx.get('num_cpus', '?')} CPUs at {ctx.get('mhz_per_cpu', '?')} MHz "
                 f"({cpu}), build type Release, -O3 -march=native; date {ctx.get('date', '?')}.\n")
    # The new tables become the newest dated section; the Current figures table and the older
    # record stay (scripts/results_file.py).
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                    "scripts"))
    import results_file
    out = os.path.join(out_dir, "RESULTS.md")
    old = open(out).read() if os.path.exists(out) else ""
    text, rows = results_file.merge(old, "\n".join(lines), "bash bench/ad/report.sh",
                                    ctx.get("date", "?")[:10], results_file.git_commit(out))
    with open(out, "w") as f:
        f.write(text)
    for r in rows:
        print(f"report.py: re-read this Current figure against the new record: {r}")

    # Fig. 1: grouped bars per robot, log scale.
    labels = [label for key, label in ROBOTS if f"J_FD_a/{key}" in t]
    keys = [key for key, label in ROBOTS if f"J_FD_a/{key}" in t]
    series = [("J_FD_a", "FD, analytical (J^a)"), ("J_FD_c", "FD, AD (J^c)"),
              ("J_FD_g", "FD, generated AD (J^g)"), ("J_ID_a", "ID, analytical (J^a)"),
              ("J_ID_c", "ID, AD (J^c)"), ("J_ID_g", "ID, generated AD (J^g)")]
    series = [(q, name) for q, name in series if all(f"{q}/{k}" in t for k in keys)]
    fig, ax = plt.subplots(figsize=(9, 4.5))
    width = 0.8 / len(series)
    for s, (q, name) in enumerate(series):
        xs = [i + (s - (len(series) - 1) / 2) * width for i in range(len(keys))]
        ax.bar(xs, [t[f"{q}/{k}"] for k in keys], width, label=name)
    ax.set_yscale("log")
    ax.set_xticks(range(len(keys)))
    ax.set_xticklabels(labels)
    ax.set_ylabel("evaluation time [us] (log scale)")
    ax.set_title("Jacobians of forward (FD) and inverse (ID) dynamics: analytical vs AD")
    ax.legend()
    ax.grid(axis="y", which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "fig1.png"), dpi=120)


if __name__ == "__main__":
    main()
