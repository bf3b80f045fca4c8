#!/usr/bin/env python3
"""Planar vs scattered fraction of sweeps (docs/experiments/worlds-geometry.md): one point per
sweep, one colour and marker per group, with the issue's ±0.1 boxes around the real groups.

usage: plot_geometry_report.py <output.png> <group>=<report.txt> [<group>=<report.txt> ...]
Each report is the table printed by ctlio_geometry_report or ctlio_simulate --geometry_report
(header line, then: label points voxels planar scattered median_ratio median_range); a group
whose name starts with "real" is drawn filled with its ±0.1 box. Exit code 3 without matplotlib.
"""
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.patches
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("matplotlib is not installed (Debian: apt install python3-matplotlib)\n")
    sys.exit(3)


def read(path):
    rows = []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if len(parts) < 7 or parts[0] == "sweep":
                continue
            try:
                rows.append((float(parts[-4]), float(parts[-3])))
            except ValueError:
                continue
    return rows


def main():
    if len(sys.argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    fig, ax = plt.subplots(figsize=(7, 5.5))
    markers = "os^vDP*Xh"
    for k, arg in enumerate(sys.argv[2:]):
        name, path = arg.split("=", 1)
        rows = read(path)
        if not rows:
            sys.stderr.write("%s: no rows\n" % path)
            return 1
        colour = "C%d" % k
        real = name.startswith("real")
        xs, ys = [r[0] for r in rows], [r[1] for r in rows]
        ax.scatter(xs, ys, label=name, color=colour, marker=markers[k % len(markers)],
                   facecolors=colour if real else "none", s=45)
        if real:
            lo_x, hi_x = min(xs) - 0.1, max(xs) + 0.1
            lo_y, hi_y = min(ys) - 0.1, max(ys) + 0.1
            ax.add_patch(matplotlib.patches.Rectangle((lo_x, lo_y), hi_x - lo_x, hi_y - lo_y,
                                                      fill=False, ls="--", color=colour))
    ax.set_xlabel("planar fraction (λ3/λ1 < 0.01)")
    ax.set_ylabel("scattered fraction (λ3/λ1 > 0.1)")
    ax.set_xlim(0, 1)
    ax.set_ylim(-0.02, 0.5)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title("Local geometry of sweeps: real vs simulated (dashed: real ± 0.1)")
    fig.tight_layout()
    fig.savefig(sys.argv[1], dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
