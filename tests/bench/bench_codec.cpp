// Codec speed: encode and decode of a real 10k-vertex performance capture (samba, when
// ../shared/data is present) and of a synthetic stand-in of the same size otherwise.
#include <benchmark/benchmark.h>

#include <filesystem>

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
}
BENCHMARK(BM_Decode)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
