#!/usr/bin/env python3
"""Plots of a contour-following run from its CSV log (examples/contour, `contour --csv FILE`).

usage: plot.py LOG.csv [OUT_DIR]   (Debian: python3-matplotlib; writes PNGs into OUT_DIR,
                                    default: the log's folder)
  contour_path.png     the end effector's 3-D path against the reference (and the tunnel radius)
  contour_error.png    tracking error |e_p| with the tunnel rho, rotation error |e_R|
  contour_progress.png s and sd against sd_ref(s)
  contour_joints.png   joint torques and velocities against their limits
  contour_timing.png   controller time per sample (preparation, feedback / SQP solve)
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

RHO = 0.01
TAU_MAX = [39, 39, 39, 39, 9, 9, 9]
QD_MAX = 0.8727


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no samples")
    cols = {}
    for key in rows[0]:
        if key in ("status", "qp_status"):
            cols[key] = [r[key] for r in rows]
        else:
            cols[key] = [float(r[key]) for r in rows]
    return cols


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    log = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.dirname(os.path.abspath(log))
    os.makedirs(out, exist_ok=True)
    d = load(log)
    t = d["t"]
    written = []

    def save(fig, name):
        path = os.path.join(out, name)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

    # 3-D path
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    ax.plot(d["px_ref"], d["py_ref"], d["pz_ref"], "k--", lw=1, label="reference p_ref(s)")
    ax.plot(d["px"], d["py"], d["pz"], "C0", lw=1.5, label="end effector")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title("Kinova Gen3 contour following (tunnel rho = %.0f mm)" % (1e3 * RHO))
    ax.legend()
    save(fig, "contour_path.png")

    # tracking error
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    a1.plot(t, [1e3 * e for e in d["e_p"]], "C0", label="|e_p|")
    a1.axhline(1e3 * RHO, color="r", ls="--", label="tunnel rho")
    a1.set_ylabel("position error [mm]")
    a1.legend(loc="lower right")
    a2.plot(t, d["e_R"], "C1", label="|e_R|")
    a2.set_ylabel("rotation error")
    a2.set_xlabel("t [s]")
    a2.legend(loc="lower right")
    save(fig, "contour_error.png")

    # progress
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    a1.plot(t, d["s"], "C0", label="s")
    a1.axhline(1.0, color="k", lw=0.5)
    a1.set_ylabel("s")
    a1.legend()
    a2.plot(t, d["sd"], "C0", label="sd")
    a2.plot(t, d["sd_ref"], "k--", label="sd_ref(s)")
    a2.set_ylabel("sd [1/s]")
    a2.set_xlabel("t [s]")
    a2.legend()
    save(fig, "contour_progress.png")

    # joints
    fig, axes = plt.subplots(7, 2, figsize=(10, 12), sharex=True)
    for i in range(7):
        at, av = axes[i]
        at.plot(t, d["tau%d" % (i + 1)], "C0", lw=1)
        for sgn in (1, -1):
            at.axhline(sgn * TAU_MAX[i], color="r", ls="--", lw=0.8)
        at.set_ylabel("tau%d [N m]" % (i + 1))
        av.plot(t, d["qd%d" % (i + 1)], "C2", lw=1)
        for sgn in (1, -1):
            av.axhline(sgn * QD_MAX, color="r", ls="--", lw=0.8)
        av.set_ylabel("qd%d [rad/s]" % (i + 1))
    axes[-1][0].set_xlabel("t [s]")
    axes[-1][1].set_xlabel("t [s]")
    axes[0][0].set_title("joint torques (limits dashed)")
    axes[0][1].set_title("joint velocities (limits dashed)")
    save(fig, "contour_joints.png")

    # timing
    fig, ax = plt.subplots(figsize=(8, 4))
    if any(v > 0 for v in d["prepare_us"]):
        ax.plot(t, [1e-3 * v for v in d["prepare_us"]], "C0.", ms=2, label="preparation")
        ax.plot(t, [1e-3 * v for v in d["feedback_us"]], "C1.", ms=2, label="feedback")
    else:
        ax.plot(t, [1e-3 * v for v in d["feedback_us"]], "C1.", ms=2, label="SQP solve")
    ax.set_ylabel("time per sample [ms]")
    ax.set_xlabel("t [s]")
    ax.set_yscale("log")
    ax.legend()
    save(fig, "contour_timing.png")

    for p in written:
        print("plot:", p)


if __name__ == "__main__":
    main()
