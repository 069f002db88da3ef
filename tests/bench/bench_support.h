// Shared pieces of the codec benchmarks (bench_stages.cpp, bench_scaling.cpp): cached synthetic
// inputs, throughput and peak-memory counters, and per-frame Draco as the reference decoder.
#pragma once

#include <benchmark/benchmark.h>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/compression/mesh/mesh_edgebreaker_encoder.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>
#include <malloc.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "dmc/metrics.h"
#include "dmc/sequence.h"
#include "dmc/simd.h"
#include "dmc/synth.h"

namespace dmc::bench {

// A built-in animation (dmc/synth.h) at a resolution and frame count, built once per
// (name, resolution, frames) and kept for the whole run.
inline const MeshSequence& Synthesized(const std::string& name, int resolution, int frames) {
  static std::map<std::tuple<std::string, int, int>, std::unique_ptr<MeshSequence>> cache;
  auto& slot = cache[{name, resolution, frames}];
  if (!slot) {
    SynthOptions options;
    options.resolution = resolution;
    options.frames = frames;
    slot = std::make_unique<MeshSequence>(*Synthesize(name, options));
  }
  return *slot;
}

// The walker (six skinned capsules, 11 bones): articulated motion like the real captures, and a
// resolution parameter, so every size comes from the same generator.
inline const MeshSequence& Walker(int resolution, int frames) {
  return Synthesized("walker", resolution, frames);
}

// Peak resident memory of the process, measured per benchmark: construction returns free heap
// pages to the system (malloc_trim) and clears the kernel's high-water mark (writing 5 to
// /proc/self/clear_refs, Linux ≥ 4.0); Report() reads it back (VmHWM). The value includes what was
// resident at the reset (the input sequence, the other cached fixtures), so `peak_MB` minus
// `base_MB` is what the benchmarked code added. When the reset is not permitted the peak is the
// process's since its start (`peak_reset` = 0).
class PeakMemory {
 public:
  PeakMemory() {
    // Give freed heap pages back first, or the code under test would reuse them without raising
    // the resident high-water mark.
    malloc_trim(0);
    std::ofstream clear("/proc/self/clear_refs");
    reset_ = static_cast<bool>(clear << "5");
    clear.close();
    reset_ = reset_ && clear.good();
    base_ = ReadKilobytes("VmRSS:");
  }
  void Report(benchmark::State& state) const {
    state.counters["peak_MB"] = ReadKilobytes("VmHWM:") / 1024.0;
    state.counters["base_MB"] = base_ / 1024.0;
    state.counters["peak_reset"] = reset_ ? 1 : 0;
  }

 private:
  static double ReadKilobytes(const std::string& key) {
    std::ifstream status("/proc/self/status");
    std::string word;
    while (status >> word) {
      if (word == key) {
        double kilobytes = 0;
        status >> kilobytes;
        return kilobytes;
      }
    }
    return 0.0;
  }
  bool reset_ = false;
  double base_ = 0.0;
};

// Wall time and CPU time of the whole process (every thread, user + system) since construction:
// Google Benchmark's CPU column counts the main thread only, and the codec runs TBB workers.
class ProcessClock {
 public:
  ProcessClock() : wall_start_(std::chrono::steady_clock::now()), cpu_start_(ProcessCpu()) {}
  double WallSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
  }
  double CpuSeconds() const { return ProcessCpu() - cpu_start_; }

 private:
  static double ProcessCpu() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    auto seconds = [](const timeval& t) {
      return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
    };
    return seconds(usage.ru_utime) + seconds(usage.ru_stime);
  }
  std::chrono::steady_clock::time_point wall_start_;
  double cpu_start_;
};

// Vertex-frames processed per second (the codec's natural throughput unit), plus the size.
inline void SetVertexFrameCounters(benchmark::State& state, const MeshSequence& sequence) {
  const double vertex_frames =
      static_cast<double>(sequence.vertex_count()) * sequence.frame_count();
  state.counters["vertex_frames/s"] =
      benchmark::Counter(vertex_frames, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["vertices"] = sequence.vertex_count();
  state.counters["frames"] = sequence.frame_count();
}

// The SIMD variant frame synthesis ran in (dmc/simd.h), as the benchmark's label.
inline void LabelSimdVariant(benchmark::State& state) {
  state.SetLabel("simd=" + ActiveSimdVariant());
}

// Registers `function` once per SIMD variant this CPU runs, fastest first, as
// `<name>/simd:<variant>`, each run with that variant forced and the previous one restored after;
// `configure` sets the arguments, unit and timing of every instance.
template <typename Configure>
void RegisterPerSimdVariant(const std::string& name, void (*function)(benchmark::State&),
                            Configure configure) {
  for (const std::string& variant : SupportedSimdVariants()) {
    configure(benchmark::RegisterBenchmark((name + "/simd:" + variant).c_str(),
                                           [function, variant](benchmark::State& state) {
                                             const std::string previous = ActiveSimdVariant();
                                             const Status forced = SetSimdVariant(variant);
                                             if (!forced.ok()) {
                                               state.SkipWithError(forced.ToString().c_str());
                                               return;
                                             }
                                             function(state);
                                             if (!SetSimdVariant(previous).ok())
                                               state.SkipWithError("restoring the SIMD variant");
                                           }));
  }
}

// Per-frame Draco, as a glTF or web pipeline ships an animation without a dynamic codec: every
// frame compressed on its own through draco::Encoder (edgebreaker, speed 0, positions quantised
// to `bits` over the frame's box). `input_vertex[i]` is the input vertex of decoded attribute
// value i, taken from Draco's edgebreaker encoder (the traversal depends on the connectivity
// only, so it is the same for every frame); it is what lets the benchmark measure Draco's STED.
// (tools/dmc/sweep/baselines.cpp does the same for `dmc sweep`; dmc_bench does not link it.)
struct DracoFrames {
  std::vector<std::vector<char>> frames;
  std::vector<int32_t> input_vertex;
};

inline DracoFrames DracoEncodeFrames(const MeshSequence& sequence, int bits) {
  draco::Mesh mesh;
  const auto vertex_count = static_cast<uint32_t>(sequence.vertex_count());
  mesh.set_num_points(vertex_count);
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false,
                3 * sizeof(float), 0);
  const int attribute_id = mesh.AddAttribute(position, true, vertex_count);
  draco::PointAttribute* attribute = mesh.attribute(attribute_id);
  for (int t = 0; t < sequence.triangle_count(); ++t) {
    mesh.AddFace({draco::PointIndex(static_cast<uint32_t>(sequence.triangles()(t, 0))),
                  draco::PointIndex(static_cast<uint32_t>(sequence.triangles()(t, 1))),
                  draco::PointIndex(static_cast<uint32_t>(sequence.triangles()(t, 2)))});
  }
  draco::Encoder encoder;
  encoder.SetSpeedOptions(0, 0);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  DracoFrames draco;
  for (int f = 0; f < sequence.frame_count(); ++f) {
    for (uint32_t v = 0; v < vertex_count; ++v) {
      attribute->SetAttributeValue(draco::AttributeValueIndex(v),
                                   sequence.frame(f).row(static_cast<Eigen::Index>(v)).data());
    }
    draco::EncoderBuffer buffer;
    if (!encoder.EncodeMeshToBuffer(mesh, &buffer).ok()) return {};
    draco.frames.emplace_back(buffer.data(), buffer.data() + buffer.size());
    if (f > 0) continue;
    // The vertex order: the same options on the edgebreaker encoder, which exposes it.
    draco::EncoderOptions options = draco::EncoderOptions::CreateDefaultOptions();
    options.SetSpeed(0, 0);
    options.SetAttributeInt(attribute_id, "quantization_bits", bits);
    draco::MeshEdgebreakerEncoder edgebreaker;
    edgebreaker.SetMesh(mesh);
    draco::EncoderBuffer scratch;
    if (!edgebreaker.Encode(options, &scratch).ok()) return {};
    const std::vector<int32_t>& value_of_vertex =
        edgebreaker.GetAttributeEncodingData(attribute_id)
            ->vertex_to_encoded_attribute_value_index_map;
    if (value_of_vertex.size() != vertex_count) return {};  // Draco split vertices
    draco.input_vertex.assign(vertex_count, 0);
    for (uint32_t v = 0; v < vertex_count; ++v) draco.input_vertex[value_of_vertex[v]] = v;
  }
  return draco;
}

// Decodes every frame to float positions (attribute value order), as a player would; returns
// the vertices decoded, or −1 when Draco fails.
inline int64_t DracoDecodeFrames(const std::vector<std::vector<char>>& frames,
                                 std::vector<float>& positions) {
  int64_t decoded = 0;
  for (const std::vector<char>& frame : frames) {
    draco::DecoderBuffer buffer;
    buffer.Init(frame.data(), frame.size());
    draco::Decoder decoder;
    auto mesh = decoder.DecodeMeshFromBuffer(&buffer);
    if (!mesh.ok()) return -1;
    const draco::PointAttribute* attribute =
        mesh.value()->GetNamedAttribute(draco::GeometryAttribute::POSITION);
    positions.resize(3 * static_cast<size_t>(attribute->size()));
    for (uint32_t v = 0; v < attribute->size(); ++v) {
      attribute->GetValue(draco::AttributeValueIndex(v), positions.data() + 3 * size_t{v});
    }
    decoded += attribute->size();
  }
  return decoded;
}

// STED of Draco's decoded frames against `original`, vertex for vertex (−1 when Draco fails).
inline double DracoSted(const MeshSequence& original, const DracoFrames& draco) {
  if (draco.input_vertex.empty()) return -1.0;
  MeshSequence decoded(original.vertex_count(), original.triangles(), original.frame_count());
  std::vector<float> positions;
  for (int f = 0; f < original.frame_count(); ++f) {
    if (DracoDecodeFrames({draco.frames[f]}, positions) != original.vertex_count()) return -1.0;
    for (int i = 0; i < original.vertex_count(); ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        decoded.frame(f)(draco.input_vertex[i], axis) =
            positions[3 * static_cast<size_t>(i) + axis];
      }
    }
  }
  const auto sted = Sted(original, decoded);
  return sted.ok() ? sted->sted : -1.0;
}

}  // namespace dmc::bench
