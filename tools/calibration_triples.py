#!/usr/bin/env python3
"""Calibration triples of docs/experiments/calibration.md ("Current state"): per simulated regime,
sequence index and method, (1) a run calibrating from the wrong start (3 deg / 10 cm / 20 ms off),
(2) the same data with the written calibration.yaml layered on top and estimation off ("pasted"),
(3) the true values with estimation off; then the page's table from the outputs.

  tools/calibration_triples.py run --out DIR --regimes walking,medium,fast --indices 0-9 \
      --methods singer_lio,imu_input --workers 2
  tools/calibration_triples.py table --out DIR [--indices 0-9] [--runs] [--plot PNG]

Run from the repository root (configs data/sim_lio.yaml,data/calibration.yaml, or --config with a
variant on top). Each triple goes to DIR/REGIME/INDEX/METHOD/{cal,pasted,true}; finished runs are
skipped, so a run can be resumed.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

OFF = """calibration:
  estimate_time_offset: false
  estimate_extrinsic: false
  warmup_replay_s: 0.0
  warmup_replay_passes: 1
  warmup_replay_hold: false
"""
TRUE_OFFSET = "calibration:\n  time_offset_s: [0.02]\n"  # the true extrinsic is the identity
BASE = "data/sim_lio.yaml,data/calibration.yaml"
TARGETS = (0.5, 0.1, 1.0)  # ms, deg, cm (the issue's)
# The written calibration's kinds in TARGETS' order: summary key, plot marker, name, unit.
KINDS = (("dt", "o", "clock offset", "ms"), ("deg", "^", "rotation", "°"),
         ("cm", "s", "lever arm", "cm"))


def target_text(j):
    """The target of KINDS[j] as written: 0.5 ms, 0.1°, 1 cm."""
    unit = KINDS[j][3]
    return f"{TARGETS[j]:g}{'' if unit == '°' else ' '}{unit}"
PASTED_WITHIN = 0.1  # the pasted run's ATE within 10 % of the true values' (the issue's)


def indices(text):
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b) + 1)) if b else [int(a)]
    return out


def run_triple(args, regime, index, method):
    d = os.path.join(args.out, regime, str(index), method)
    os.makedirs(d, exist_ok=True)
    sim = ["--format", "sim", "--sim_regime", regime, "--sim_index", str(index),
           "--sim_duration", str(args.duration), "--sim_beams", "16",
           "--sim_firing_decimation", "4", "--sim_imu_stamp_offset", "0.02", "--method", method,
           "--plot=false", "--progress=false"]
    wrong = ["--sim_extrinsic_error=3deg,0.10m"]
    off, true_offset = os.path.join(args.out, "off.yaml"), os.path.join(args.out, "true_off.yaml")
    base = args.config
    runs = [("cal", wrong + ["--config", base] + args.cal_args.split()),
            ("pasted", wrong + ["--config", ",".join([base, off, os.path.join(d, "cal",
                                                                               "calibration.yaml")])]),
            ("true", ["--config", ",".join([base, off, true_offset])])]
    for name, extra in runs:
        if name not in args.kinds.split(","):
            continue
        if os.path.exists(os.path.join(d, name, "evaluation.txt")):
            continue
        with open(os.path.join(d, name + ".log"), "w") as log:
            rc = subprocess.call([args.binary] + sim + extra + ["--out", os.path.join(d, name)],
                                 stdout=log, stderr=subprocess.STDOUT)
        if rc != 0:
            print(f"{regime}/{index} {method} {name}: exit {rc} (see {d}/{name}.log)", flush=True)
            return
    print(f"{regime}/{index} {method} done", flush=True)


def evaluation(path):
    out = {}
    try:
        with open(path) as f:
            for line in f:
                key, _, value = line.strip().partition(" ")
                out[key] = value
    except FileNotFoundError:
        return None
    return out


def written_errors(path):
    """calibration.yaml's comments: the clock offset's and the extrinsic's written error."""
    text = open(path).read()
    dt = re.search(r"# time_offset_0 \[ms\].*?off by ([-0-9.e+]+)\)", text, re.S)
    ext = re.search(r"The extrinsic written is off the truth by ([-0-9.e+]+) cm, ([-0-9.e+]+) deg",
                    text)
    kept = len(re.findall(r"#   why\s+the start", text))
    return abs(float(dt.group(1))), float(ext.group(2)), float(ext.group(1)), kept


def scan_cpu(path):
    """Per-scan CPU [ms] of scans.log (column cpu_ms), initialising scans left out, and the index
    of the scan that adopted the warm-up replay (its message says so; None without a replay)."""
    cpu, adopting = [], None
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                continue
            fields = line.split()
            if fields[1] != "initialising":
                if "warm-up replayed" in line:
                    adopting = len(cpu)
                cpu.append(float(fields[14]))
    return cpu, adopting


def summary(out, regime, index, method):
    d = os.path.join(out, regime, str(index), method)
    cal, pasted, true = (evaluation(os.path.join(d, k, "evaluation.txt"))
                         for k in ("cal", "pasted", "true"))
    if not (cal and pasted and true and "ate_rmse_m" in pasted and "ate_rmse_m" in true):
        return None
    dt, deg, cm, kept = written_errors(os.path.join(d, "cal", "calibration.yaml"))
    (cpu_cal, adopting), (cpu_true, _) = (scan_cpu(os.path.join(d, k, "scans.log"))
                                          for k in ("cal", "true"))
    live = [c for i, c in enumerate(cpu_cal) if i != adopting]
    return dict(index=index, dt=dt, deg=deg, cm=cm, kept=kept,
                ok=dt <= TARGETS[0] and deg <= TARGETS[1] and cm <= TARGETS[2],
                pasted=100 * float(pasted["ate_rmse_m"]), true=100 * float(true["ate_rmse_m"]),
                median_cal=float(cal["median_cpu_ms"]), median_true=float(true["median_cpu_ms"]),
                # The scan that adopts the replay (at the end of the input, after the last live
                # output, or --warmup_replay_adopt_after_s after the span) has the replay's CPU in
                # its cpu_ms: the live thread's longest is taken without it, the total with it.
                longest=max(live), total_ratio=(sum(cpu_cal) / len(cpu_cal)) /
                (sum(cpu_true) / len(cpu_true)),
                replay_s=float(cal.get("warmup_replay_cpu_ms", "nan")) / 1000)


def table(args):
    print(f"| regime, method | runs (sequences) | written within "
          f"{' / '.join(target_text(j) for j in range(len(KINDS)))} | written error max: δ / "
          "rotation / lever arm | coordinates kept at the start | ATE pasted ÷ true values, per run "
          f"(within {PASTED_WITHIN * 100:g} %) | ATE true values, mean | CPU per scan: calibrating "
          "/ without (median of runs) | live thread: longest scan CPU | replay CPU |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    plotted = []
    for regime in args.regimes.split(","):
        for method in args.methods.split(","):
            rows = [r for r in (summary(args.out, regime, i, method) for i in indices(args.indices))
                    if r]
            if not rows:
                continue
            ratios = [r["pasted"] / r["true"] for r in rows]
            median_cal = statistics.median(r["median_cal"] for r in rows)
            median_true = statistics.median(r["median_true"] for r in rows)
            live = [r["median_cal"] / r["median_true"] for r in rows]
            total = [r["total_ratio"] for r in rows]
            print(f"| {regime}, {method} | {len(rows)} ({','.join(str(r['index']) for r in rows)}) "
                  f"| {sum(r['ok'] for r in rows)}/{len(rows)} | "
                  f"{max(r['dt'] for r in rows):.3f} ms / {max(r['deg'] for r in rows):.3f}° / "
                  f"{max(r['cm'] for r in rows):.2f} cm | {sum(r['kept'] for r in rows)} of "
                  f"{7 * len(rows)} | {', '.join('%.2f' % x for x in ratios)} "
                  f"({sum(abs(x - 1) <= PASTED_WITHIN for x in ratios)}/{len(rows)}) | "
                  f"{statistics.mean(r['true'] for r in rows):.3f} cm | {median_cal:.1f} / "
                  f"{median_true:.1f} ms ({median_cal / median_true:.2f}×; runs "
                  f"{min(live):.2f}–{max(live):.2f}×; with the replay {min(total):.2f}–"
                  f"{max(total):.2f}×) | {max(r['longest'] for r in rows):.0f} ms | "
                  f"{statistics.median(r['replay_s'] for r in rows):.1f} s |")
            plotted.append((regime, method, rows, ratios))
            if args.runs:
                for r, x in zip(rows, ratios):
                    print(f"  {regime}/{r['index']} {method}: written {r['dt']:.3f} ms "
                          f"{r['deg']:.3f}° {r['cm']:.2f} cm{'' if r['ok'] else ' (miss)'}, "
                          f"pasted {r['pasted']:.3f} / true {r['true']:.3f} cm = {x:.2f}, "
                          f"longest live scan {r['longest']:.0f} ms")
    if args.plot and plotted:
        plot(args.plot, plotted)


def plot(path, plotted):
    """Per run: the written error of each kind over its target, and the pasted ÷ true ATE."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for k, (regime, method, rows, ratios) in enumerate(plotted):
        x = [k + 0.8 * (i / max(1, len(rows) - 1) - 0.5) for i in range(len(rows))]
        for j, ((key, marker, name, _), target) in enumerate(zip(KINDS, TARGETS)):
            a.scatter(x, [r[key] / target for r in rows], marker=marker, s=14, color=f"C{j}",
                      label=f"{name} / {target_text(j)}" if k == 0 else None)
        b.scatter(x, ratios, s=14, color="k")
    labels = [f"{regime}\n{method}" for regime, method, _, _ in plotted]
    for ax in (a, b):
        ax.set_xticks(range(len(plotted)))
        ax.set_xticklabels(labels, fontsize=8)
    a.axhline(1.0, color="r", lw=0.8)
    a.set_ylabel("written error ÷ target")
    a.set_title("written calibration, per run (target: below 1)")
    a.legend(fontsize=8)
    b.axhspan(1 - PASTED_WITHIN, 1 + PASTED_WITHIN, color="g", alpha=0.15, lw=0)
    b.set_ylabel("ATE pasted ÷ ATE true values")
    b.set_title("pasted run, per run (target: within the band)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("mode", choices=("run", "table"))
    p.add_argument("--out", required=True)
    p.add_argument("--regimes", default="walking,medium,fast")
    p.add_argument("--indices", default="0-9", help="e.g. 0-9 or 310,311")
    p.add_argument("--methods", default="singer_lio,imu_input")
    p.add_argument("--duration", type=float, default=60.0, help="seconds (the page's: 60)")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--binary", default="build/apps/lio/ctlio_odometry")
    p.add_argument("--runs", action="store_true", help="table: one line per run as well")
    p.add_argument("--plot", default="", help="table: a PNG of the per-run written errors and "
                   "pasted ÷ true ATE")
    p.add_argument("--kinds", default="cal,pasted,true",
                   help="run: which runs of each triple (a variant of the calibrating configs can "
                   "share the true-value runs of another directory: link them into DIR)")
    p.add_argument("--cal_args", default="",
                   help="run: more flags of the calibrating run, e.g. "
                   "'--warmup_replay_adopt_after_s 6'")
    p.add_argument("--config", default=BASE,
                   help="run: the configs of every run (off.yaml and the rest come after them)")
    args = p.parse_args()
    if args.mode == "table":
        table(args)
        return 0
    if not os.path.exists(args.binary):
        sys.exit(f"--binary {args.binary}: not found (build ctlio_odometry first)")
    os.makedirs(args.out, exist_ok=True)
    for name, text in (("off.yaml", OFF), ("true_off.yaml", TRUE_OFFSET)):
        with open(os.path.join(args.out, name), "w") as f:
            f.write(text)
    # Methods outermost, so that the first method's triples finish first.
    jobs = [(r, i, m) for m in args.methods.split(",") for i in indices(args.indices)
            for r in args.regimes.split(",")]
    with ThreadPoolExecutor(max_workers=args.workers) as pool:
        list(pool.map(lambda job: run_triple(args, *job), jobs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
