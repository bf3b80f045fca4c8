#!/usr/bin/env python3
"""One picture of a worlds x regimes experiment (docs/experiments/worlds-and-degeneracy.md):
per cell (world / regime) and method, the RMSE ATE over the runs that did not fail, the mean
drift per 100 m over the same runs, and the median CPU ms per scan; failed runs are written
above the bars ("3/10 failed"), a cell where every run failed gets an "x" at the top.

usage: plot_worlds.py <output.png> <dir> [<dir> ...]
Each <dir> is a ctlio_experiment output folder (a job or a --merge of jobs) with settings.txt
(its "world" and "config" lines), pooled.csv and results.csv. The first folder's config is the
main one: the methods of a folder run with another config are shown as "method [config]".
Exit code 3 if matplotlib is missing.
"""
import csv
import math
import os
import statistics
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.patches
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("matplotlib is not installed (Debian: apt install python3-matplotlib)\n")
    sys.exit(3)

COLOURS = {"singer_lio": "#d62728", "imu_input": "#1f77b4", "lidar_gyro": "#2ca02c",
           "lidar_only": "#9467bd"}
EXTRA_COLOURS = ["#17becf", "#8c564b", "#e377c2", "#7f7f7f"]


def read_settings(folder):
    settings = {}
    with open(os.path.join(folder, "settings.txt")) as f:
        for line in f:
            key, _, value = line.strip().partition(" ")
            settings[key] = value
    return settings


def read_folder(folder, main_config):
    """Returns [(cell label, method, pooled row, median of the runs' median CPU ms)]; a method
    run with another config than main_config is named "method [config]"."""
    settings = read_settings(folder)
    world = settings.get("world", "?")
    config = settings.get("config", "")
    suffix = "" if config == main_config else " [" + os.path.splitext(config)[0] + "]"
    cpu = {}
    with open(os.path.join(folder, "results.csv")) as f:
        for row in csv.DictReader(f):
            if row["error"]:
                continue
            key = (row["regime"], row["method"], row["scenario"])
            cpu.setdefault(key, []).append(float(row["median_cpu_ms"]))
    cells = []
    with open(os.path.join(folder, "pooled.csv")) as f:
        for row in csv.DictReader(f):
            key = (row["regime"], row["method"], row["scenario"])
            label = world + " / " + row["regime"]
            if row["scenario"] != "none":
                label += " / " + row["scenario"]
            # The same statistic as table.md's "median CPU ms/scan" (median over the runs).
            median_cpu = statistics.median(cpu[key]) if key in cpu else math.nan
            cells.append((label, row["method"] + suffix, row, median_cpu))
    return cells


def main():
    if len(sys.argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    out = sys.argv[1]
    # The config of the first folder is the main one; others mark their methods.
    main_config = read_settings(sys.argv[2]).get("config", "")
    rows = []
    for folder in sys.argv[2:]:
        rows += read_folder(folder, main_config)
    labels, methods = [], []
    for label, method, _, _ in rows:
        if label not in labels:
            labels.append(label)
        if method not in methods:
            methods.append(method)
    # Variants of a method (another config) next to it.
    base = list(COLOURS)
    methods.sort(key=lambda m: (base.index(m.split(" ")[0]) if m.split(" ")[0] in base
                                else len(base), m))
    by_key = {(label, method): (row, cpu) for label, method, row, cpu in rows}
    colours = dict(COLOURS)
    for method in methods:
        if method not in colours:
            colours[method] = EXTRA_COLOURS[len(colours) % len(EXTRA_COLOURS)]

    fig, axes = plt.subplots(3, 1, figsize=(max(8, 1.1 * len(labels) + 2), 11), sharex=True)
    width = 0.8 / len(methods)
    panels = [("RMSE ATE, runs not failed [m]", lambda r, c: float(r["rmse_ate_non_failed_m"])),
              ("drift per 100 m, runs not failed [m]",
               lambda r, c: float(r["drift_m_per_100m_non_failed"])),
              ("median CPU ms per scan", lambda r, c: c)]
    for ax, (title, value) in zip(axes, panels):
        if ax is not axes[2]:
            ax.set_yscale("log")
        ax.set_ylabel(title)
        ax.grid(axis="y", which="both", color="#ddd", linewidth=0.5)
        top = max((value(r, c) for r, c in by_key.values() if math.isfinite(value(r, c))),
                  default=1.0)
        for m, method in enumerate(methods):
            for i, label in enumerate(labels):
                if (label, method) not in by_key:
                    continue
                row, cpu = by_key[(label, method)]
                x = i - 0.4 + width * (m + 0.5)
                v = value(row, cpu)
                failures, runs = int(row["failures"]), int(row["runs"])
                if math.isfinite(v) and v > 0:
                    ax.bar(x, v, width, color=colours[method])
                elif ax is not axes[2]:
                    ax.plot(x, top * 1.5, "x", color=colours[method])
                if ax is axes[0] and failures > 0:
                    y = v if math.isfinite(v) and v > 0 else top * 1.5
                    ax.text(x, y * 1.2, "%d/%d failed" % (failures, runs), rotation=90,
                            ha="center", va="bottom", fontsize=7)
        if ax is not axes[2]:
            ax.set_ylim(top=top * 40)
    handles = [matplotlib.patches.Patch(color=colours[m], label=m) for m in methods]
    axes[0].legend(handles=handles, ncol=len(methods), fontsize=8, loc="upper left")
    axes[0].set_title("worlds x regimes: x = every run failed; failed runs are not in ATE/drift")
    axes[-1].set_xticks(range(len(labels)))
    axes[-1].set_xticklabels(labels, rotation=30, ha="right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote " + out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
