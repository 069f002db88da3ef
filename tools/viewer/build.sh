#!/usr/bin/env bash
# Builds the viewer into OUTDIR (index.html + viewer.js, three.js bundled by esbuild; no CDN).
# npm packages are installed with `npm ci` from the committed package-lock.json into a work
# directory under OUTDIR's parent, never into the source tree.
# Usage: tools/viewer/build.sh OUTDIR        (e.g. build/bin/viewer, where `dmc view` looks)
set -euo pipefail
out=${1:?usage: build.sh OUTDIR}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
out=$(cd "$out" && pwd)
work="$out/../viewer-npm"
mkdir -p "$work"
cp "$here/package.json" "$here/package-lock.json" "$work/"
rm -rf "$work/src" && cp -r "$here/src" "$work/src"
# npm ci only when the lock file changed since the last install.
if ! cmp -s "$here/package-lock.json" "$work/node_modules/.dmc-lock" 2>/dev/null; then
  (cd "$work" && npm ci --no-audit --no-fund --loglevel=error)
  cp "$here/package-lock.json" "$work/node_modules/.dmc-lock"
fi
(cd "$work" && ./node_modules/.bin/esbuild src/main.js --bundle --minify --format=esm \
   --log-level=warning --outfile="$out/viewer.js")
cp "$here/index.html" "$out/index.html"
# The WebAssembly decoder (web/build.sh), when WEB_PACKAGE (default: <build>/web/package beside
# OUTDIR's parent) holds it: dmc view then has the page decode the stream.
web_package=${WEB_PACKAGE:-"$out/../../web/package"}
rm -rf "$out/wasm"
if [ -f "$web_package/dmc_decoder.wasm" ]; then
  mkdir -p "$out/wasm"
  cp "$web_package/dmc.js" "$web_package/dmc_decoder.js" "$web_package/dmc_decoder.wasm" "$out/wasm/"
  echo "viewer built in $out, with the WebAssembly decoder"
else
  echo "viewer built in $out (no WebAssembly decoder: build it with web/build.sh)"
fi
