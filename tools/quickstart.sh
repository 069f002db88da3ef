#!/usr/bin/env bash
# Installs dependencies, builds dmc (Release), makes a built-in example sequence, and runs the
# main job on it, printing a summary. Outputs go to ./out (override with DMC_OUT).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${DMC_BUILD_DIR:-$root/build}"
out="${DMC_OUT:-$root/out}"

"$root/tools/install-deps.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDMC_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target dmc_cli
dmc="$build/bin/dmc"
mkdir -p "$out"

echo "== generating the built-in 'walker' example"
"$dmc" synth walker -o "$out/walker.pc2" --frames 60 --resolution 4000
echo "== info"
"$dmc" info "$out/walker.pc2"
echo "== converting to a directory of OBJ frames and validating it"
"$dmc" convert "$out/walker.pc2" -o "$out/walker_obj"
"$dmc" info "$out/walker_obj"
echo "== done: outputs in $out"
