#!/usr/bin/env bash
# The project's scoreboard (docs/experiments/scoreboard.md): Singer-LIO and the IMU-as-input
# baseline on sensors × worlds × motions, each cell one ctlio_experiment job with the sensor's
# shipped config (data/sensors/<sensor>.yaml), pooled by ctlio_scoreboard into OUT/scoreboard.md
# and OUT/scoreboard.csv, plotted by tools/plot_scoreboard.py into OUT/scoreboard.png.
#
#   scripts/scoreboard.sh OUT [BUILD_DIR]
#
# Settings (environment): SEQUENCES (10), FIRST_SEQUENCE (0: the reported indices; tuning used
# 100+), DURATION (20 s), THREADS (2), GRID (full | core | a space-separated list of
# sensor:world:motion cells), SENSORS (the sensors of the core part; default all eight). The full
# scoreboard is the defaults: GRID=full SEQUENCES=10 DURATION=20. A cell whose OUT/cells/<cell>/
# results.csv exists is not run again (an interrupted run resumes); delete it to re-run the cell.
#
# The grid (only world × motion pairs a sensor is carried through in practice):
#   core, every sensor: walking in quad and office, handheld fast in office and box,
#                       vehicle in town
#   older worlds, one sensor per class (os1_64, vlp16, mid360): walking in park, handheld fast in
#                       corridor and indoor, vehicle in street and park
set -euo pipefail
out=${1:?usage: scripts/scoreboard.sh OUT [BUILD_DIR]}
build=${2:-build-test}
root=$(cd "$(dirname "$0")/.." && pwd)
exe=$build/apps/lio/ctlio_experiment
board=$build/apps/lio/ctlio_scoreboard
for e in "$exe" "$board"; do
  [[ -x $e ]] || { echo "scoreboard.sh: $e not built (cmake --build $build --target $(basename "$e"))" >&2; exit 2; }
done
sequences=${SEQUENCES:-10}
first=${FIRST_SEQUENCE:-0}
duration=${DURATION:-20}
threads=${THREADS:-2}
grid=${GRID:-full}
sensors=${SENSORS:-"os0_128 os1_64 os1_128 vlp16 hdl32e pandar_xt32 mid360 avia"}

cells=()
if [[ $grid == full || $grid == core ]]; then
  for s in $sensors; do
    for wm in quad:walking office:walking office:fast box:fast town:vehicle; do
      cells+=("$s:$wm")
    done
  done
  if [[ $grid == full ]]; then
    for s in os1_64 vlp16 mid360; do
      for wm in park:walking corridor:fast indoor:fast street:vehicle park:vehicle; do
        cells+=("$s:$wm")
      done
    done
  fi
else
  read -r -a cells <<< "$grid"
fi

mkdir -p "$out/cells"
start=$(date +%s)
n=${#cells[@]}
k=0
for cell in "${cells[@]}"; do
  k=$((k + 1))
  IFS=: read -r sensor world motion <<< "$cell"
  dir=$out/cells/${sensor}_${world}_${motion}
  if [[ -f $dir/results.csv ]]; then
    echo "[$k/$n] $cell: done before, kept"
    continue
  fi
  t0=$(date +%s)
  if ! "$exe" --out "$dir.tmp" --sim_sensor "$sensor" --world "$world" --regimes "$motion" \
      --methods singer_lio,imu_input --sequences "$sequences" --first_sequence "$first" \
      --duration "$duration" --threads "$threads" > "$out/cells/${sensor}_${world}_${motion}.log" 2>&1; then
    echo "scoreboard.sh: cell $cell failed; see $out/cells/${sensor}_${world}_${motion}.log" >&2
    exit 1
  fi
  rm -rf "$dir" && mv "$dir.tmp" "$dir"
  now=$(date +%s)
  line=$(grep -E "^\| $motion \| (singer_lio|imu_input) " "$dir/table.md" |
         awk -F'|' '{printf "%s %s cm, ", $3, 100*$7}')
  echo "[$k/$n] $cell: $((now - t0)) s ($line elapsed $((now - start)) s, about $(( (now - start) * (n - k) / k )) s left)"
done

note="Command: \`SEQUENCES=$sequences FIRST_SEQUENCE=$first DURATION=$duration GRID=\"$grid\" scripts/scoreboard.sh OUT\`; wall time $(( $(date +%s) - start )) s on $threads threads (cells run before were kept)."
"$board" --cells_under "$out/cells" --out "$out" --note "$note"
if /usr/bin/python3 -c "import matplotlib" 2> /dev/null; then
  /usr/bin/python3 "$root/tools/plot_scoreboard.py" "$out/scoreboard.csv" "$out/scoreboard.png"
else
  echo "scoreboard.sh: no matplotlib for /usr/bin/python3; skipped the plot" >&2
fi
