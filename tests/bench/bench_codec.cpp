// Codec speed: encode and decode of a real 10k-vertex performance capture (samba, when
// ../shared/data is present) and of a synthetic stand-in of the same size otherwise.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <vector>

#include "bench/bench_support.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/io.h"
#include "dmc/synth.h"

namespace {

const dmc::MeshSequence& BenchSequence() {
  static const dmc::MeshSequence sequence = [] {
    const std::filesystem::path samba = std::filesystem::path(DMC_SHARED_DATA_DIR) / "samba";
    if (std::filesystem::exists(samba)) {
      auto read = dmc::ReadSequence(samba);
      if (read.ok()) return *read;
    }
    dmc::SynthOptions options;
    options.frames = 30;
    options.resolution = 10000;
    return *dmc::Synthesize("walker", options);
  }();
  return sequence;
}

void BM_Encode(benchmark::State& state) {
  const dmc::MeshSequence& sequence = BenchSequence();
  dmc::EncoderOptions options;
  options.measure = false;
  for (auto _ : state) {
    auto bytes = dmc::Encode(sequence, options);
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["vertices"] = sequence.vertex_count();
  state.counters["frames"] = sequence.frame_count();
}
BENCHMARK(BM_Encode)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_Decode(benchmark::State& state) {
  const dmc::MeshSequence& sequence = BenchSequence();
  dmc::EncoderOptions options;
  options.measure = false;
  const auto bytes = *dmc::Encode(sequence, options);
  for (auto _ : state) {
    auto decoded = dmc::Decode(bytes);
    benchmark::DoNotOptimize(decoded);
  }
  state.counters["bpfv"] =
      8.0 * static_cast<double>(bytes.size()) / (sequence.frame_count() * sequence.vertex_count());
  dmc::bench::LabelSimdVariant(state);
}
BENCHMARK(BM_Decode)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// The speed target: a 10k-vertex × 175-frame sequence at rank 60 decodes in ≤ 0.15 s and
// encodes in ≤ 2 s (no measuring) on 2 cores. A synthetic walker stands in for a capture.
const dmc::MeshSequence& TargetSequence() {
  static const dmc::MeshSequence sequence = [] {
    dmc::SynthOptions options;
    options.frames = 175;
    options.resolution = 10000;
    return *dmc::Synthesize("walker", options);
  }();
  return sequence;
}

dmc::EncoderOptions TargetOptions(int rank = 60) {
  dmc::EncoderOptions options;
  options.measure = false;
  options.rank = rank;
  return options;
}

void BM_EncodeTarget(benchmark::State& state) {
  const dmc::MeshSequence& sequence = TargetSequence();
  for (auto _ : state) {
    auto bytes = dmc::Encode(sequence, TargetOptions());
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["vertices"] = sequence.vertex_count();
  state.counters["frames"] = sequence.frame_count();
}
BENCHMARK(BM_EncodeTarget)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(4.0);

// The default encode (automatic rank, measured) at each effort level (the argument) on the 10k ×
// 175 walker: the time of the search each level does, with the rate and STED it reached.
void BM_EncodeEffort(benchmark::State& state) {
  const dmc::MeshSequence& sequence = TargetSequence();
  dmc::EncoderOptions options;
  options.effort = static_cast<int>(state.range(0));
  dmc::EncodeReport report;
  dmc::bench::PeakMemory memory;
  for (auto _ : state) {
    auto bytes = dmc::Encode(sequence, options, &report);
    if (!bytes.ok()) state.SkipWithError(bytes.status().ToString().c_str());
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["bpfv"] = report.bpfv;
  state.counters["sted"] = report.distortion.sted;
  state.counters["rank"] = report.rank;
  dmc::bench::SetVertexFrameCounters(state, sequence);
  memory.Report(state);
}
BENCHMARK(BM_EncodeEffort)
    ->DenseRange(0, dmc::kMaxEffort)
    ->ArgName("effort")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// At rank 60 and rank 100 (the argument), once per SIMD variant the CPU runs.
void BM_DecodeTarget(benchmark::State& state) {
  const dmc::MeshSequence& sequence = TargetSequence();
  // One encode per rank, shared by the variants' instances.
  static std::map<int64_t, std::vector<uint8_t>> streams;
  std::vector<uint8_t>& bytes = streams[state.range(0)];
  if (bytes.empty())
    bytes = *dmc::Encode(sequence, TargetOptions(static_cast<int>(state.range(0))));
  double cpu_seconds = 0.0;
  dmc::bench::PeakMemory memory;
  for (auto _ : state) {
    const dmc::bench::ProcessClock clock;
    auto decoded = dmc::Decode(bytes);
    benchmark::DoNotOptimize(decoded);
    cpu_seconds += clock.CpuSeconds();
  }
  // Every thread's CPU time (the CPU column is the main thread's only).
  state.counters["process_cpu_ms"] = 1e3 * cpu_seconds / static_cast<double>(state.iterations());
  state.counters["bpfv"] =
      8.0 * static_cast<double>(bytes.size()) / (sequence.frame_count() * sequence.vertex_count());
  state.counters["raw_MB"] = 12.0 * sequence.frame_count() * sequence.vertex_count() / 1e6;
  dmc::bench::SetVertexFrameCounters(state, sequence);
  memory.Report(state);
  dmc::bench::LabelSimdVariant(state);
}
const bool kDecodeTargetRegistered = [] {
  dmc::bench::RegisterPerSimdVariant("BM_DecodeTarget", BM_DecodeTarget, [](auto* b) {
    b->Arg(60)
        ->Arg(100)
        ->ArgName("rank")
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->MinTime(2.0);
  });
  return true;
}();

}  // namespace
