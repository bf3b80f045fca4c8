#!/usr/bin/env python3
"""Bad-input probe: mutates a short simulated recording in the ways real recordings go wrong and
runs ctlio_odometry on each mutant (docs/user-guide/bad-input.md).

Each run is classified:
  error            exit != 0 with a message that names the input (file, flag or key)
  run_failed       exit != 0 after the run: evaluation.txt written, the run reported failed
  error_unnamed    exit != 0, the message names no input (a finding)
  warned           exit 0 and evaluation.txt reports the defect (a count or a warning line)
  accurate         exit 0, no warning, ATE within 3x the clean run's (the defect did no harm)
  crash            killed by a signal (a finding)
  hang             no exit within the timeout (a finding)
  nan_exit0        exit 0 with NaN or Inf in the trajectory or the ATE (a finding)
  silent_wrong     exit 0, ATE above 3x the clean run's, no warning in evaluation.txt (a finding)
  memory           peak resident memory above 1 GB (a finding)
  sanitizer        an AddressSanitizer / UndefinedBehaviorSanitizer report (a finding; with
                   --odometry pointing at an instrumented build)
The findings are the outcomes the bad-input promise rules out ("never crashes, never lies").

  python3 tools/bad_input_probe.py --build build-test --out /tmp/probe [--seed 7] [--only imu]
  # a sample of 40 cases under ASan + UBSan (the programs of scripts/fuzz.sh's instrumented tree):
  python3 tools/bad_input_probe.py --odometry build-fuzz/apps/lio/ctlio_odometry --sample 40 ...
  # the readers alone under the sanitizers: every scan of each mutated folder or bag decoded by
  # ctlio_geometry_report (the readers and their checks, no estimator; outcomes error / read):
  python3 tools/bad_input_probe.py --reader build-fuzz/apps/ctlio_geometry_report ...

The bag mutations run on a ROS 1 bag (class `bag`) and on ROS 2 bag folders with MCAP
(`ros2_mcap`) and SQLite (`ros2_sqlite3`) storage, the layouts ctlio_simulate writes.

Writes <out>/probe.csv (one line per mutant) and prints the count per class and outcome.
The mutants are drawn from --seed; a different seed gives mutants the tests never saw.
"""
import argparse
import csv
import math
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import time

FINDINGS = {"error_unnamed", "crash", "hang", "nan_exit0", "silent_wrong", "memory", "sanitizer"}
SANITIZER_MARKS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:",
                   "UndefinedBehaviorSanitizer")
WARN_COUNTERS = ("failed_scans", "imu_gap_scans", "imu_samples_rejected",
                 "points_dropped_out_of_interval", "scans_skipped", "constant_imu_scans",
                 "lidar_gaps", "overlapping_scans")
WARN_KEYS = ("first_input_warning", "extrinsic_disagreement", "no_ate", "first_lidar_gap",
             "input_defect", "config_warning", "imu_inconsistency", "frame_inconsistency",
             "degenerate_run", "accel_relabelling", "reference_disagreement")


# The mutations live in their own module beside this one.
from bad_input_mutations import (FLAG_MUTATIONS, bag_mutations, config_mutations,
                                 folder_mutations, mutate_bytes, read_lines, ros2_mutations,
                                 ros2_storage_file)


# ---------------------------------------------------------------- running and judging
def run(cmd, timeout, log_path):
    """(exit code or None on timeout, log text, peak resident MB of the child, seconds)."""
    t0 = time.time()
    with open(log_path, "w") as log:
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, preexec_fn=os.setsid)
        while True:
            pid, status, usage = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            if time.time() - t0 > timeout:
                os.killpg(p.pid, signal.SIGKILL)
                os.wait4(p.pid, 0)
                return None, open(log_path, errors="replace").read(), 0, time.time() - t0
            time.sleep(0.05)
    p.returncode = -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)
    return (p.returncode, open(log_path, errors="replace").read(), usage.ru_maxrss / 1024.0,
            time.time() - t0)


def evaluation(out_dir):
    ev = {}
    for root, _, files in os.walk(out_dir):
        if "evaluation.txt" in files:
            for line in read_lines(os.path.join(root, "evaluation.txt")):
                k, _, v = line.partition(" ")
                ev[k] = v
    return ev


def trajectory_has_nan(out_dir):
    for root, _, files in os.walk(out_dir):
        for f in files:
            if f.startswith("trajectory") and f.endswith(".tum"):
                with open(os.path.join(root, f)) as fh:
                    for line in fh:
                        if re.search(r"nan|inf", line, re.I):
                            return True
    return False


def judge(rc, log, peak_mb, out_dir, names, clean_ate):
    if rc is None:
        return "hang", ""
    last = [l for l in log.splitlines() if l.strip()]
    msg = last[-1][:200] if last else ""
    for mark in SANITIZER_MARKS:
        i = log.find(mark)
        if i >= 0:
            return "sanitizer", log[i:i + 200]
    if peak_mb > 1024:
        return "memory", msg
    if rc < 0:
        return "crash", msg
    if rc != 0 and evaluation(out_dir):
        return "run_failed", msg
    if rc != 0:
        text = log[-2000:]
        named = any(n in text for n in names)
        return ("error" if named else "error_unnamed"), msg
    ev = evaluation(out_dir)
    ate = ev.get("ate_rmse_m")
    if trajectory_has_nan(out_dir) or (ate is not None and not math.isfinite(float(ate))):
        return "nan_exit0", msg
    warned = any(float(ev.get(k, "0") or 0) > 0 for k in WARN_COUNTERS) or any(
        k in ev for k in WARN_KEYS)
    if warned:
        return "warned", next((ev[k] for k in WARN_KEYS if k in ev), msg)[:200]
    if ate is not None and float(ate) > 3 * clean_ate:
        return "silent_wrong", f"ATE {float(ate):.4f} m vs clean {clean_ate:.4f} m"
    return "accurate", ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build-test")
    ap.add_argument("--out", default="/tmp/ctlio_probe")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--only", default="",
                    help="run only classes containing this text (several: comma-separated)")
    ap.add_argument("--timeout", type=float, default=180)
    ap.add_argument("--odometry", default="",
                    help="the ctlio_odometry to probe (default: <build>/apps/lio/ctlio_odometry); "
                    "an instrumented one makes sanitizer reports findings")
    ap.add_argument("--reader", default="",
                    help="instead of the odometry, read every scan with this ctlio_geometry_report "
                    "(the folder and bag classes only)")
    ap.add_argument("--sample", type=int, default=0,
                    help="run only this many cases, drawn from --seed (0: all)")
    ap.add_argument("--bag_layouts", default="rosbag,ros2,ros2_sqlite3",
                    help="bag layouts to mutate (ctlio_simulate --layout values)")
    ap.add_argument("--config", default=os.path.join(os.path.dirname(__file__), "..", "data",
                                                      "sim_lio.yaml"))
    a = ap.parse_args()
    rng = random.Random(a.seed)
    sim = os.path.join(a.build, "apps", "ctlio_simulate")
    odo = a.odometry or os.path.join(a.build, "apps", "lio", "ctlio_odometry")
    os.makedirs(a.out, exist_ok=True)
    clean = os.path.join(a.out, "clean")
    bag = os.path.join(a.out, "clean.bag")
    sim_args = ["--regime=medium", f"--index={200 + a.seed % 50}", "--duration=4", "--beams=32"]
    if not os.path.isdir(clean):
        subprocess.run([sim, *sim_args, f"--output={clean}"], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    layouts = [l for l in a.bag_layouts.split(",") if l]
    clean_bags = {"rosbag": bag, "ros2": os.path.join(a.out, "clean_ros2"),
                  "ros2_sqlite3": os.path.join(a.out, "clean_ros2_sqlite3")}
    for layout in layouts:
        if not os.path.exists(clean_bags[layout]):
            subprocess.run([sim, *sim_args, f"--layout={layout}",
                            f"--output={clean_bags[layout]}"], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    base = [odo, f"--config={a.config}", "--plot=false"]
    rc, log, _, _ = run(base + [f"--dataset={clean}", f"--out={a.out}/clean_run"], a.timeout,
                        os.path.join(a.out, "clean.log"))
    clean_ate = float(evaluation(f"{a.out}/clean_run")["ate_rmse_m"])
    print(f"clean run: ATE {clean_ate:.4f} m", flush=True)

    cases = []
    for cls, name, fn in folder_mutations(rng):
        cases.append((cls, name, "folder", fn))
    for cls, name, text in config_mutations(a.config):
        cases.append((cls, name, "config", text))
    for cls, name, flags in FLAG_MUTATIONS:
        cases.append((cls, name, "flags", flags))
    if "rosbag" in layouts:
        for cls, name, op in bag_mutations(rng, os.path.getsize(bag)):
            cases.append((cls, name, "bag", op))
    for layout, cls in (("ros2", "ros2_mcap"), ("ros2_sqlite3", "ros2_sqlite3")):
        if layout in layouts:
            for cls, name, op in ros2_mutations(rng, clean_bags[layout], cls):
                cases.append((cls, name, layout, op))
    cases = [c for c in cases if any(o in c[0] for o in a.only.split(","))]
    if a.reader:
        cases = [c for c in cases if c[2] not in ("config", "flags")]
    if a.sample and a.sample < len(cases):
        cases = [cases[i] for i in sorted(rng.sample(range(len(cases)), a.sample))]

    rows = []
    for i, (cls, name, kind, what) in enumerate(cases):
        work = os.path.join(a.out, "work")
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
        out_dir = os.path.join(work, "run")
        args = list(base)
        names = []
        if kind == "folder":
            d = os.path.join(work, "seq")
            shutil.copytree(clean, d)
            what(d)
            args.append(f"--dataset={d}")
            names = [d, "imu.csv", "scans.csv", ".bin", "ctlio_sim.yaml", "ground_truth"]
        elif kind == "config":
            cfg = os.path.join(work, "cfg.yaml")
            open(cfg, "w").write(what)
            args = [odo, f"--config={cfg}", "--plot=false", f"--dataset={clean}"]
            names = ["cfg.yaml", name.split("=")[0]]
        elif kind == "flags":
            args += [f"--dataset={clean}", *what]
            names = [f.split("=")[0].lstrip("-") for f in what]
        elif kind == "bag":
            b = os.path.join(work, "m.bag")
            open(b, "wb").write(mutate_bytes(open(bag, "rb").read(), what))
            args.append(f"--dataset={b}")
            names = ["m.bag"]
        else:
            d = os.path.join(work, "m_ros2")
            shutil.copytree(clean_bags[kind], d)
            f = ros2_storage_file(d)
            meta = os.path.join(d, "metadata.yaml")
            if what[0] in ("truncate", "flip"):
                data = open(f, "rb").read()
                open(f, "wb").write(mutate_bytes(data, what))
            elif what[0] == "metadata":
                if what[1] is None:
                    os.remove(meta)
                else:
                    open(meta, "w").write(what[1])
            elif what[0] == "metadata_sub":
                text = open(meta).read()
                assert what[1][0] in text, what
                open(meta, "w").write(text.replace(what[1][0], what[1][1]))
            else:
                os.remove(f)
            args.append(f"--dataset={d}")
            names = ["m_ros2", os.path.basename(f), "metadata.yaml"]
        args.append(f"--out={out_dir}")
        if a.reader:
            args = [a.reader, args[-2], "--first=1000000", "--scans=1000000"]
        rc, log, peak, secs = run(args, a.timeout, os.path.join(work, "log.txt"))
        outcome, msg = judge(rc, log, peak, out_dir, names, clean_ate)
        # Every scan decoded: ctlio_geometry_report then says it had fewer than the 10⁶ asked for.
        if a.reader and (outcome in ("accurate", "run_failed") or (
                outcome == "error" and "of the 1000000 sweeps asked for" in log)):
            outcome = "read"
        rows.append(dict(cls=cls, name=name, outcome=outcome, rc=rc, seconds=f"{secs:.1f}",
                         peak_mb=f"{peak:.0f}", message=msg.replace("\n", " ")))
        flag = "  <-- FINDING" if outcome in FINDINGS else ""
        print(f"[{i + 1}/{len(cases)}] {cls:13s} {name:32s} {outcome}{flag}", flush=True)

    with open(os.path.join(a.out, "probe.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    counts = {}
    for r in rows:
        counts.setdefault(r["cls"], {}).setdefault(r["outcome"], 0)
        counts[r["cls"]][r["outcome"]] += 1
    print("\nclass          cases  outcomes")
    for cls, c in counts.items():
        print(f"{cls:13s} {sum(c.values()):6d}  " +
              ", ".join(f"{k} {v}" for k, v in sorted(c.items())))
    top = max(rows, key=lambda r: float(r["peak_mb"]))
    print(f"\npeak resident memory: {top['peak_mb']} MB ({top['cls']} {top['name']}); longest run "
          f"{max(float(r['seconds']) for r in rows):.1f} s")
    findings = sum(1 for r in rows if r["outcome"] in FINDINGS)
    print(f"\n{len(rows)} mutants, {findings} findings; {a.out}/probe.csv")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
