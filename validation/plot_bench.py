#!/usr/bin/env python3
"""Draws the plots of a `cairn bench` run.

usage: plot_bench.py DIR

Reads DIR/bench.json (the manifest) and DIR/bench.csv (one row per scene
and engine configuration) and writes into DIR:
  bench_times.png     ms per step of each scene, cairn and both Bullet
                      configurations side by side (log scale), with the
                      ratio Bullet / cairn over each Bullet bar
  bench_accuracy.png  the accuracy figures beside them: rest displacement,
                      penetration, joint error, distance from the exact solve
  bench_stages.png    where cairn's step goes, stage by stage (share of the step)
and, for a scaling run (manifest "scaling": true), one plot per family,
scaling_FAMILY.png: ms per step against the number of bodies and against
cairn's contacts + rows per step, log-log, with a line of slope 1 through
cairn's smallest size (cost proportional to size).

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

ENGINES = ["cairn", "bullet_defaults", "bullet_matched"]
LABELS = {"cairn": "cairn", "bullet_defaults": "Bullet, its defaults", "bullet_matched": "Bullet, matched to cairn"}
COLORS = {"cairn": "tab:blue", "bullet_defaults": "tab:orange", "bullet_matched": "tab:green"}
ACCURACY = [
    ("rest_displacement_m", "rest displacement (m)"),
    ("penetration_m", "penetration, last second (m)"),
    ("joint_error_m", "joint error, whole run (m)"),
    ("exact_distance_m", "distance from the exact solve (m)"),
]


def number(cell):
    try:
        return float(cell)
    except (TypeError, ValueError):
        return math.nan


def scenes_in_order(rows):
    seen = []
    for r in rows:
        if r["scene"] not in seen:
            seen.append(r["scene"])
    return seen


def by_scene_engine(rows):
    return {(r["scene"], r["engine"]): r for r in rows}


def grouped_bars(ax, scenes, table, column, log=True, annotate_ratio=False):
    width = 0.8 / len(ENGINES)
    drawn = False
    zeros = []  # a log scale has no bar for 0: marked "0" at the bottom instead
    for k, engine in enumerate(ENGINES):
        xs, ys = [], []
        for i, scene in enumerate(scenes):
            v = number(table.get((scene, engine), {}).get(column))
            if math.isfinite(v) and (v > 0 or not log):
                xs.append(i + (k - 1) * width)
                ys.append(v)
            elif v == 0:
                zeros.append((i + (k - 1) * width, engine))
        if not xs:
            continue
        drawn = True
        ax.bar(xs, ys, width, label=LABELS[engine], color=COLORS[engine])
        if annotate_ratio and engine != "cairn":
            for i, scene in enumerate(scenes):
                row = table.get((scene, engine), {})
                v, q = number(row.get(column)), number(row.get("ratio_vs_cairn"))
                if math.isfinite(v) and v > 0 and math.isfinite(q):
                    ax.annotate(f"{q:.2f}", (i + (k - 1) * width, v), ha="center", va="bottom", fontsize=7)
    ax.set_xticks(range(len(scenes)))
    ax.set_xticklabels(scenes, rotation=30, ha="right")
    if log and drawn:
        ax.set_yscale("log")
        bottom = ax.get_ylim()[0]
        for x, engine in zeros:
            ax.annotate("0", (x, bottom), ha="center", va="bottom", fontsize=8, color=COLORS[engine])
    ax.grid(True, axis="y", which="both", alpha=0.3)
    return drawn


def times_plot(root, rows, manifest):
    scenes = scenes_in_order(rows)
    table = by_scene_engine(rows)
    fig, ax = plt.subplots(figsize=(max(6, 1.2 * len(scenes) + 2), 4.5))
    grouped_bars(ax, scenes, table, "ms_per_step", annotate_ratio=True)
    ax.set_ylabel("ms per step (median of %s repeats)" % manifest.get("repeats", "?"))
    ax.set_title("cairn bench: time per step (numbers: Bullet / cairn, > 1 = cairn faster)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(root, "bench_times.png"), dpi=110)
    plt.close(fig)


def accuracy_plot(root, rows):
    scenes = scenes_in_order(rows)
    table = by_scene_engine(rows)
    fig, axes = plt.subplots(2, 2, figsize=(max(8, 1.6 * len(scenes) + 3), 7))
    for ax, (column, label) in zip(axes.flat, ACCURACY):
        with_figure = [s for s in scenes if any(math.isfinite(number(table.get((s, e), {}).get(column))) for e in ENGINES)]
        if not grouped_bars(ax, with_figure, table, column):
            ax.text(0.5, 0.5, "no scene has this figure", ha="center", va="center", transform=ax.transAxes)
        ax.set_title(label, fontsize=9)
    axes.flat[0].legend(fontsize=7)
    fig.suptitle("cairn bench: accuracy beside the time (lower is better; log scale)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(root, "bench_accuracy.png"), dpi=110)
    plt.close(fig)


def stages_plot(root, rows):
    cairn_rows = [r for r in rows if r["engine"] == "cairn"]
    stages = [c for c in (cairn_rows[0].keys() if cairn_rows else []) if c.startswith("stage_")]
    if not stages:
        return
    fig, ax = plt.subplots(figsize=(8, 0.5 * len(cairn_rows) + 2.4))
    left = [0.0] * len(cairn_rows)
    totals = [sum(max(number(r[s]), 0) for s in stages if math.isfinite(number(r[s]))) for r in cairn_rows]
    cmap = plt.get_cmap("tab10")
    for k, s in enumerate(stages):
        share = []
        for i, r in enumerate(cairn_rows):
            v = number(r[s])
            share.append(100 * v / totals[i] if math.isfinite(v) and totals[i] > 0 else 0)
        ax.barh(range(len(cairn_rows)), share, left=left, color=cmap(k % 10), label=s[len("stage_"):-len("_ms")])
        left = [a + b for a, b in zip(left, share)]
    ax.set_yticks(range(len(cairn_rows)))
    ax.set_yticklabels([f"{r['scene']} ({number(r['ms_per_step']):.3g} ms)" for r in cairn_rows])
    ax.invert_yaxis()
    ax.set_title("where cairn's step goes (share of the step, %)", fontsize=10)
    ax.set_xlim(0, 100)
    ax.legend(fontsize=7, ncol=5, loc="upper center", bbox_to_anchor=(0.5, -0.08))
    fig.tight_layout()
    fig.savefig(os.path.join(root, "bench_stages.png"), dpi=110)
    plt.close(fig)


def scaling_plots(root, rows):
    families = []
    for r in rows:
        if r["family"] not in families:
            families.append(r["family"])
    cairn = {r["scene"]: r for r in rows if r["engine"] == "cairn"}
    for family in families:
        fam = [r for r in rows if r["family"] == family]
        if len({r["scene"] for r in fam}) < 2:
            continue
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
        for ax, xlabel, xof in (
            (axes[0], "dynamic bodies", lambda r: number(r["bodies"])),
            (axes[1], "cairn's contacts + rows per step (mean)",
             lambda r: number(cairn[r["scene"]]["contacts"]) + number(cairn[r["scene"]]["rows"])),
        ):
            anchor = None
            for engine in ENGINES:
                pts = sorted((xof(r), number(r["ms_per_step"])) for r in fam if r["engine"] == engine)
                pts = [(x, y) for x, y in pts if math.isfinite(x) and math.isfinite(y) and x > 0 and y > 0]
                if not pts:
                    continue
                ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=COLORS[engine], label=LABELS[engine])
                if engine == "cairn":
                    anchor = pts
            if anchor:
                x0, y0 = anchor[0]
                x1 = max(p[0] for p in anchor)
                ax.plot([x0, x1], [y0, y0 * x1 / x0], "k:", label="slope 1 (cost proportional to size)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("ms per step")
            ax.grid(True, which="both", alpha=0.3)
        axes[0].legend(fontsize=8)
        sizes = ", ".join(sorted({r["scene"] for r in fam}, key=lambda s: number(cairn[s]["bodies"])))
        fig.suptitle(f"cairn bench --scaling: {family} ({sizes})", fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(root, f"scaling_{family}.png"), dpi=110)
        plt.close(fig)


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    root = argv[1]
    with open(os.path.join(root, "bench.json")) as f:
        manifest = json.load(f)
    with open(os.path.join(root, "bench.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        print("bench.csv has no rows", file=sys.stderr)
        return 1
    times_plot(root, rows, manifest)
    accuracy_plot(root, rows)
    stages_plot(root, rows)
    if manifest.get("scaling"):
        scaling_plots(root, rows)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
