#!/usr/bin/env python3
"""Scenarios of the contour demo side by side, from their CSV logs (`contour --csv FILE`).

usage: plot_scenarios.py OUT.png LABEL=LOG.csv [LABEL=LOG.csv ...]
  (Debian: python3-matplotlib). Two panels over the time since the task's start (the start
  phase, `--hold`, is drawn at negative times, shaded): the tunnel error |e_p| against rho and
  rho + 1 mm, and the worst joint velocity ratio max_i |qd_i| / qd_max against 1 and 1.02.
  demo.sh-style example:
    contour --csv nominal.csv; contour --mismatch --csv payload.csv
    contour --mismatch --observer --csv payload_obs.csv
    plot_scenarios.py scenarios.png nominal=nominal.csv payload=payload.csv \\
        "payload, observer"=payload_obs.csv
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

RHO = 0.01
QD_MAX = 0.8727
NQ = 7


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no samples")
    t = [float(r["t"]) for r in rows]
    hold = [int(r.get("hold", "0") or 0) for r in rows]
    # the task starts at the end of the last start-phase sample
    t0 = max((ti for ti, hi in zip(t, hold) if hi), default=0.0)
    e = [1e3 * float(r["e_p"]) for r in rows]
    qd = [max(abs(float(r[f"qd{i}"])) for i in range(1, NQ + 1)) / QD_MAX for r in rows]
    return [ti - t0 for ti in t], e, qd, t0


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = sys.argv[1]
    fig, (ax_e, ax_v) = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    hold = 0.0
    for arg in sys.argv[2:]:
        label, _, path = arg.partition("=")
        if not path:
            sys.exit(f"{arg}: LABEL=LOG.csv")
        t, e, qd, t0 = load(path)
        hold = max(hold, t0)
        ax_e.plot(t, e, label=label, lw=1)
        ax_v.plot(t, qd, label=label, lw=1)
    for ax in (ax_e, ax_v):
        if hold > 0:
            ax.axvspan(-hold, 0, color="0.9", zorder=0)
        ax.grid(alpha=0.3)
    ax_e.axhline(1e3 * RHO, color="k", lw=0.8, ls="--", label="rho")
    ax_e.axhline(1e3 * RHO + 1, color="r", lw=0.8, ls=":", label="rho + 1 mm")
    ax_e.set_ylabel("tunnel error |e_p| [mm]")
    ax_e.set_ylim(0, None)
    ax_v.axhline(1.0, color="k", lw=0.8, ls="--", label="limit")
    ax_v.axhline(1.02, color="r", lw=0.8, ls=":", label="1.02")
    ax_v.set_ylabel("max_i |qd_i| / qd_max")
    ax_v.set_xlabel("time since the task's start [s] (shaded: start phase, pose held)")
    ax_e.legend(fontsize=8, ncol=2)
    ax_v.legend(fontsize=8, ncol=2)
    ax_e.set_title("Kinova Gen3 contour demo: scenarios (RTI, OCP-FD, MuJoCo plant)")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
