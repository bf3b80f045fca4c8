#!/usr/bin/env python3
"""Plots for ctlio_evaluate (SPEC section 6): the top view of the aligned estimate coloured by
its absolute position error (like the paper's Fig. 11) and the error over time.

usage: plot_trajectory_error.py <errors.csv> <output_dir> [title]
errors.csv columns: t_s, est_x, est_y, est_z (aligned), ref_x, ref_y, ref_z, error_m.
Writes <output_dir>/top_view.png and <output_dir>/error_over_time.png. Exit code 3 if matplotlib
is missing (the caller prints a message and carries on).
"""
import csv
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("matplotlib is not installed (Debian: apt install python3-matplotlib)\n")
    sys.exit(3)


def main():
    if len(sys.argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    path, out = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else ""
    t, ex, ey, rx, ry, err = [], [], [], [], [], []
    with open(path) as f:
        for row in csv.DictReader(f):
            t.append(float(row["t_s"]))
            ex.append(float(row["est_x"]))
            ey.append(float(row["est_y"]))
            rx.append(float(row["ref_x"]))
            ry.append(float(row["ref_y"]))
            err.append(float(row["error_m"]))
    if not t:
        sys.stderr.write(path + ": no rows\n")
        return 1
    t0 = t[0]
    t = [x - t0 for x in t]

    fig, ax = plt.subplots(figsize=(7, 6))
    ax.plot(rx, ry, color="0.6", lw=1.0, label="reference")
    sc = ax.scatter(ex, ey, c=err, s=4, cmap="jet", label="estimate (aligned)")
    fig.colorbar(sc, ax=ax, label="absolute position error [m]")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best")
    ax.set_title(title or "top view")
    fig.tight_layout()
    fig.savefig(out + "/top_view.png", dpi=150)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(t, err, lw=1.0)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("absolute position error [m]")
    ax.grid(True, alpha=0.3)
    ax.set_title(title or "error over time")
    fig.tight_layout()
    fig.savefig(out + "/error_over_time.png", dpi=150)
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
