#!/usr/bin/env bash
# Installs dependencies, builds ctlio and runs the main job.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
./build/apps/ctlio_demo
