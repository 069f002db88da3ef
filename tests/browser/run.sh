#!/usr/bin/env bash
# ctest driver of the browser-side tests (registered in tests/CMakeLists.txt):
#   run.sh validate BUILD_DIR SHARED_DATA_DIR   Khronos glTF validator on dmc's GLB exports
#   run.sh viewer   BUILD_DIR SHARED_DATA_DIR   headless chromium against `dmc view`
#   run.sh player   BUILD_DIR SHARED_DATA_DIR   three.js's GLTFLoader playing dmc's GLB output
#   run.sh loader   BUILD_DIR SHARED_DATA_DIR   web/DMCLoader.js playing a .dmc in three.js (needs
#                                               emscripten for web/build.sh)
#   run.sh types    BUILD_DIR                   tsc --strict on web/test/types_check.ts against the
#                                               package's .d.ts files and @types/three
# npm packages come from the committed package-lock.json files through `npm ci` into BUILD_DIR
# (never into the source tree). Exits 77 (ctest: skipped) when node/npm or chromium is missing or
# the npm registry cannot be reached.
set -euo pipefail
mode=${1:?usage: run.sh validate|viewer|player|loader|types BUILD_DIR SHARED_DATA_DIR}
build=$(cd "${2:?build dir}" && pwd)
shared=${3:-}
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
dmc="$build/bin/dmc"
skip() { echo "SKIPPED: $*"; exit 77; }

command -v node >/dev/null && command -v npm >/dev/null || skip "node/npm not installed"
[ -x "$dmc" ] || { echo "no dmc binary at $dmc"; exit 1; }

work="$build/browser-tests"
mkdir -p "$work"
cp "$here/package.json" "$here/package-lock.json" "$here"/*.mjs "$work/"
if ! cmp -s "$here/package-lock.json" "$work/node_modules/.dmc-lock" 2>/dev/null; then
  (cd "$work" && npm ci --no-audit --no-fund --loglevel=error) || skip "npm ci failed (registry unreachable?)"
  cp "$here/package-lock.json" "$work/node_modules/.dmc-lock"
fi

if [ "$mode" = types ]; then
  # The declarations beside a file that uses them, as in the package; three's types from the
  # lock file's @types/three (found in $work/node_modules).
  types="$work/types"
  rm -rf "$types" && mkdir -p "$types"
  cp "$source_dir/web/dmc.d.ts" "$source_dir/web/DMCLoader.d.ts" "$source_dir/web/test/types_check.ts" "$types/"
  cat >"$types/tsconfig.json" <<'JSON'
{ "compilerOptions": { "strict": true, "noEmit": true, "target": "es2022", "module": "es2022",
                       "moduleResolution": "bundler", "lib": ["es2022", "dom"], "types": [] },
  "files": ["types_check.ts"] }
JSON
  (cd "$types" && "$work/node_modules/.bin/tsc" -p tsconfig.json)
  echo "types_check.ts compiles against dmc.d.ts and DMCLoader.d.ts"
  exit 0
fi

# A small synthetic animation, encoded and decoded: the files under test.
data="$work/data-$mode"
rm -rf "$data" && mkdir -p "$data"
"$dmc" synth cloth -o "$data/cloth" --frames 12 --resolution 400 >/dev/null
"$dmc" encode "$data/cloth" -o "$data/cloth.dmc" >/dev/null

case "$mode" in
  validate)
    # Every layout in every encoding. The validator cannot decode EXT_meshopt_compression (it
    # checks the compact files' structure only), so the quantized files, the same data without
    # meshopt, are what checks the quantised accessors' contents.
    files=()
    for layout in basis morph frames auto; do
      for encoding in compact quantized float; do
        [ "$layout-$encoding" = basis-float ] && continue  # refused: basis targets are quantised
        out="$data/cloth-$layout-$encoding.glb"
        "$dmc" decode "$data/cloth.dmc" -o "$out" --glb-layout "$layout" --glb-encoding "$encoding" >/dev/null
        files+=("$out")
      done
    done
    # Real skinned and morph-target samples: imported and written back out (float32), and
    # encoded with their scene and decoded in every encoding, when present; the decoded scene is
    # compared with the input (compare_scene.mjs).
    compare=()
    for sample in cesium-man/CesiumMan.glb threejs-horse-morph/Horse.glb fox/Fox.glb \
                  robot-expressive/RobotExpressive.glb; do
      if [ -n "$shared" ] && [ -f "$shared/$sample" ]; then
        name=$(basename "$sample" .glb)
        "$dmc" convert "$shared/$sample" -o "$data/$name-export.glb" --max-frames 20 >/dev/null
        files+=("$data/$name-export.glb")
        "$dmc" encode "$shared/$sample" -o "$data/$name.dmc" >/dev/null
        fps=$("$dmc" info "$data/$name.dmc" --json | node -e 'let s="";process.stdin.on("data",d=>s+=d).on("end",()=>console.log(JSON.parse(s).frame_rate))')
        for encoding in compact quantized float; do
          "$dmc" decode "$data/$name.dmc" -o "$data/$name-$encoding.glb" --glb-encoding "$encoding" >/dev/null
          files+=("$data/$name-$encoding.glb")
        done
        # Both scene layouts without meshopt, so the validator checks their contents.
        for layout in basis morph; do
          "$dmc" decode "$data/$name.dmc" -o "$data/$name-$layout-quantized.glb" \
            --glb-layout "$layout" --glb-encoding quantized >/dev/null
          files+=("$data/$name-$layout-quantized.glb")
          compare+=("$shared/$sample|$data/$name-$layout-quantized.glb|$fps")
        done
      fi
    done
    (cd "$work" && node validate_glb.mjs "${files[@]}")
    for item in "${compare[@]}"; do
      IFS='|' read -r original decoded fps <<<"$item"
      echo "== $(basename "$original") against $(basename "$decoded")"
      (cd "$work" && node compare_scene.mjs "$original" "$decoded" "$fps")
    done
    ;;
  viewer)
    [ -x /usr/bin/chromium ] || skip "/usr/bin/chromium not installed"
    # With emscripten the page decodes the stream with the WebAssembly decoder (and must).
    expect_wasm=0
    if command -v emcmake >/dev/null; then
      "$source_dir/web/build.sh" "$build/web" >/dev/null
      expect_wasm=1
    fi
    "$source_dir/tools/viewer/build.sh" "$build/bin/viewer" >/dev/null \
      || skip "viewer build failed (npm registry unreachable?)"
    "$dmc" view "$data/cloth.dmc" --original "$data/cloth" --port 0 --json --exit-after 240 \
      >"$data/view.json" 2>"$data/view.err" &
    server=$!
    trap 'kill "$server" 2>/dev/null || true' EXIT
    url=""
    for _ in $(seq 1 200); do
      url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$data/view.json" 2>/dev/null || true)
      [ -n "$url" ] && break
      kill -0 "$server" 2>/dev/null || { cat "$data/view.err"; exit 1; }
      sleep 0.1
    done
    [ -n "$url" ] || { echo "dmc view printed no URL"; cat "$data/view.err"; exit 1; }
    mkdir -p "$build/test-artifacts"
    (cd "$work" && DMC_EXPECT_WASM=$expect_wasm node viewer_test.mjs "$url" "$build/test-artifacts/viewer.png")
    ;;
  player)
    # three.js's GLTFLoader (+ MeshoptDecoder) plays dmc's GLB output in headless chromium.
    [ -x /usr/bin/chromium ] || skip "/usr/bin/chromium not installed"
    "$source_dir/tools/viewer/build.sh" "$build/bin/viewer" >/dev/null \
      || skip "viewer build failed (npm registry unreachable?)"
    npm_dir="$build/bin/viewer-npm"  # three.js and esbuild, installed by the viewer's build
    cp "$here/gltf_player.js" "$npm_dir/src/gltf_player.js"
    (cd "$npm_dir" && ./node_modules/.bin/esbuild src/gltf_player.js --bundle --format=esm \
       --log-level=warning --outfile="$data/gltf_player.bundle.js")
    cp "$here/gltf_player.html" "$data/"
    cases=()
    for encoding in compact quantized float; do
      "$dmc" decode "$data/cloth.dmc" -o "$data/cloth-$encoding.glb" --glb-encoding "$encoding" >/dev/null
      cases+=("cloth-$encoding.glb:1")
    done
    for sample in cesium-man/CesiumMan.glb fox/Fox.glb; do
      if [ -n "$shared" ] && [ -f "$shared/$sample" ]; then
        name=$(basename "$sample" .glb)
        "$dmc" encode "$shared/$sample" -o "$data/$name.dmc" >/dev/null
        "$dmc" decode "$data/$name.dmc" -o "$data/$name.glb" >/dev/null
        "$dmc" decode "$data/$name.dmc" -o "$data/$name-float.glb" --float >/dev/null
        "$dmc" decode "$data/$name.dmc" -o "$data/$name-morph.glb" --glb-layout morph >/dev/null
        clips=$("$dmc" info "$data/$name.dmc" --json | node -e 'let s="";process.stdin.on("data",d=>s+=d).on("end",()=>console.log(JSON.parse(s).clips.length))')
        # The default (basis) and the morph layout, each against the float32 file.
        cases+=("$name-float.glb:$clips" "$name.glb:$clips:$name-float.glb"
                "$name-morph.glb:$clips:$name-float.glb")
      fi
    done
    (cd "$work" && node gltf_player_test.mjs "$data" "${cases[@]}")
    ;;
  loader)
    # web/DMCLoader.js with the WebAssembly decoder, in headless chromium, in both modes.
    [ -x /usr/bin/chromium ] || skip "/usr/bin/chromium not installed"
    command -v emcmake >/dev/null || skip "emscripten not installed (web/build.sh)"
    "$source_dir/tools/viewer/build.sh" "$build/bin/viewer" >/dev/null \
      || skip "viewer build failed (npm registry unreachable?)"
    "$source_dir/web/build.sh" "$build/web" >/dev/null
    npm_dir="$build/bin/viewer-npm"  # three.js and esbuild, installed by the viewer's build
    rm -rf "$npm_dir/src/package" && cp -r "$build/web/package" "$npm_dir/src/package"
    cp "$here/dmc_loader_page.js" "$npm_dir/src/dmc_loader_page.js"
    (cd "$npm_dir" && ./node_modules/.bin/esbuild src/dmc_loader_page.js --bundle --format=esm --external:node:* \
       --log-level=warning --outfile="$data/dmc_loader.bundle.js")
    cp "$build/web/package/dmc_decoder.wasm" "$here/dmc_loader.html" "$data/"
    rm -rf "$data/package" && cp -r "$build/web/package" "$data/package"  # the worker's modules
    cases=("cloth.dmc:morph" "cloth.dmc:buffer")
    if [ -n "$shared" ] && [ -f "$shared/cesium-man/CesiumMan.glb" ]; then
      "$dmc" encode "$shared/cesium-man/CesiumMan.glb" -o "$data/CesiumMan.dmc" >/dev/null
      cases+=("CesiumMan.dmc:morph" "CesiumMan.dmc:buffer")
    fi
    # The README's whole page, with three's build beside it.
    mkdir -p "$data/example"
    cp "$source_dir/web/example/index.html" "$npm_dir/node_modules/three/build/three.module.js" \
      "$npm_dir/node_modules/three/build/three.core.js" "$data/example/"
    rm -rf "$data/example/package" && cp -r "$build/web/package" "$data/example/package"
    cases+=("example:../cloth.dmc")
    (cd "$work" && node dmc_loader_test.mjs "$data" "${cases[@]}")
    ;;
  *) echo "unknown mode $mode"; exit 2 ;;
esac
