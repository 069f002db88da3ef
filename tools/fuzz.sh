#!/usr/bin/env bash
# Coverage-guided fuzzing of every target in tests/fuzz with libFuzzer (clang-14, ASan + UBSan;
# the "fuzz" preset of CMakePresets.json), for a bounded time each. Fails when any target
# crashes, leaks, times out or runs out of memory; the inputs that did are copied into a crasher
# directory printed at the end.
#
# Usage: tools/fuzz.sh [seconds]
#   seconds   time for each of the two main targets, decode_fuzz and codec_roundtrip_fuzz
#             (default 60); every other target gets half of it. With the default the fuzzing
#             itself takes 7 × 30 + 2 × 60 = 330 s.
# Environment:
#   DMC_FUZZ_BUILD_DIR    build directory (default build-libfuzzer next to the sources); its
#                         corpus/ subdirectory keeps what the fuzzers learnt between runs
#   DMC_FUZZ_CRASH_DIR    where crashers go (default <build>/crashers/<UTC time>)
#   DMC_FUZZ_TARGETS      space-separated subset of targets to run (default: all)
#   DMC_FUZZ_JOBS         build parallelism (default nproc)
#
# A crasher replays outside libFuzzer with the target's replay driver or the fuzzer itself:
#   <build>/tests/fuzz/decode_fuzz CRASHER
# and shrinks with
#   <build>/tests/fuzz/decode_fuzz -minimize_crash=1 -max_total_time=60 CRASHER
# Once the bug is fixed, add the minimised input to conformance/vectors/invalid (see
# conformance/README.md) or tests/fuzz/corpus/<target>/ so that it stays a regression test.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${DMC_FUZZ_BUILD_DIR:-$root/build-libfuzzer}"
main_seconds="${1:-60}"
other_seconds=$((main_seconds / 2 > 0 ? main_seconds / 2 : 1))
crash_dir="${DMC_FUZZ_CRASH_DIR:-$build/crashers/$(date -u +%Y%m%dT%H%M%SZ)}"
jobs="${DMC_FUZZ_JOBS:-$(nproc)}"
all_targets=(decode_fuzz codec_roundtrip_fuzz decode_rechecksum_fuzz stream_info_fuzz
  connectivity_fuzz connectivity_roundtrip_fuzz obj_fuzz ply_fuzz pc2_fuzz glb_fuzz)
read -r -a targets <<<"${DMC_FUZZ_TARGETS:-${all_targets[*]}}"

if ! command -v clang++-14 >/dev/null; then
  echo "fuzz: clang++-14 not found (tools/install-deps.sh installs clang-14 and libclang-rt-14-dev)" >&2
  exit 2
fi

# The "fuzz" preset of CMakePresets.json: the library is instrumented for coverage too
# (fuzzer-no-link); only the fuzz binaries link libFuzzer's main. UBSan does not recover, so
# undefined behaviour is a crash like any other.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
cmake -S "$root" --preset fuzz -B "$build" >/dev/null
start=$SECONDS
cmake --build "$build" --target "${targets[@]}" -j "$jobs"
echo "fuzz: build took $((SECONDS - start)) s"

# quarantine_size_mb: ASan holds freed memory this long to catch use after free; its default
# (256 MB) alone would take half of the decode targets' memory limit below.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0:quarantine_size_mb=64}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"

# Seeds: the checked-in corpus of each target, plus the valid conformance vectors (their .dmc
# streams, not the manifests and reference positions beside them) for the targets that read
# .dmc streams.
vector_seeds="$build/seeds/valid_vectors"
rm -rf "$vector_seeds"
mkdir -p "$vector_seeds"
cp "$root"/conformance/vectors/valid/*.dmc "$root"/conformance/vectors/invalid/*.dmc "$vector_seeds/"
seed_dirs() {
  local target="$1"
  echo "$root/tests/fuzz/corpus/$target"
  case "$target" in
    decode_fuzz | decode_rechecksum_fuzz | stream_info_fuzz) echo "$vector_seeds" ;;
  esac
}

start=$SECONDS
failed=()
for target in "${targets[@]}"; do
  seconds="$other_seconds"
  case "$target" in decode_fuzz | codec_roundtrip_fuzz) seconds="$main_seconds" ;; esac
  corpus="$build/corpus/$target"
  artifacts="$build/artifacts/$target"
  mkdir -p "$corpus" "$artifacts"
  log="$build/logs/$target.log"
  mkdir -p "$(dirname "$log")"
  mapfile -t seeds < <(seed_dirs "$target")
  echo "fuzz: $target for ${seconds} s (log $log)"
  # -timeout: one input taking longer is a hang. Memory: the decode targets cap what a stream
  # may declare (fuzz_support.h: 16 MB of output, 32 MB of normal equations) and inputs are at
  # most 16 KB, so the decoder's bound (spec §11.4) keeps every allocation under 64 MB
  # (-malloc_limit_mb) and the process, sanitizer included, under 512 MB (-rss_limit_mb); the
  # file parsers and round trips get 1 GB for both. -reload=0: new inputs come from this process
  # only.
  rss_limit_mb=1024 malloc_limit_mb=1024
  case "$target" in
    decode_fuzz | decode_rechecksum_fuzz | stream_info_fuzz) rss_limit_mb=512 malloc_limit_mb=64 ;;
  esac
  status=0
  "$build/tests/fuzz/$target" -max_total_time="$seconds" -timeout=25 -rss_limit_mb="$rss_limit_mb" \
    -malloc_limit_mb="$malloc_limit_mb" \
    -max_len=16384 -print_final_stats=1 -reload=0 -artifact_prefix="$artifacts/" \
    "$corpus" "${seeds[@]}" >"$log" 2>&1 || status=$?
  grep -E "^(stat::peak_rss_mb|Done [0-9]+ runs)" "$log" |
    sed "s/^/fuzz:   /" || true
  if [ "$status" -ne 0 ]; then
    failed+=("$target")
    mkdir -p "$crash_dir/$target"
    cp "$artifacts"/* "$crash_dir/$target/" 2>/dev/null || true
    cp "$log" "$crash_dir/$target/"
    echo "fuzz: $target FAILED (exit $status):"
    grep -E "^(==[0-9]+==ERROR|SUMMARY|.*runtime error)" "$log" | head -5 | sed "s/^/fuzz:   /" ||
      true
  fi
  rm -f "$artifacts"/*
done

echo "fuzz: fuzzing took $((SECONDS - start)) s"
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz: ${#failed[@]} target(s) failed: ${failed[*]}"
  echo "fuzz: crashers and logs in $crash_dir"
  exit 1
fi
echo "fuzz: all ${#targets[@]} targets ran clean"
