#!/usr/bin/env python3
"""Draws the plots of a `cairn validate` report.

usage: plot_report.py DIR

Reads DIR/plots.json, written by `cairn validate --report DIR`: a list of
plots, each {csv, png, title, xlabel, ylabel, series: [{column, label}],
logy}, with csv and png relative to DIR. Every plot gets its title, both
axes labelled with units and a legend naming the engine of each line.

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

STYLE = {"cairn": {"color": "tab:blue", "linewidth": 1.6},
         "Bullet": {"color": "tab:orange", "linewidth": 1.2, "linestyle": "--"}}


def read_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    cols = {name: [] for name in header}
    for row in body:
        for name, cell in zip(header, row):
            cols[name].append(float(cell) if cell != "" else math.nan)
    return cols


def draw(root, plot, cache):
    csv_path = os.path.join(root, plot["csv"])
    if csv_path not in cache:
        cache[csv_path] = read_columns(csv_path)
    cols = cache[csv_path]
    fig, ax = plt.subplots(figsize=(7.5, 4.0), dpi=100)
    t = cols["time"]
    for s in plot["series"]:
        if s["column"] not in cols:
            continue
        ax.plot(t, cols[s["column"]], label=s["label"], **STYLE.get(s["label"], {}))
    ax.set_title(plot["title"])
    ax.set_xlabel(plot.get("xlabel", "time (s)"))
    ax.set_ylabel(plot["ylabel"])
    if plot.get("logy"):
        ax.set_yscale("symlog", linthresh=1e-6)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    fig.tight_layout()
    fig.savefig(os.path.join(root, plot["png"]))
    plt.close(fig)


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    root = argv[1]
    with open(os.path.join(root, "plots.json")) as f:
        plots = json.load(f)
    cache = {}
    for plot in plots:
        draw(root, plot, cache)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
