#!/usr/bin/env bash
# Installs dependencies, builds ctlio and runs every test with ctest.
#   scripts/test.sh [BUILD_DIR]       (default: build)
# CTLIO_SANITIZE=1 builds with AddressSanitizer + UndefinedBehaviorSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
bash scripts/install_deps.sh

cmake_args=(-DCMAKE_BUILD_TYPE=Release)
if [ "${CTLIO_SANITIZE:-0}" = "1" ]; then
  cmake_args+=(-DCTLIO_SANITIZE=ON -DCTLIO_BUILD_BENCHMARKS=OFF)
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
fi
cmake -S . -B "$build_dir" "${cmake_args[@]}"
cmake --build "$build_dir" -j"$(nproc)"
ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)"
