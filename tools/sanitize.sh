#!/usr/bin/env bash
# Builds the tests with AddressSanitizer and UndefinedBehaviorSanitizer (-O1, frame pointers kept)
# in a separate build directory, configured by the "asan" preset of CMakePresets.json, and runs
# the whole ctest suite there. Any sanitizer report aborts the test that triggered it, so the run
# fails.
#
# Usage: tools/sanitize.sh [extra ctest arguments]
# Environment:
#   DMC_ASAN_BUILD_DIR   build directory (default build-asan next to the sources, as the preset)
#   DMC_ASAN_CXX         compiler (default the preset's g++; clang++-14 works too)
#   DMC_ASAN_JOBS        build and test parallelism (default nproc)
#   DMC_ASAN_TARGETS     space-separated build targets (default: all); with a subset, select the
#                        matching tests too, e.g.
#     DMC_ASAN_TARGETS="dmc_conformance_tests dmc_conform" tools/sanitize.sh -R '^conformance\.'
#   DMC_ASAN_EXCLUDE_LABELS  ctest -LE regex (default no-sanitize); 'no-sanitize|slow' also skips
#                        the tests labelled slow (see tools/test.sh), which CI runs
#
# Tests labelled "no-sanitize" are skipped: the ones too slow under ASan to be worth their time
# there (they still run unsanitized in tools/test.sh). The fuzz targets build as their replay
# drivers only (gcc), so the checked-in fuzz corpora are replayed sanitized too; coverage-guided
# fuzzing is tools/fuzz.sh. No benchmarks, and no Python module: it would need the sanitizer
# runtime preloaded into the interpreter.
#
# The preset's flags, and why: -fno-sanitize-recover makes undefined behaviour abort like a memory
# error instead of printing and carrying on. NDEBUG as in a release build, so the suite checks the
# code that ships; -g1 gives reports file:line stacks at a fraction of full debug info's build
# cost. Warnings are not errors here: tools/test.sh enforces them, and gcc's sanitizer
# instrumentation raises false positives (-Wmaybe-uninitialized, -Wstringop-overflow) that would
# fail the build for nothing.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${DMC_ASAN_BUILD_DIR:-$root/build-asan}"
jobs="${DMC_ASAN_JOBS:-$(nproc)}"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"

compiler=()
if [ -n "${DMC_ASAN_CXX:-}" ]; then compiler=(-DCMAKE_CXX_COMPILER="$DMC_ASAN_CXX"); fi
cmake -S "$root" --preset asan -B "$build" "${compiler[@]}" >/dev/null
read -r -a targets <<<"${DMC_ASAN_TARGETS:-all}"
start=$SECONDS
cmake --build "$build" -j "$jobs" --target "${targets[@]}"
echo "sanitize: build took $((SECONDS - start)) s"

# The environment and test selection below are the "asan" test preset's; keep the two in step.
# halt_on_error/abort_on_error: the first report kills the process (a failed test, whatever the
# test itself checks). detect_leaks: a leak fails the test at exit.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_init_order=1:check_initialization_order=1"
export UBSAN_OPTIONS="halt_on_error=1:abort_on_error=1:print_stacktrace=1"
# Tests that start the dmc binary inherit these too, so the CLI tests are sanitized as well.
# install.find_package_example is left out: it builds an unsanitized program against the
# sanitized libraries, which cannot link.
start=$SECONDS
ctest --test-dir "$build" --output-on-failure -j "$jobs" \
  -LE "${DMC_ASAN_EXCLUDE_LABELS:-no-sanitize}" -E '^install\.' --timeout 1500 "$@"
echo "sanitize: tests took $((SECONDS - start)) s"
