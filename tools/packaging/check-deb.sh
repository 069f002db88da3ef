#!/usr/bin/env bash
# The Debian package as a user gets it: `cpack -G DEB` of a build, installed with apt-get into a
# clean Debian 12 root (debootstrap --variant=minbase, from deb.debian.org), where the packaged
# dmc runs the README's first commands: synth, encode, decode, info, and its man page and bash
# completion are in place. Needs root (chroot) and the network (the root and the package's
# dependencies). Usage: tools/packaging/check-deb.sh BUILD_DIR
set -euo pipefail
build="$(cd "$1" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "check-deb: $*" >&2; exit 1; }
command -v debootstrap >/dev/null || fail "debootstrap is not installed (tools/install-deps.sh)"

cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/package" >"$work/cpack.log" 2>&1 ||
  { cat "$work/cpack.log" >&2; fail "cpack failed"; }
deb=$(ls "$work"/package/dmc_*.deb)
echo "check-deb: $(basename "$deb"), $(stat -c %s "$deb") bytes"
dpkg-deb --field "$deb" Depends

# A machine that cannot build the root (no network to deb.debian.org, no chroot) cannot run this
# check: that is a skip (exit 77, ctest's SKIP_RETURN_CODE), not a failure of the package.
if ! debootstrap --variant=minbase bookworm "$work/root" http://deb.debian.org/debian \
  >"$work/debootstrap.log" 2>&1; then
  tail -5 "$work/debootstrap.log" >&2
  echo "check-deb: skipped: debootstrap could not build a Debian 12 root here" >&2
  exit 77
fi
cp /etc/resolv.conf "$work/root/etc/resolv.conf"
cp "$deb" "$work/root/tmp/"
chroot "$work/root" /bin/sh -euc "
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq /tmp/$(basename "$deb") >/tmp/apt.log 2>&1 ||
    { tail -20 /tmp/apt.log; exit 1; }
  dmc --version
  dmc synth cloth -o /tmp/cloth.pc2 --frames 8 --resolution 500
  dmc encode /tmp/cloth.pc2 -o /tmp/cloth.dmc
  dmc decode /tmp/cloth.dmc -o /tmp/decoded.pc2
  dmc info /tmp/cloth.dmc
  dmc metrics /tmp/cloth.pc2 /tmp/decoded.pc2
  test -s /usr/share/man/man1/dmc.1
  test -s /usr/share/bash-completion/completions/dmc
  test -s /usr/share/doc/dmc/LICENSE
  test -e /usr/lib/libdmc_decoder.so.0
" || fail "the packaged dmc did not run in a clean Debian 12"
echo "check-deb: the package installs on a clean Debian 12 and its dmc runs"
