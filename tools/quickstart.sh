#!/usr/bin/env bash
# Installs dependencies, builds dmc (Release), makes a built-in example animation, compresses and
# decompresses it, and prints a summary. Outputs go to ./out (override with DMC_OUT).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${DMC_BUILD_DIR:-$root/build}"
out="${DMC_OUT:-$root/out}"

"$root/tools/install-deps.sh"
# The "release" preset, as tools/test.sh, so the two can share one build directory.
cmake -S "$root" --preset release -B "$build" >/dev/null
cmake --build "$build" -j "$(nproc)" --target dmc_cli
dmc="$build/bin/dmc"
mkdir -p "$out"

echo "== 1. a built-in example: 'walker', an articulated figure animated by skinning"
"$dmc" synth walker -o "$out/walker.pc2" --frames 120 --resolution 8000
"$dmc" info "$out/walker.pc2"
echo "== 2. encode (trajectory PCA -> data-dependent Laplacian -> high-pass quantisation)"
"$dmc" encode "$out/walker.pc2" -o "$out/walker.dmc"
echo "== 3. decode to a directory of OBJ frames"
"$dmc" decode "$out/walker.dmc" -o "$out/walker_decoded"
echo "== 4. distortion of the decoded frames against the original"
"$dmc" metrics "$out/walker.pc2" "$out/walker_decoded"
echo "== done: outputs in $out"
