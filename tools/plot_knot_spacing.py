#!/usr/bin/env python3
"""The ATE bars of docs/experiments/knot-spacing.md (tuning table, columns baseline / one knot / F).

Usage: tools/plot_knot_spacing.py [OUT.png]; the numbers are the table's, copied here."""
import sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
cells = ["hdl32e\nbox", "xt32\nbox", "vlp16\nbox", "os1_128\nbox", "hdl32e\noffice", "vlp16\noffice",
         "xt32\noffice", "mid360\noffice", "avia\noffice", "os1_64\ncorridor"]
base = [0.14, 0.25, 0.33, 0.76, 0.97, 0.87, 1.14, 1.78, 4.20, 0.61]
one = [0.77, 0.81, 1.43, 0.76, 1.98, 1.95, 2.00, 3.21, 4.06, 1.61]
f = [0.31, 0.24, 0.49, 0.66, 1.28, 1.02, 1.28, 2.40, 5.24, 0.79]
x = range(len(cells))
w = 0.27
fig, ax = plt.subplots(figsize=(11, 4.2))
ax.bar([i - w for i in x], base, w, label="baseline (imu_input)", color="0.55")
ax.bar(list(x), one, w, label="Singer-LIO, one knot per sweep (before)", color="tab:orange")
ax.bar([i + w for i in x], f, w, label="Singer-LIO, knots from the motion + variance floor (shipped)", color="tab:blue")
ax.set_xticks(list(x))
ax.set_xticklabels(cells)
ax.set_yscale("log")
ax.set_yticks([0.1, 0.2, 0.5, 1, 2, 5])
ax.set_yticklabels(["0.1", "0.2", "0.5", "1", "2", "5"])
ax.set_ylim(0.1, 7)
ax.set_ylabel("ATE RMS over 3 runs [cm] (log)")
ax.set_title("Handheld fast motion, tuning indices 100-102, 3 x 10 s per cell")
ax.legend(fontsize=8, loc="upper left")
ax.grid(axis="y", which="both", alpha=0.3)
fig.tight_layout()
fig.savefig(sys.argv[1] if len(sys.argv) > 1 else "docs/experiments/img/knot_spacing.png", dpi=110)
