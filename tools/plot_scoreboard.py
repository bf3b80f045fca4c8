#!/usr/bin/env python3
"""Plots the scoreboard (scoreboard.csv of ctlio_scoreboard, docs/experiments/scoreboard.md).

Left: every cell as a point at (ATE ratio, CPU ratio) Singer-LIO / baseline, log axes; the target
region (both ≤ 1) shaded; colour = motion, marker = sensor; a cell where a method failed a run is
ringed in red. Right: both methods' ATE per cell [cm, log scale], failed runs annotated.

  /usr/bin/python3 tools/plot_scoreboard.py OUT/scoreboard.csv OUT/scoreboard.png
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

MOTION_COLOURS = {"walking": "#1f77b4", "fast": "#d62728", "vehicle": "#2ca02c"}
MARKERS = "osD^v<>pPX*h"


def main(argv):
    if len(argv) != 3:
        sys.exit("usage: plot_scoreboard.py scoreboard.csv out.png")
    with open(argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_scoreboard.py: {argv[1]}: no cells")
    sensors = sorted({r["sensor"] for r in rows})
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(15, max(6, 0.22 * len(rows) + 2)),
                                 gridspec_kw={"width_ratios": [1, 1.2]})
    ratios = []
    for r in rows:
        s, b = float(r["singer_ate_rms_m"]), float(r["baseline_ate_rms_m"])
        ate_ratio = s / b if b > 0 and math.isfinite(s / b) else float("nan")
        cpu_ratio = float(r["cpu_ratio"])
        ratios.append((ate_ratio, cpu_ratio))
        failed = int(r["singer_failed_runs"]) + int(r["baseline_failed_runs"]) > 0
        ax.scatter([ate_ratio], [cpu_ratio], c=MOTION_COLOURS.get(r["regime"], "k"),
                   marker=MARKERS[sensors.index(r["sensor"]) % len(MARKERS)], s=55,
                   edgecolors="red" if failed else "none", linewidths=2 if failed else 0)
    finite = [v for pair in ratios for v in pair if math.isfinite(v) and v > 0]
    lo, hi = min(finite + [0.5]) / 1.3, max(finite + [2.0]) * 1.3
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    ticks = [t for t in (0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50) if lo <= t <= hi]
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(matplotlib.ticker.FixedLocator(ticks))
        axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.fill_between([lo, 1], lo, 1, color="#e8f5e9", zorder=0)
    ax.axvline(1, color="grey", lw=0.8)
    ax.axhline(1, color="grey", lw=0.8)
    ax.set_xlabel("ATE Singer-LIO / baseline (RMS over runs)")
    ax.set_ylabel("CPU per scan Singer-LIO / baseline (median)")
    ax.set_title("Each cell (shaded: Singer-LIO better on both)")
    for motion, colour in MOTION_COLOURS.items():
        ax.scatter([], [], c=colour, label=motion)
    for i, s in enumerate(sensors):
        ax.scatter([], [], c="k", marker=MARKERS[i % len(MARKERS)], label=s)
    ax.scatter([], [], c="w", edgecolors="red", linewidths=2, label="a failed run")
    ax.legend(fontsize=8, loc="upper left")

    labels = [f'{r["sensor"]} {r["world"]} {r["regime"]}' for r in rows]
    y = list(range(len(rows)))
    s_cm = [100 * float(r["singer_ate_rms_m"]) for r in rows]
    b_cm = [100 * float(r["baseline_ate_rms_m"]) for r in rows]
    bx.barh([v + 0.2 for v in y], s_cm, height=0.4, color="#d62728", label="Singer-LIO")
    bx.barh([v - 0.2 for v in y], b_cm, height=0.4, color="#1f77b4", label="baseline (imu_input)")
    for i, r in enumerate(rows):
        notes = []
        if int(r["singer_failed_runs"]):
            notes.append(f'S failed {r["singer_failed_runs"]}')
        if int(r["baseline_failed_runs"]):
            notes.append(f'B failed {r["baseline_failed_runs"]}')
        if notes:
            bx.text(max(s_cm[i], b_cm[i]) * 1.1, i, ", ".join(notes), va="center", fontsize=7,
                    color="red")
    bx.set_xscale("log")
    bx.xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    bx.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    bx.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    bx.set_yticks(y)
    bx.set_yticklabels(labels, fontsize=7)
    bx.invert_yaxis()
    bx.set_xlabel("ATE [cm], RMS over runs (log scale)")
    bx.legend(fontsize=8, loc="lower right")
    bx.grid(axis="x", color="#ddd")
    # The headline a reader needs before the cells: how many, how many runs each, how many met.
    runs = sorted({int(r["runs"]) for r in rows})
    met = sum(int(r["target_met"]) for r in rows)
    fig.suptitle(f"Singer-LIO vs baseline: {len(rows)} cells, "
                 f"{'/'.join(map(str, runs))} runs per cell; target "
                 f"(ATE and CPU no worse, no failure) met in {met} of {len(rows)}")
    fig.tight_layout()
    fig.savefig(argv[2], dpi=110)


if __name__ == "__main__":
    main(sys.argv)
