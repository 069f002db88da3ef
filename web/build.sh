#!/usr/bin/env bash
# Builds the WebAssembly decoder (web/CMakeLists.txt) with Debian's Emscripten into BUILD_DIR
# (default build-web beside the sources): BUILD_DIR/dmc_decoder.{js,wasm}, the ES module that
# web/dmc.js loads, and BUILD_DIR/package, the npm package (dmc.js and the module). The decoder halves of Draco, Highway and zstd are compiled from Debian's
# source packages (the same versions the native build links), fetched once into BUILD_DIR/deps
# with `apt-get source` (deb-src for bookworm is added when missing). Eigen and xxhash are
# header-only, staged from the host's packages.
# Usage: web/build.sh [BUILD_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-"$here/../build-web"}
mkdir -p "$build"
build=$(cd "$build" && pwd)
deps="$build/deps"
command -v emcmake >/dev/null || { echo "web/build.sh: emscripten is not installed (apt-get install emscripten node-acorn)"; exit 1; }
# Emscripten's JS optimiser requires acorn, which Debian installs under /usr/share/nodejs.
export NODE_PATH=/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}

if [ ! -f "$deps/.ready" ]; then
  mkdir -p "$deps" && cd "$deps"
  if ! apt-get source --download-only --print-uris draco >/dev/null 2>&1; then
    cat > /etc/apt/sources.list.d/dmc-deb-src.sources <<'SRC'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
    apt-get update -qq
  fi
  apt-get source --download-only draco highway zstd >/dev/null 2>&1
  for archive in draco_*.orig.tar.* highway_*.orig.tar.* libzstd_*.orig.tar.*; do
    case "$archive" in *.asc) continue ;; esac
    tar xf "$archive"
  done
  mkdir -p include
  ln -sfn /usr/include/eigen3/Eigen include/Eigen
  cp /usr/include/xxhash.h include/
  touch .ready
fi

emcmake cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DDMC_WEB_DEPS="$deps" >/dev/null
cmake --build "$build" -j"$(nproc)"
# The npm package, assembled in BUILD_DIR/package (never in the source tree).
mkdir -p "$build/package"
cp "$here/package.json" "$here/dmc.js" "$here/dmc.d.ts" "$here/DMCLoader.js" "$here/DMCLoader.d.ts" \
  "$here/dmc_worker.js" \
  "$build/dmc_decoder.js" "$build/dmc_decoder.wasm" \
  "$build/package/"
# Licences: dmc's, and those of what the module compiles in (licenses/README.md).
root=$(cd "$here/.." && pwd)
mkdir -p "$build/package/licenses"
cp "$root/LICENSE" "$root/NOTICE" "$build/package/"
for component in eigen draco zstd highway xxhash; do
  cp "$root/licenses/$component.copyright" "$build/package/licenses/"
done
cp /usr/share/doc/emscripten/copyright "$build/package/licenses/emscripten.copyright"
ls -l "$build/package"
