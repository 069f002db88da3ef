#!/usr/bin/env bash
# Installs dependencies, checks that every tracked C++ file is clang-formatted, builds dmc with the
# "release" preset of CMakePresets.json (Release, warnings as errors, tests, benchmarks, fuzz
# replay drivers, Python module) and runs every test.
#
# Usage: tools/test.sh [extra ctest arguments]
#        tools/test.sh --check-format     only the formatting check
# Examples:
#   tools/test.sh -LE slow               skip the tests labelled "slow", the few that take many
#                                        times the others' second or two (install, browser, two
#                                        B-spline CLI tests; labels in tests/CMakeLists.txt).
#                                        CI runs them all.
#   tools/test.sh -R '^conformance\.'    only the conformance tests
#   ctest --test-dir build -LE slow -j2  skip them without rebuilding
# Environment:
#   DMC_BUILD_DIR   build directory (default build next to the sources, as the preset)
#   DMC_JOBS        build and test parallelism (default nproc)
# The compiler runs through ccache when it is installed (top-level CMakeLists.txt); CCACHE_BASEDIR
# defaults to the source tree so that two checkouts share cache entries.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${DMC_BUILD_DIR:-$root/build}"
jobs="${DMC_JOBS:-$(nproc)}"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"

# Every tracked C++ file must be as clang-format-14 leaves it with the repository's .clang-format.
# clang-format's own output differs between major versions, hence the pinned one. A vendored or
# generated directory opts out with a .clang-format of its own holding "DisableFormat: true".
check_format() {
  local clang_format
  clang_format="$(command -v clang-format-14 || true)"
  if [ -z "$clang_format" ]; then
    echo "test: clang-format-14 not found (tools/install-deps.sh installs it)" >&2
    return 2
  fi
  local files=() file
  if git -C "$root" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    while IFS= read -r file; do
      # A file deleted in the work tree but still in the index is not checked.
      if [ -f "$root/$file" ]; then files+=("$file"); fi
    done < <(git -C "$root" ls-files -- '*.cpp' '*.cc' '*.h' '*.hpp' '*.inl')
  else
    mapfile -t files < <(cd "$root" && find codec conformance examples python tests tools \
      -type f \( -name '*.cpp' -o -name '*.cc' -o -name '*.h' -o -name '*.hpp' -o -name '*.inl' \) |
      sort)
  fi
  local output status=0 unformatted
  output="$(cd "$root" && "$clang_format" --dry-run -Werror "${files[@]}" 2>&1)" || status=$?
  if [ "$status" -ne 0 ]; then
    unformatted="$(grep -o '^[^:]*:[0-9]*:[0-9]*: error: code should be clang-formatted' \
      <<<"$output" | cut -d: -f1 | sort -u)"
    if [ -n "$unformatted" ]; then
      echo "test: not clang-formatted (fix with clang-format-14 -i FILE):" >&2
      sed 's/^/  /' <<<"$unformatted" >&2
    else
      echo "test: clang-format failed: $output" >&2
    fi
    return 1
  fi
  echo "test: ${#files[@]} C++ files clang-formatted"
}

"$root/tools/install-deps.sh"
check_format
if [ "${1:-}" = "--check-format" ]; then exit 0; fi

cmake -S "$root" --preset release -B "$build" >/dev/null
start=$SECONDS
cmake --build "$build" -j "$jobs"
echo "test: build took $((SECONDS - start)) s"
start=$SECONDS
ctest --test-dir "$build" --output-on-failure -j "$jobs" "$@"
echo "test: tests took $((SECONDS - start)) s"
