#!/usr/bin/env python3
"""Lists the scoreboard cells where Singer-LIO misses its target, with the numbers a diagnosis
starts from (docs/experiments/scoreboard.md, "Where Singer-LIO loses").

Reads OUT/scoreboard.csv (ctlio_scoreboard) and each cell's OUT/cells/<cell>/results.csv
(ctlio_experiment), prints one Markdown row per missed cell: ATE Singer-LIO / baseline, their
ratio, the CPU ratio, failed runs, degenerate-direction scans summed over the runs, and Singer-LIO's
worst run. The cause column is left for the person who diagnoses it.

  /usr/bin/python3 tools/scoreboard_losses.py OUT
"""
import csv
import os
import sys


def cell_runs(path):
    with open(path, newline="") as f:
        return [r for r in csv.DictReader(f) if r["scenario"] == "none"]


def main(argv):
    if len(argv) != 2:
        sys.exit("usage: scoreboard_losses.py OUT (the folder of scripts/scoreboard.sh)")
    out = argv[1]
    board = os.path.join(out, "scoreboard.csv")
    if not os.path.isfile(board):
        sys.exit(f"scoreboard_losses.py: {board}: not found (run scripts/scoreboard.sh first)")
    with open(board, newline="") as f:
        cells = list(csv.DictReader(f))
    print("| cell | ATE Singer-LIO / baseline [cm] | ratio | CPU ratio | failed runs S / B "
          "| degenerate-direction scans S / B | worst Singer-LIO run | cause |")
    print("|---|---|---|---|---|---|---|---|")
    missed = 0
    for c in cells:
        if c["target_met"] == "1":
            continue
        missed += 1
        name = f"{c['sensor']}_{c['world']}_{c['regime']}"
        results = os.path.join(out, "cells", name, "results.csv")
        if not os.path.isfile(results):
            sys.exit(f"scoreboard_losses.py: {results}: not found (cell of {board})")
        runs = cell_runs(results)
        degenerate = {m: sum(int(r["degenerate_direction_scans"]) for r in runs if r["method"] == m)
                      for m in ("singer_lio", "imu_input")}
        singer = [r for r in runs if r["method"] == "singer_lio"]
        worst = max(singer, key=lambda r: float(r["ate_rmse_m"]))
        s, b = float(c["singer_ate_rms_m"]), float(c["baseline_ate_rms_m"])
        ratio = f"{s / b:.2f}" if b > 0 else "n/a"
        print(f"| {c['sensor']} {c['world']} {c['regime']} | {100 * s:.2f} / {100 * b:.2f} | "
              f"{ratio} | {float(c['cpu_ratio']):.2f} | {c['singer_failed_runs']} / "
              f"{c['baseline_failed_runs']} | {degenerate['singer_lio']} / "
              f"{degenerate['imu_input']} | seq {worst['sequence']}: "
              f"{100 * float(worst['ate_rmse_m']):.2f} cm |  |")
    print(f"\n{missed} of {len(cells)} cells miss the target.")


if __name__ == "__main__":
    main(sys.argv)
