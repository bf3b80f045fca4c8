#!/usr/bin/env python3
"""Plots of the 1D study (paper Figs. 3-7) from the CSV output of ctlio_study_1d.

usage: plot_study_1d.py OUTPUT_DIR

For every <scenario>_<dataset> prefix found in OUTPUT_DIR writes
  <prefix>_samples.png   sample trajectories with both estimates (Fig. 3)
  <prefix>_errors.png    mean error +- RMSE band and 3-sigma of sample 0 over time (Figs. 4-5)
  <prefix>_nees.png      average NEES of both estimators with the 95% chi^2 bounds (Figs. 6-7)
Needs matplotlib (Debian: python3-matplotlib); prints a message and exits 0 without it.
"""
import csv
import glob
import os
import sys


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    out = sys.argv[1]
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot_study_1d.py: matplotlib not available (apt install python3-matplotlib); "
              "skipping the plots, the CSV/JSON output is complete")
        return 0
    prefixes = sorted(p[:-len("_input_stats.csv")]
                      for p in glob.glob(os.path.join(out, "*_input_stats.csv")))
    if not prefixes:
        print(f"plot_study_1d.py: no *_input_stats.csv in {out}")
        return 1
    for prefix in prefixes:
        name = os.path.basename(prefix)
        a = read_csv(prefix + "_input_stats.csv")
        b = read_csv(prefix + "_measurement_stats.csv")
        s = read_csv(prefix + "_samples.csv")

        # Fig. 3: sample trajectories.
        fig, ax = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        samples = sorted(set(int(v) for v in s["sample"])) if s else []
        for k in samples:
            idx = [i for i, v in enumerate(s["sample"]) if int(v) == k]
            t = [s["t"][i] for i in idx]
            for row, (truth, key_in, key_me) in enumerate(
                    [("p", "in_p", "me_p"), ("v", "in_v", "me_v"), ("a", None, "me_a")]):
                ax[row].plot(t, [s[truth][i] for i in idx], "k-", lw=1,
                             label="truth" if k == 0 else None)
                if key_in:
                    ax[row].plot(t, [s[key_in][i] for i in idx], "C0--", lw=1,
                                 label="IMU as input" if k == 0 else None)
                ax[row].plot(t, [s[key_me][i] for i in idx], "C1:", lw=1.5,
                             label="IMU as measurement" if k == 0 else None)
        for row, lab in enumerate(["p [m]", "v [m/s]", "a [m/s²]"]):
            ax[row].set_ylabel(lab)
        ax[0].legend(loc="best", fontsize=8)
        ax[2].set_xlabel("t [s]")
        fig.suptitle(f"{name}: sample test trajectories")
        fig.tight_layout()
        fig.savefig(prefix + "_samples.png", dpi=120)
        plt.close(fig)

        # Figs. 4-5: error statistics over time (mean error and RMSE of both estimators).
        fig, ax = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        for row, comp in enumerate(["p", "v", "a"]):
            for stats, color, label in [(a, "C0", "IMU as input"), (b, "C1", "IMU as measurement")]:
                if "mean_" + comp not in stats:
                    continue
                t = stats["t"]
                m = stats["mean_" + comp]
                r = stats["rmse_" + comp]
                ax[row].plot(t, m, color=color, lw=1, label=f"{label}: mean error")
                ax[row].fill_between(t, [x - 3 * y for x, y in zip(m, r)],
                                     [x + 3 * y for x, y in zip(m, r)], color=color, alpha=0.15,
                                     label=f"{label}: ±3 RMSE")
            ax[row].set_ylabel(f"error {comp}")
        ax[0].legend(loc="best", fontsize=7)
        ax[2].set_xlabel("t [s]")
        fig.suptitle(f"{name}: error over time (test set)")
        fig.tight_layout()
        fig.savefig(prefix + "_errors.png", dpi=120)
        plt.close(fig)

        # Figs. 6-7: average NEES with two-sided 95% chi^2 bounds.
        fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        for row, (stats, label, dim) in enumerate([(a, "IMU as input", 2),
                                                    (b, "IMU as measurement", 3)]):
            ax[row].plot(stats["t"], stats["nees"], "C%d" % row, lw=1, label="average NEES")
            ax[row].plot(stats["t"], stats["nees_lower"], "k--", lw=1, label="95% bounds")
            ax[row].plot(stats["t"], stats["nees_upper"], "k--", lw=1)
            ax[row].axhline(dim, color="gray", lw=0.5)
            ax[row].set_ylabel(f"NEES ({label})")
            ax[row].legend(loc="best", fontsize=8)
        ax[1].set_xlabel("t [s]")
        fig.suptitle(f"{name}: NEES over time")
        fig.tight_layout()
        fig.savefig(prefix + "_nees.png", dpi=120)
        plt.close(fig)
        print(f"plot_study_1d.py: wrote {name}_{{samples,errors,nees}}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
