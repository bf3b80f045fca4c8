#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in their own build folder, writes the
# seed corpora from the simulator and runs every target for SECONDS (default 60) each.
#   scripts/fuzz.sh [SECONDS] [BUILD_DIR]        (default build dir: build-fuzz)
#   CTLIO_FUZZ_TARGETS="pcd table" scripts/fuzz.sh 600   runs a subset, 10 minutes each
# Memory is bounded (-rss_limit_mb=1024, and with it -malloc_limit_mb): every input is < 64 KiB, so
# a reader that needs 1 GB has allocated from a count the input cannot hold — a finding.
# The corpus grows in BUILD_DIR/corpus/<target> across runs; a crash or sanitizer report stops
# the script with the reproducer in BUILD_DIR/artifacts/ (rerun: BUILD_DIR/fuzz/fuzz_<target>
# <file>).
#   CTLIO_FUZZ_TESTS="io_dataset_test io_pcd_hardening_test"   also builds these gtest targets in
# the same instrumented tree and runs them (ASan + UBSan) before fuzzing: CI does this for the
# reader tests, which costs a few test files more than the fuzz build, not a second build.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
build_dir=${2:-build-fuzz}
# rosbag: RosbagSource over Debian's uninstrumented librosbag, behind ctlio's bag structure check
# (docs/developer-guide/fuzzing.md); 5 minutes clean when it was added.
# pointcloud2: structure-aware, edits the decoded fields of a simulated PointCloud2 message.
# cdr_messages: the ROS 2 message decoders (cdr_messages.h) on arbitrary bytes, type by first byte.
# mcap, ros2_sqlite: the ROS 2 bag containers (apps/io/ros2), seeded by ctlio's own writers.
targets=${CTLIO_FUZZ_TARGETS:-"pcd ply kitti_bin table trajectory sim_folder newer_college kitti_folder yaml_config euroc rosbag pointcloud2 cdr_messages mcap ros2_sqlite"}
bash scripts/install_deps.sh

start=$(date +%s)
tests=${CTLIO_FUZZ_TESTS:-}
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
  -DCTLIO_FUZZ=ON -DCTLIO_BUILD_TESTS="$([ -n "$tests" ] && echo ON || echo OFF)" \
  -DCTLIO_BUILD_BENCHMARKS=OFF \
  ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER} >/dev/null
# shellcheck disable=SC2086  # the test list is a word list
cmake --build "$build_dir" -j"$(nproc)" --target fuzz_all $tests
echo "fuzz: build done in $(( $(date +%s) - start )) s"

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The listed gtest executables (<part>_<name>, in build/test/<part>/) under the sanitizers, each
# from its own folder as ctest runs them.
for t in $tests; do
  exe=$(find "$build_dir/test" -type f -name "$t" -perm -u+x | head -n 1)
  if [ -z "$exe" ]; then
    echo "fuzz: test target $t was not built"
    exit 1
  fi
  echo "fuzz: $t under ASan + UBSan"
  if ! (cd "$(dirname "$exe")" && "./$t" --gtest_brief=1); then
    echo "fuzz: $t FAILED under the sanitizers"
    exit 1
  fi
done

corpus="$build_dir/corpus"
artifacts="$build_dir/artifacts"
mkdir -p "$corpus" "$artifacts"
"$build_dir/fuzz/fuzz_make_seeds" "$corpus" "$PWD"
for t in $targets; do
  mkdir -p "$corpus/$t"
  # Inputs that once crashed a target stay in its corpus (fuzz/regressions/<target>_*).
  for f in fuzz/regressions/"${t}"_*; do [ -e "$f" ] && cp "$f" "$corpus/$t/"; done
  echo "fuzz: $t for $seconds s"
  log="$build_dir/fuzz_$t.log"
  if ! "$build_dir/fuzz/fuzz_$t" "$corpus/$t" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=1024 -max_len=65536 -print_final_stats=1 -artifact_prefix="$artifacts/$t-" \
    >"$log" 2>&1; then
    tail -n 60 "$log"
    echo "fuzz: $t FAILED (reproducer in $artifacts/, full log $log)"
    exit 1
  fi
  grep -E "^stat::(number_of_executed_units|peak_rss_mb)|^#[0-9]+ +DONE" "$log" | tr '\n' ' '
  echo
done
echo "fuzz: all targets ran $seconds s each without a finding ($(( $(date +%s) - start )) s in all)"
