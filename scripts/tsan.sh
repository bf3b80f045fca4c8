#!/usr/bin/env bash
# ThreadSanitizer over ParallelFor's persistent pool (solvers/src/parallel_for.cc), the one piece
# of ctlio that synchronises threads by hand (atomics, a claimed-chunk ticket, spin-then-sleep
# helpers): its test program built with -fsanitize=thread and run REPEAT times (default 20).
# Small on purpose (one source and its test, seconds); the pipeline's use of it is checked for
# bit-identical results by lio.LioPipeline.FrontendThreadsAndVoxelPlanes.
#   scripts/tsan.sh [REPEAT] [OUT_DIR]     (default out dir: build-tsan)
set -euo pipefail
cd "$(dirname "$0")/.."
repeat=${1:-20}
out=${2:-build-tsan}
bash scripts/install_deps.sh
mkdir -p "$out"
g++ -std=c++17 -O1 -g -fsanitize=thread -Isolvers/include solvers/src/parallel_for.cc \
  test/solvers/parallel_for_test.cc -lgtest -lgtest_main -pthread -o "$out/parallel_for_test"
TSAN_OPTIONS=halt_on_error=1 "$out/parallel_for_test" --gtest_repeat="$repeat" --gtest_brief=1
echo "tsan: ParallelFor clean over $repeat repetitions"
