#!/usr/bin/env bash
# ctest driver of the WebAssembly decoder's tests (registered in tests/CMakeLists.txt as
# web.conformance): builds it with web/build.sh into BUILD_DIR/web, then runs conformance.mjs over
# conformance/vectors in Node. Exits 77 (ctest: skipped) when emscripten or node is missing.
#   run.sh BUILD_DIR
set -euo pipefail
build=$(cd "${1:?build dir}" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
command -v emcmake >/dev/null || { echo "SKIPPED: emscripten not installed"; exit 77; }
command -v node >/dev/null || { echo "SKIPPED: node not installed"; exit 77; }
"$source_dir/web/build.sh" "$build/web" >/dev/null
wasm="$build/web/package/dmc_decoder.wasm"
echo "dmc_decoder.wasm $(stat -c %s "$wasm") bytes, $(gzip -9 -c "$wasm" | wc -c) gzipped;" \
     "dmc_decoder.js + dmc.js $(cat "$build/web/package/dmc_decoder.js" "$build/web/package/dmc.js" | gzip -9 | wc -c) gzipped"
node "$here/conformance.mjs" "$build/web/package" "$source_dir/conformance/vectors"
