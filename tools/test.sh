#!/usr/bin/env bash
# Installs dependencies, builds dmc (Release, warnings as errors) with tests, runs every test.
# Usage: tools/test.sh [extra ctest arguments]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${DMC_BUILD_DIR:-$root/build}"
jobs="$(nproc)"

# The Python module is built and tested once python/ exists.
python_option=()
if [ -f "$root/python/CMakeLists.txt" ]; then python_option=(-DDMC_BUILD_PYTHON=ON); fi

"$root/tools/install-deps.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDMC_WERROR=ON \
  -DDMC_BUILD_TESTS=ON -DDMC_BUILD_BENCH=ON -DDMC_BUILD_FUZZ=ON "${python_option[@]}"
cmake --build "$build" -j "$jobs"
ctest --test-dir "$build" --output-on-failure -j "$jobs" "$@"
