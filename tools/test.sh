#!/usr/bin/env bash
# Installs dependencies, builds dmc (Release, warnings as errors) with tests, runs every test.
# Usage: tools/test.sh [extra ctest arguments]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${DMC_BUILD_DIR:-$root/build}"
jobs="$(nproc)"

"$root/tools/install-deps.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDMC_WERROR=ON \
  -DDMC_BUILD_TESTS=ON -DDMC_BUILD_BENCH=ON -DDMC_BUILD_FUZZ=ON
cmake --build "$build" -j "$jobs"
ctest --test-dir "$build" --output-on-failure -j "$jobs" "$@"
