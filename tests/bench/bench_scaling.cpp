// How full encode and decode scale: with the vertex count (walker at 1k, 10k, 100k, 1M vertices,
// 20 frames) and with the frame count (10k vertices, 50, 200, 1000 frames), for the default DDL
// operator and for Tutte (no fit: the rest of the pipeline alone). Default options otherwise
// (10 residual bits, automatic rank, segments of at most 256 frames). The exponents of the last
// full run are in CHANGELOG.md.
//
//   dmc_bench --benchmark_filter='Scaling'             (all: several minutes on 2 cores)
//   dmc_bench --benchmark_filter='Scaling.*vertices:1000000/'  (the 1M-vertex points)
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "bench/bench_support.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"

namespace dmc::bench {
namespace {

constexpr const char* kOperators[] = {"ddl", "tutte"};

EncoderOptions Options(int operator_index) {
  EncoderOptions options;
  options.operator_name = kOperators[operator_index];
  options.measure = false;
  return options;
}

struct Encoded {
  std::vector<uint8_t> bytes;
  EncodeReport report;
};
// One stream per (resolution, frames, operator), encoded on first use.
const Encoded& EncodedStream(int resolution, int frames, int operator_index) {
  static std::map<std::tuple<int, int, int>, std::unique_ptr<Encoded>> cache;
  auto& slot = cache[{resolution, frames, operator_index}];
  if (!slot) {
    slot = std::make_unique<Encoded>();
    slot->bytes = *Encode(Walker(resolution, frames), Options(operator_index), &slot->report);
  }
  return *slot;
}

// Args: walker resolution, frames, operator (0 = ddl, 1 = tutte).
void BM_ScalingEncode(benchmark::State& state) {
  const int operator_index = static_cast<int>(state.range(2));
  const MeshSequence& sequence =
      Walker(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const EncoderOptions options = Options(operator_index);
  PeakMemory memory;
  EncodeReport report;
  for (auto _ : state) {
    auto bytes = Encode(sequence, options, &report);
    if (!bytes.ok()) state.SkipWithError(bytes.status().ToString().c_str());
    benchmark::DoNotOptimize(bytes);
  }
  SetVertexFrameCounters(state, sequence);
  memory.Report(state);
  state.counters["bpfv"] = report.bpfv;
  state.counters["rank"] = report.rank;
  state.counters["segments"] = report.segments;
  state.SetLabel(kOperators[operator_index]);
}

void BM_ScalingDecode(benchmark::State& state) {
  const int resolution = static_cast<int>(state.range(0));
  const int frames = static_cast<int>(state.range(1));
  const int operator_index = static_cast<int>(state.range(2));
  const Encoded& encoded = EncodedStream(resolution, frames, operator_index);
  PeakMemory memory;
  for (auto _ : state) {
    auto decoded = Decode(encoded.bytes);
    if (!decoded.ok()) state.SkipWithError(decoded.status().ToString().c_str());
    benchmark::DoNotOptimize(decoded);
  }
  SetVertexFrameCounters(state, Walker(resolution, frames));
  memory.Report(state);
  state.counters["bpfv"] = encoded.report.bpfv;
  state.counters["segments"] = encoded.report.segments;
  state.SetLabel(kOperators[operator_index]);
}

void ScalingArguments(benchmark::internal::Benchmark* benchmark) {
  for (const int op : {0, 1}) {
    for (const int resolution : {1000, 10000, 100000, 1000000})
      benchmark->Args({resolution, 20, op});
    for (const int frames : {50, 200, 1000}) benchmark->Args({10000, frames, op});
  }
  benchmark->ArgNames({"vertices", "frames", "op"});
  benchmark->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(BM_ScalingEncode)->Apply(ScalingArguments);
BENCHMARK(BM_ScalingDecode)->Apply(ScalingArguments);

}  // namespace
}  // namespace dmc::bench
