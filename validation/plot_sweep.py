#!/usr/bin/env python3
"""Draws the Pareto plot of a `cairn sweep`.

usage: plot_sweep.py DIR

Reads DIR/sweep.json (the manifest: scene, setting columns, Pareto axis)
and DIR/sweep.csv, and writes DIR/pareto.png: wall time per step against
the Pareto axis's error, both on log scales. Each cairn solver variant
(every setting but the iteration count: method x substeps, and erp or dt
when they vary) is one curve through its iteration counts, labelled at
its ends; Bullet's jobs are dashed grey curves on the same axes; the
Pareto-optimal rows are ringed in red and joined by the front.

Needs matplotlib (Debian: python3-matplotlib; scripts/setup installs it).
Run it with /usr/bin/python3: a pyenv python3 on PATH may lack matplotlib.
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display: files only
import matplotlib.pyplot as plt  # noqa: E402

AXIS_LABELS = {
    "penetration_m": "deepest penetration over the run (m)",
    "joint_error_m": "largest joint error over the run (m)",
    "joint_angle_error_rad": "largest joint angle error over the run (rad)",
    "lcp_residual": "largest LCP residual of a step (natural map)",
    "energy_drift_j": "largest energy change |E - E0| (J)",
    "exact_lcp_distance": "distance from the exact LCP impulses (relative, mean of sampled steps)",
    "exact_velocity_distance": "distance from the exact velocity change (relative, mean of sampled steps)",
    "bullet_position_diff_m": "largest position difference from Bullet (m)",
    "drift_m": "largest body displacement at the end (m)",
    "analytic_error": "error against the closed form",
}


def number(cell):
    try:
        return float(cell)
    except ValueError:
        return math.nan


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    root = argv[1]
    with open(os.path.join(root, "sweep.json")) as f:
        manifest = json.load(f)
    with open(os.path.join(root, "sweep.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    axis = manifest["pareto_axis"]
    varied = {v["key"] for v in manifest["vary"]}
    # A curve per variant: every setting but iterations; the label names
    # those that vary (and always the method and substeps).
    label_keys = [c for c in manifest["columns"]
                  if c != "iterations" and (c in varied or c in ("method", "substeps"))]

    curves = {}
    for r in rows:
        x, y = number(r["ms_per_step"]), number(r[axis])
        if not (x > 0 and y > 0) or r["status"] != "ok":
            continue  # log axes: a zero or missing figure cannot be drawn
        key = tuple(r[c] for c in manifest["columns"] if c != "iterations")
        curves.setdefault(key, {"label": r, "points": []})["points"].append(
            (int(r["iterations"]), x, y, r["pareto"] == "1"))

    fig, ax = plt.subplots(figsize=(8.5, 5.5), dpi=100)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = {"pgs": "o", "direct": "s", "lcp": "^", "bullet": "x"}
    front = []
    cairn_index = 0
    for key in sorted(curves, key=lambda k: (k[0] == "bullet", k)):
        c = curves[key]
        first = c["label"]
        pts = sorted(c["points"])
        method = first["method"]
        parts = []
        for k in label_keys:
            if k == "method":
                parts.append("Bullet" if method == "bullet" else method)
            elif k == "substeps":
                parts.append(f"{first[k]} substep" + ("" if first[k] == "1" else "s"))
            elif first[k] != "-":  # "-": a setting Bullet does not see
                parts.append(f"{k} {first[k]}")
        style = {"marker": markers.get(method, "o"), "markersize": 5, "linewidth": 1.3}
        if method == "bullet":
            style.update(color="0.35", linestyle="--")
        else:
            style.update(color=colours[cairn_index % len(colours)])
            cairn_index += 1
        xs = [p[1] for p in pts]
        ys = [p[2] for p in pts]
        ax.plot(xs, ys, label=", ".join(parts), **style)
        if len(pts) > 1:  # iteration counts at the ends of each curve
            for it, x, y, _ in (pts[0], pts[-1]):
                ax.annotate(f"{it}", (x, y), textcoords="offset points", xytext=(4, 3), fontsize=7,
                            color=style["color"])
        front += [(p[1], p[2]) for p in pts if p[3]]
    if front:
        front.sort()
        ax.plot([p[0] for p in front], [p[1] for p in front], linestyle=":", color="tab:red", linewidth=1,
                drawstyle="steps-post")
        ax.scatter([p[0] for p in front], [p[1] for p in front], s=110, facecolors="none", edgecolors="tab:red",
                   linewidths=1.5, label="Pareto-optimal", zorder=5)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per step (ms)")
    ax.set_ylabel(AXIS_LABELS.get(axis, axis))
    dt = manifest.get("dt", 0)
    ax.set_title(f"{manifest['scene']}: time per step against {axis}\n"
                 f"{manifest['steps']} steps of {dt:.4g} s; numbers at curve ends are iterations")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(root, "pareto.png"))
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
