#!/usr/bin/env bash
# Installs a built dmc into a temporary prefix and uses it as a consumer would:
#  - examples/embed (dmc::dmc) and examples/decode (dmc::decoder) built with find_package(dmc)
#    and run; the decoder example also built with pkg-config's dmc-decoder;
#  - the package is relocatable: no absolute library path in its CMake files, and it is used
#    from a prefix it was not configured for;
#  - in a shared build (BUILD_SHARED_LIBS) the decoder example needs libdmc_decoder.so only, and
#    the libraries export the public API alone (no internal namespace, no third-party symbol);
#  - the man page, the bash completion and the licence files are installed.
# Usage: tools/check-install.sh BUILD_DIR
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "check-install: $*" >&2; exit 1; }
cmake --install "$build" --prefix "$work/prefix" >/dev/null
prefix="$work/prefix"
libdir=$(dirname "$(find "$prefix" -name dmcConfig.cmake -printf '%h')")
libdir=$(dirname "$libdir")  # .../lib[/multiarch]/cmake/dmc -> .../lib[/multiarch]

if grep -n '/usr/lib\|/usr/local/lib' "$libdir"/cmake/dmc/dmcTargets*.cmake; then
  fail "dmcTargets.cmake names absolute library paths (above)"
fi

cmake -S "$root/examples/embed" -B "$work/embed" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/embed" -j "$(nproc)" >/dev/null
"$work/embed/embed"

# A stream to play: the embed example's own kind of input, from the installed tool.
"$prefix/bin/dmc" synth cloth -o "$work/cloth.pc2" --frames 3 --resolution 200 >/dev/null
"$prefix/bin/dmc" encode "$work/cloth.pc2" -o "$work/cloth.dmc" >/dev/null
cmake -S "$root/examples/decode" -B "$work/decode" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/decode" -j "$(nproc)" >/dev/null
"$work/decode/decode" "$work/cloth.dmc" | grep -Eq "^[0-9]+ vertices, [0-9]+ triangles, 3 frames$" ||
  fail "the decoder example did not decode the cloth"

export PKG_CONFIG_PATH="$libdir/pkgconfig"
pkg-config --exists dmc dmc-decoder || fail "pkg-config does not find dmc and dmc-decoder"
[ "$(pkg-config --modversion dmc)" = "$("$prefix/bin/dmc" --version | cut -d' ' -f2)" ] ||
  fail "dmc.pc's version is not dmc --version's"
# shellcheck disable=SC2046  # pkg-config's flags are words
c++ -std=c++20 -O1 "$root/examples/decode/main.cpp" -o "$work/decode_pc" \
  $(pkg-config --cflags --libs dmc-decoder) -Wl,-rpath,"$libdir"
"$work/decode_pc" "$work/cloth.dmc" | grep -Eq "^[0-9]+ vertices, [0-9]+ triangles, 3 frames$" ||
  fail "the pkg-config build of the decoder example did not decode the cloth"

if [ -e "$libdir/libdmc_decoder.so" ]; then
  needed=$(readelf -d "$work/decode/decode" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p')
  grep -qx 'libdmc_decoder.so.[0-9]*' <<<"$needed" || fail "decode does not need libdmc_decoder: $needed"
  if grep -q '^libdmc\.so' <<<"$needed"; then fail "decode needs the whole libdmc"; fi
  for library in "$libdir"/libdmc.so "$libdir"/libdmc_decoder.so; do
    exported=$(nm -D --defined-only -C "$library" | awk '$2 ~ /^[TWVBDR]$/ {$1 = ""; $2 = ""; print}')
    leaked=$(grep -v -E '^ +(dmc::|typeinfo (name )?for dmc::|vtable for dmc::|DMC_0)' <<<"$exported" | head -5 || true)
    [ -z "$leaked" ] || fail "$(basename "$library") exports symbols outside dmc::: $leaked"
    internal=$(grep -E '^ +dmc::(format|syntax|connectivity|[a-z_]*_internal|N_[A-Z0-9]*)::' <<<"$exported" | head -5 || true)
    [ -z "$internal" ] || fail "$(basename "$library") exports internal symbols: $internal"
  done
fi

[ -s "$prefix/share/man/man1/dmc.1" ] || fail "no man page"
for command in encode decode info sweep; do
  grep -q "^\.SS $command\$" "$prefix/share/man/man1/dmc.1" || fail "the man page lacks $command"
done
grep -q "complete -o filenames -F _dmc dmc" "$prefix/share/bash-completion/completions/dmc" ||
  fail "no bash completion"
for file in LICENSE NOTICE licenses/README.md licenses/eigen.copyright; do
  [ -s "$prefix/share/doc/dmc/$file" ] || fail "share/doc/dmc/$file is not installed"
done
echo "check-install: the installed package works (bpfv, KG printed above)"
