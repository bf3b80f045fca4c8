#!/usr/bin/env bash
# Installs dependencies, builds ctlio and runs every test with ctest.
#   scripts/test.sh [BUILD_DIR]       (default: build-test)
# The suite is built with clang++ (installed by install_deps.sh): on this code base it compiles in
# ~0.7x GCC's CPU time (Eigen/Ceres template instantiation), which keeps CI inside its budget.
# CTLIO_CXX=g++ builds it with GCC instead (a plain cmake uses the default compiler, GCC on
# Debian; the sanitized suite and CI's ThreadSanitizer pass use GCC).
# CTLIO_SANITIZE=1 builds with AddressSanitizer + UndefinedBehaviorSanitizer (GCC by default).
# CTLIO_BUILD_BENCHMARKS=OFF skips the Google Benchmark programs (they are not tests; CI skips them
# to stay inside its time budget).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build-test}
bash scripts/install_deps.sh

cxx=${CTLIO_CXX:-clang++}
# The sanitizer build's flags (-Og, CMakeLists.txt) were chosen with GCC, its default there.
if [ "${CTLIO_SANITIZE:-0}" = "1" ]; then cxx=${CTLIO_CXX:-g++}; fi
cmake_args=(-DCMAKE_BUILD_TYPE=Release -DCTLIO_BUILD_BENCHMARKS="${CTLIO_BUILD_BENCHMARKS:-ON}"
            -DCMAKE_CXX_COMPILER="$cxx")
if [ "${CTLIO_SANITIZE:-0}" = "1" ]; then
  cmake_args+=(-DCTLIO_SANITIZE=ON -DCTLIO_BUILD_BENCHMARKS=OFF)
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
fi
cmake -S . -B "$build_dir" "${cmake_args[@]}"
cmake --build "$build_dir" -j"$(nproc)"
ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)"
