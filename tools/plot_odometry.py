#!/usr/bin/env python3
"""Plots of a ctlio_odometry run: one figure per method and one comparing the methods.

usage: plot_odometry.py <out_dir> <method_dir> [<method_dir> ...]

Each method folder is what ctlio_odometry writes: trajectory.tum (scan-end poses),
trajectory_dense.tum and trajectory_dense_live.tum (optional, --trajectory_rate: the dense
trajectory from the final estimates, and the live one stitched from each scan's window as it was
returned), scans.log, evaluation.txt and, with ground truth, ground_truth.tum and pose_errors.csv
(aligned scan poses and their position/rotation errors), trajectory_covariance.csv (optional,
--pose_covariance: drawn as the 3σ band of the position under its error). Writes <method_dir>/odometry.png and,
for several methods, <out_dir>/comparison.png:
  * top view (x-y) and side view (x-z) in metres: ground truth, the estimate at the densest rate
    written ("dense, final estimates"; in the single-method figure also "dense, live, causal"),
    the scan poses as dots;
  * position error [cm] and rotation error [deg] over time;
  * per-scan CPU time [ms] of the scan thread over time, coloured by scan status; degenerate, IMU-gap and failed
    scans marked, gaps in the scan sequence shaded.
Exit code 3 if matplotlib is missing (the caller then writes its SVG fallback). CTLIO_PLOT_DPI
sets the resolution (default 90).
"""
import csv
import os
import sys
import textwrap

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("matplotlib is not installed (Debian: apt install python3-matplotlib)\n")
    sys.exit(3)

STATUS_COLOURS = {"ok": "#1f77b4", "initialising": "#7f7f7f", "degenerate": "#ff7f0e",
                  "imu_gap": "#9467bd", "failed": "#d62728"}
METHOD_COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd"]


def read_tum(path):
    rows = []
    if not os.path.exists(path):
        return rows
    with open(path) as f:
        for line in f:
            p = line.split()
            if len(p) >= 8 and not line.startswith("#"):
                rows.append([float(x) for x in p[:8]])
    return rows


def read_evaluation(path):
    ev = {}
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                key, _, value = line.strip().partition(" ")
                ev[key] = value.strip('"')
    return ev


def read_scans(path):
    """(t, status, CPU ms of the scan thread) per scan; the wall-clock `ms` column of logs written
    before `cpu_ms` existed. Columns are found by the header's names."""
    scans = []
    if not os.path.exists(path):
        return scans
    t_col, status_col, ms_col = 0, 1, 8
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                names = line[1:].split()
                if "cpu_ms" in names:
                    ms_col = names.index("cpu_ms")
                elif "ms" in names:
                    ms_col = names.index("ms")
                continue
            p = line.split()
            if len(p) > ms_col:
                scans.append((float(p[t_col]), p[status_col], float(p[ms_col])))
    return scans


def read_errors(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def alignment_of(ev):
    """The estimate-to-truth alignment (4x4, row-major in evaluation.txt), applied to positions."""
    values = [float(x) for x in ev.get("ate_alignment", "").split()]
    if len(values) != 16:
        return lambda p: p
    m = [values[0:4], values[4:8], values[8:12]]
    return lambda p: [m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] for i in range(3)]


class Run:
    def __init__(self, folder):
        self.folder = folder
        self.ev = read_evaluation(os.path.join(folder, "evaluation.txt"))
        self.method = self.ev.get("method", os.path.basename(folder.rstrip("/")))
        self.source = self.ev.get("source", "")
        align = alignment_of(self.ev)
        self.scan_poses = [align(r[1:4]) for r in read_tum(os.path.join(folder, "trajectory.tum"))]
        self.scan_t = [r[0] for r in read_tum(os.path.join(folder, "trajectory.tum"))]
        dense = read_tum(os.path.join(folder, "trajectory_dense.tum"))
        self.dense = len(dense) > len(self.scan_poses)
        self.path = [align(r[1:4]) for r in dense] if self.dense else self.scan_poses
        live = read_tum(os.path.join(folder, "trajectory_dense_live.tum"))
        self.live_path = [align(r[1:4]) for r in live] if len(live) > len(self.scan_poses) else []
        self.truth = read_tum(os.path.join(folder, "ground_truth.tum"))
        if self.truth and self.scan_t:
            lo, hi = self.scan_t[0] - 0.05, self.scan_t[-1] + 0.05
            self.truth = [r for r in self.truth if lo <= r[0] <= hi]
        self.errors = read_errors(os.path.join(folder, "pose_errors.csv"))
        # With --pose_covariance: (t, 3σ of the position [m]) per scan, σ² = trace of the
        # translation block (docs/user-guide/outputs.md, trajectory_covariance.csv).
        self.sigma3 = [(c["t"], 3.0 * (c["c_x_x"] + c["c_y_y"] + c["c_z_z"]) ** 0.5)
                       for c in read_errors(os.path.join(folder, "trajectory_covariance.csv"))]
        self.scans = read_scans(os.path.join(folder, "scans.log"))
        self.t0 = self.scans[0][0] if self.scans else (self.scan_t[0] if self.scan_t else 0.0)

    def ate_text(self):
        if "ate_rmse_m" in self.ev:
            return "ATE %.2f cm" % (100.0 * float(self.ev["ate_rmse_m"]))
        return "no ground truth"


def draw_views(ax_top, ax_side, runs, single):
    truth = runs[0].truth
    for ax, (i, j), name in ((ax_top, (1, 2), "top view"), (ax_side, (1, 3), "side view")):
        if truth:
            ax.plot([r[i] for r in truth], [r[j] for r in truth], color="0.55", lw=3.0,
                    label="ground truth", zorder=1)
        for k, run in enumerate(runs):
            colour = METHOD_COLOURS[k % len(METHOD_COLOURS)]
            rate = "dense, final estimates" if run.dense else "scan poses"
            label = "estimate (%s)" % rate if single else "%s (%s)" % (run.method, rate)
            ax.plot([p[i - 1] for p in run.path], [p[j - 1] for p in run.path], color=colour,
                    lw=1.2, label=label, zorder=2)
            if single and run.live_path:
                ax.plot([p[i - 1] for p in run.live_path], [p[j - 1] for p in run.live_path],
                        color="#1f77b4", lw=0.8, ls="--", label="estimate (dense, live, causal)",
                        zorder=2)
            if single:
                ax.plot([p[i - 1] for p in run.scan_poses], [p[j - 1] for p in run.scan_poses],
                        ".", color=colour, ms=4, label="scan-end poses (live)", zorder=3)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]" if j == 2 else "z [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(name + (" (aligned to the truth)" if truth else ""))
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8)


def draw_errors(ax, runs, single):
    if not any(run.errors for run in runs):
        ax.text(0.5, 0.5, "no ground truth: no errors", ha="center", va="center",
                transform=ax.transAxes)
        ax.set_axis_off()
        return
    ax_rot = ax.twinx() if single else None
    for k, run in enumerate(runs):
        colour = METHOD_COLOURS[k % len(METHOD_COLOURS)]
        t = [e["t_s"] - run.t0 for e in run.errors]
        ax.plot(t, [100.0 * e["position_error_m"] for e in run.errors], color=colour,
                label="position" if single else run.method)
        if run.sigma3:
            ax.fill_between([c[0] - run.t0 for c in run.sigma3],
                            [100.0 * c[1] for c in run.sigma3], color=colour, alpha=0.15, lw=0,
                            label="3σ of the position (filter)" if single else None)
        if ax_rot is not None:
            ax_rot.plot(t, [e["rotation_error_deg"] for e in run.errors], color="#2ca02c",
                        ls="--", label="rotation")
    ax.set_xlabel("time since the first scan [s]")
    ax.set_ylabel("position error [cm]")
    ax.set_title("error at the scan poses" + ("" if single else " (position)"))
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if ax_rot is not None:
        ax_rot.set_ylabel("rotation drift since the first pose [deg]")
        h2, l2 = ax_rot.get_legend_handles_labels()
        handles, labels = handles + h2, labels + l2
    ax.legend(handles, labels, loc="upper left", fontsize=8)


def draw_timing(ax, runs, single):
    for k, run in enumerate(runs):
        if not run.scans:
            continue
        t = [s[0] - run.t0 for s in run.scans]
        ms = [s[2] for s in run.scans]
        if single:
            for status, colour in STATUS_COLOURS.items():
                pts = [(a, b) for a, b, s in zip(t, ms, run.scans) if s[1] == status]
                if pts:
                    ax.scatter([p[0] for p in pts], [p[1] for p in pts], s=10, color=colour,
                               label="%s (%d)" % (status, len(pts)), zorder=3)
            for a, s in zip(t, run.scans):
                if s[1] in ("degenerate", "imu_gap", "failed"):
                    ax.axvline(a, color=STATUS_COLOURS[s[1]], alpha=0.4, lw=1)
        else:
            ax.plot(t, ms, ".-", ms=3, lw=0.8, color=METHOD_COLOURS[k % len(METHOD_COLOURS)],
                    label=run.method)
        # Gaps: a step between scans over 1.5 times the median step.
        steps = sorted(b - a for a, b in zip(t, t[1:]))
        if steps:
            median = steps[len(steps) // 2]
            first_gap = True
            for a, b in zip(t, t[1:]):
                if b - a > 1.5 * median:
                    ax.axvspan(a, b, color="0.8", alpha=0.5,
                               label="gap between scans" if first_gap and k == 0 else None)
                    first_gap = False
    ax.set_xlabel("time since the first scan [s]")
    ax.set_ylabel("CPU time per scan [ms]")
    ax.set_title("per-scan time and status" if single else "per-scan time")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)


def figure(runs, title, path):
    single = len(runs) == 1
    fig, axes = plt.subplots(2, 2, figsize=(12, 9.5), layout="constrained")
    draw_views(axes[0][0], axes[0][1], runs, single)
    draw_errors(axes[1][0], runs, single)
    draw_timing(axes[1][1], runs, single)
    # Wrapped so that a long source path never runs off the figure.
    fig.suptitle("\n".join(textwrap.wrap(title, 95)), fontsize=12)
    fig.savefig(path, dpi=int(os.environ.get("CTLIO_PLOT_DPI", "90")))
    plt.close(fig)
    print("wrote " + path)


def main():
    if len(sys.argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    out, folders = sys.argv[1], sys.argv[2:]
    runs = [Run(f) for f in folders]
    for run in runs:
        figure([run], "%s on %s: %s, %d scans" % (run.method, run.source, run.ate_text(),
                                                  len(run.scans)),
               os.path.join(run.folder, "odometry.png"))
    if len(runs) > 1:
        summary = ", ".join("%s %s" % (r.method, r.ate_text()) for r in runs)
        figure(runs, "%s: %s" % (runs[0].source, summary), os.path.join(out, "comparison.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
