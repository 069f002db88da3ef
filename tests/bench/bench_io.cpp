// Sequence I/O speed: reading the real OBJ sequences (serial vs one thread per core), OpenMesh's
// reader on the same frame for comparison, and writing/reading frame directories and PC2.
//
//   dmc_bench --benchmark_filter=Io
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <cmath>
#include <filesystem>
#include <string>

#include "dmc/io.h"
#include "synth/grid_triangles.h"

namespace dmc {
namespace {

std::filesystem::path SharedData(const std::string& relative) {
  return std::filesystem::path(DMC_SHARED_DATA_DIR) / relative;
}

// Reads a whole shared OBJ sequence; the argument is ReadOptions::threads (0 = one per core).
void BM_IoReadSequence(benchmark::State& state, const std::string& name) {
  const auto input = SharedData(name);
  if (!std::filesystem::exists(input)) {
    state.SkipWithError(("../shared/data/" + name + " is absent").c_str());
    return;
  }
  ReadOptions options;
  options.threads = static_cast<int>(state.range(0));
  int64_t bytes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(input)) {
    bytes += static_cast<int64_t>(entry.file_size());
  }
  int frames = 0;
  for (auto _ : state) {
    auto sequence = ReadSequence(input, options);
    if (!sequence.ok()) {
      state.SkipWithError(sequence.status().ToString().c_str());
      return;
    }
    frames = sequence->frame_count();
    benchmark::DoNotOptimize(sequence->data());
  }
  state.SetBytesProcessed(state.iterations() * bytes);
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(frames),
                                                  benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK_CAPTURE(BM_IoReadSequence, samba, std::string("samba"))
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_IoReadSequence, horse_gallop, std::string("horse-gallop"))
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond);

// One 10k-vertex OBJ frame: dmc's parser against OpenMesh's reader with its default importer.
void BM_IoReadObjFrameDmc(benchmark::State& state) {
  const auto file = SharedData("samba/mesh_0000.obj");
  if (!std::filesystem::exists(file)) {
    state.SkipWithError("../shared/data/samba is absent");
    return;
  }
  for (auto _ : state) {
    auto sequence = ReadSequence(file);
    benchmark::DoNotOptimize(sequence.ok());
  }
  state.SetBytesProcessed(state.iterations() *
                          static_cast<int64_t>(std::filesystem::file_size(file)));
}
BENCHMARK(BM_IoReadObjFrameDmc)->Unit(benchmark::kMillisecond);

void BM_IoReadObjFrameOpenMesh(benchmark::State& state) {
  const auto file = SharedData("samba/mesh_0000.obj");
  if (!std::filesystem::exists(file)) {
    state.SkipWithError("../shared/data/samba is absent");
    return;
  }
  for (auto _ : state) {
    OpenMesh::PolyMesh_ArrayKernelT<> mesh;
    benchmark::DoNotOptimize(OpenMesh::IO::read_mesh(mesh, file.string()));
  }
  state.SetBytesProcessed(state.iterations() *
                          static_cast<int64_t>(std::filesystem::file_size(file)));
}
BENCHMARK(BM_IoReadObjFrameOpenMesh)->Unit(benchmark::kMillisecond);

// A smoothly waving n x n grid, `frames` frames.
MeshSequence WavingGrid(int n, int frames) {
  MeshSequence sequence(n * n, synth::GridTriangles(n, n, synth::GridDiagonals::kUniform), frames);
  for (int f = 0; f < frames; ++f) {
    for (int v = 0; v < n * n; ++v) {
      const float x = static_cast<float>(v % n) / static_cast<float>(n - 1);
      const float y = static_cast<float>(v / n) / static_cast<float>(n - 1);
      sequence.frame(f).row(v) << x, y, 0.1f * std::sin(6.0f * x + 0.2f * static_cast<float>(f));
    }
  }
  return sequence;
}

std::filesystem::path BenchDir() {
  const auto dir =
      std::filesystem::temp_directory_path() / ("dmc_bench_io_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

// Writing then reading 30 frames of a 10k-vertex grid in each layout.
void BM_IoWriteRead(benchmark::State& state, const std::string& layout) {
  const MeshSequence sequence = WavingGrid(100, 30);
  const auto dir = BenchDir();
  const auto output = dir / layout;  // "frames_obj", "frames_ply" or "anim.pc2"
  WriteOptions options;
  if (layout == "frames_ply") options.frame_format = "ply";
  for (auto _ : state) {
    if (!WriteSequence(sequence, output, options).ok()) {
      state.SkipWithError("write failed");
      break;
    }
    auto read = ReadSequence(output);
    if (!read.ok()) {
      state.SkipWithError(read.status().ToString().c_str());
      break;
    }
    benchmark::DoNotOptimize(read->data());
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK_CAPTURE(BM_IoWriteRead, frames_obj, std::string("frames_obj"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_IoWriteRead, frames_ply, std::string("frames_ply"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_IoWriteRead, pc2, std::string("anim.pc2"))->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dmc
