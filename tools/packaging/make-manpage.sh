#!/usr/bin/env bash
# Writes dmc.1, the man page, from the built tool's own --help and --version (so it cannot drift
# from the CLI). Usage: make-manpage.sh DMC OUTPUT
set -euo pipefail
dmc="$1"
out="$2"
version=$("$dmc" --version | sed -n '1s/^dmc \([0-9.]*\).*/\1/p')
commands=$("$dmc" --help | sed -n '/^Subcommands:/,$p' | sed -n 's/^  \([a-z][a-z]*\)  .*/\1/p')
# roff: a leading dot or quote starts a request, a backslash an escape.
escape() { sed -e 's/\\/\\e/g' -e 's/^\([.'"'"']\)/\\\&\1/'; }
tmp="$out.tmp"
{
  echo ".TH DMC 1 \"\" \"dmc $version\" \"User Commands\""
  echo ".SH NAME"
  echo "dmc \\- compress, decode, measure and process dynamic meshes"
  echo ".SH SYNOPSIS"
  echo ".B dmc"
  echo ".I command"
  echo "[options]"
  echo ".SH DESCRIPTION"
  echo "dmc is a codec for animated triangle meshes whose connectivity is fixed and whose vertex"
  echo "positions change every frame. Each command below prints its own help with"
  echo ".BR \"dmc \\fIcommand\\fP \\-\\-help\" ."
  echo ".PP"
  echo ".B dmc \\-\\-version"
  echo "prints the version and the SIMD variant in use;"
  echo ".B DMC_SIMD"
  echo "in the environment forces one (avx512, avx2, sse4, ssse3, baseline)."
  echo ".SH COMMANDS"
  for command in $commands; do
    echo ".SS $command"
    echo ".nf"
    "$dmc" "$command" --help | sed "s|^Usage: [^ ]*dmc |Usage: dmc |" | escape
    echo ".fi"
  done
  echo ".SH EXIT STATUS"
  echo "0 on success, 1 for a usage error, 10 + the error code for a codec error (printed as"
  echo ".IR \"dmc command\" \": error: \" \"name\" \": message\""
  echo "on standard error)."
  echo ".SH FILES"
  echo "The licence texts are in the package's documentation directory (LICENSE, NOTICE, licenses/)."
} >"$tmp"
mv "$tmp" "$out"
