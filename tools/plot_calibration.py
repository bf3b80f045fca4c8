#!/usr/bin/env python3
"""Plots the odometry's online calibration over time (calibration.csv of ctlio_odometry --out):
each estimate with its ±3σ band, the truth when calibration.yaml states one (simulator), in
grey the spans the observability check reported the coordinate unobservable, and hatched the
spans a hold prior kept it at its value (the held pass of a warm-up replay, hold_unobservable).
After a warm-up replay (calibration.warmup_replay_s) calibration.csv holds the replayed
estimates, which start from the values reached at the replay; calibration_live.csv, the
estimates returned live before it, is drawn as a dashed line up to a vertical line at the replay.

Usage: plot_calibration.py FOLDER [FOLDER ...]   (writes FOLDER/calibration.png)
"""
import csv
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_columns(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, data = rows[0], rows[1:]
    cols = {h: [] for h in header}
    for row in data:
        for h, v in zip(header, row):
            if h.endswith("_status"):  # observable | unobservable | - (not assessed)
                cols[h].append(v)
            else:
                cols[h].append(float(v) if v not in ("", "nan", "-nan") else math.nan)
    return cols


def spans(t, flags):
    """[(t_begin, t_end)] over which flags[i] is true: from the first scan of a run of true flags
    to the first scan after it (or the last scan)."""
    out, begin = [], None
    for i, on in enumerate(flags):
        if on and begin is None:
            begin = t[i]
        elif not on and begin is not None:
            out.append((begin, t[i]))
            begin = None
    if begin is not None:
        out.append((begin, t[-1]))
    return out


def unobservable_spans(t, status):
    """Where the observability check reported the coordinate unobservable."""
    return spans(t, [s == "unobservable" for s in status])


def held_spans(t, held):
    """Where a hold prior kept the coordinate at its value in the scan's solve (column 1)."""
    return spans(t, [h == 1 for h in held])


def read_truths(folder):
    """{series key: true value in calibration.csv's unit} from calibration.yaml's per-coordinate
    blocks ("# <coordinate> [ms|cm|deg]" ... "#   truth      <value>", simulator runs only): the
    IMU index for a time offset [s], the column name for the extrinsic's rho [m] / phi [deg]."""
    truth = {}
    path = os.path.join(folder, "calibration.yaml")
    if not os.path.exists(path):
        return truth
    coordinate = None
    with open(path) as f:
        for line in f:
            m = re.match(r"# (time_offset_\d+|extrinsic_(?:rho|phi)_[xyz]) \[(ms|cm|deg)\]", line)
            if m:
                coordinate = m.group(1)
                continue
            m = re.match(r"#   truth +([-+0-9.eE]+|nan|inf)", line)
            if m and coordinate:
                v = float(m.group(1))
                if coordinate.startswith("time_offset_"):
                    truth[int(coordinate[len("time_offset_"):])] = 1e-3 * v
                elif coordinate.startswith("extrinsic_rho_"):
                    truth[coordinate + "_m"] = 1e-2 * v
                else:
                    truth[coordinate + "_deg"] = v
    return truth


def plot(folder):
    cols = read_columns(os.path.join(folder, "calibration.csv"))
    if "t_s" not in cols or not cols["t_s"]:
        return
    t0 = cols["t_s"][0]
    t = [x - t0 for x in cols["t_s"]]
    # One panel per estimated quantity: "<name>" with "<name>_sigma..." next to it.
    series = []
    for h in cols:
        m = re.match(r"time_offset_(\d+)_s$", h)
        if m:
            series.append((f"IMU {m.group(1)} time offset [ms]", h,
                           f"time_offset_{m.group(1)}_sigma_s", 1e3, int(m.group(1)),
                           f"time_offset_{m.group(1)}"))
    # The extrinsic: its deviation from the starting value, [rho; phi] of T = Exp([rho; phi]) T_start.
    for a in "xyz":
        key = f"extrinsic_rho_{a}_m"
        if key in cols:
            series.append((f"extrinsic rho_{a} [cm]", key, f"extrinsic_rho_{a}_sigma_m", 1e2, key,
                           f"extrinsic_rho_{a}"))
    for a in "xyz":
        key = f"extrinsic_phi_{a}_deg"
        if key in cols:
            series.append((f"extrinsic phi_{a} [deg]", key, f"extrinsic_phi_{a}_sigma_deg", 1.0,
                           key, f"extrinsic_phi_{a}"))
    if not series:
        return
    live_path = os.path.join(folder, "calibration_live.csv")
    live = read_columns(live_path) if os.path.exists(live_path) else {}
    t_live = [x - t0 for x in live.get("t_s", [])]
    truth = read_truths(folder)
    fig, axes = plt.subplots(len(series), 1, figsize=(8, 2.6 * len(series)), squeeze=False)
    for ax, (label, key, sigma_key, scale, imu, coordinate) in zip(axes[:, 0], series):
        est = [scale * v for v in cols[key]]
        sig = [scale * v for v in cols.get(sigma_key, [math.nan] * len(est))]
        ax.plot(t, est, color="tab:red", label="estimate")
        lo = [e - 3 * s for e, s in zip(est, sig)]
        hi = [e + 3 * s for e, s in zip(est, sig)]
        ax.fill_between(t, lo, hi, color="tab:red", alpha=0.2, label="±3σ")
        if t_live and key in live:
            ax.plot(t_live, [scale * v for v in live[key]], color="tab:blue", linestyle="--",
                    label="live, before the replay")
            ax.axvline(t_live[-1], color="tab:blue", lw=0.8, label="warm-up replay")
        # Grey: unobservable from the measurements of the horizon (held in the next scan).
        for n, (b, e) in enumerate(unobservable_spans(t, cols.get(coordinate + "_status", []))):
            ax.axvspan(b, e, color="0.6", alpha=0.3, lw=0, label="unobservable" if n == 0 else None)
        # Hatched: held at its value by a hold prior (not estimated in those scans' solves).
        for n, (b, e) in enumerate(held_spans(t, cols.get(coordinate + "_held", []))):
            ax.axvspan(b, e, facecolor="none", edgecolor="tab:green", hatch="//", lw=0,
                       label="held" if n == 0 else None)
        if imu in truth:
            ax.axhline(scale * truth[imu], color="k", linestyle="--", label="truth")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    axes[-1, 0].set_xlabel("time since the first scan [s]")
    fig.suptitle(f"Online calibration: {os.path.basename(os.path.normpath(folder))}")
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "calibration.png"), dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for folder in sys.argv[1:]:
        plot(folder)
