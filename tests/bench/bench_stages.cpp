// The codec stage by stage, on the synthetic walker at about 10k and 100k vertices × 60 frames
// (one segment) with the encoder's default options (DDL, 10 residual bits, automatic rank,
// 1 % anchors), and at the decode target of issue 5 (10k × 175 frames, rank 60): what each stage
// costs in time, in vertex-frames per second and in peak memory;
// then the full encode and decode next to per-frame Draco decoding of the same sequence at the
// same STED (Draco at 11 bits, dmc's residual step matched to it), at 60 and 175 frames, so the
// ratio is read in one run.
//
//   dmc_bench --benchmark_filter='Stage|Full|Draco'
//
// The basis multiply and BM_DecodeVsDraco run once per SIMD variant (…/simd:avx512, …/simd:avx2,
// …); DMC_SIMD=<variant> forces the variant of the others (dmc/simd.h).
//
// BM_DecodeVsDraco times both decoders in the same iterations (the ratio on a shared machine).
//
// Each stage runs the codec's own internal functions on the data the previous stages produced,
// in the encoder's order (see codec/src/encoder/encoder.cpp, EncodeSegment):
//   encoder: PCA (trajectory matrix + Gram eigen-decomposition), DDL fit, weight coding,
//            residual quantisation + range coding;
//   decoder: residual range decoding, operator rebuild, factorisation of the normal equations,
//            solve for the r coefficient columns, basis multiply (coefficients × basisᵀ + mean,
//            written as float frames).
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "bench/bench_support.h"
#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/segment_reconstruction.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/metrics.h"
#include "dmc/operators.h"
#include "encoder/basis_writer.h"
#include "encoder/syntax_writer.h"
#include "fitting/segment_pca.h"

namespace dmc::bench {
namespace {

constexpr int kDracoBits = 11;  // Draco's STED is closest to dmc's default at 11 bits

// Everything one segment's stages consume, computed once per resolution exactly as the encoder
// does with its default options.
struct StageFixture {
  const MeshSequence* sequence = nullptr;
  MeshTopology topology;
  std::vector<int32_t> vertex_order;
  SegmentTrajectories trajectories;
  Eigen::MatrixXd coefficients;
  LaplaceOperator fitted;   // the DDL fit, before weight quantisation
  SegmentSyntax syntax;     // dequantised elements, as the decoder rebuilds them
  LaplaceOperator laplace;  // rebuilt from the quantised weights
  std::vector<uint8_t> residual_payload;
};

// Anchors as the encoder chooses them in number (1 % of the vertices, at least one per
// component), spread by index rather than by farthest-point sampling: the solver's cost does
// not depend on where they are.
std::vector<int32_t> SpreadAnchors(const MeshTopology& topology) {
  const int count = std::max(1, static_cast<int>(std::lround(0.01 * topology.vertex_count)));
  std::vector<int32_t> anchors;
  std::vector<uint8_t> anchored(topology.component_count, 0);
  for (int a = 0; a < count; ++a) {
    const int v = static_cast<int>(static_cast<int64_t>(a) * topology.vertex_count / count);
    anchors.push_back(v);
    anchored[topology.component_of_vertex[v]] = 1;
  }
  for (int v = 0; v < topology.vertex_count; ++v) {
    if (!anchored[topology.component_of_vertex[v]]) {
      anchored[topology.component_of_vertex[v]] = 1;
      anchors.push_back(v);
    }
  }
  std::sort(anchors.begin(), anchors.end());
  return anchors;
}

// One fixture per benchmark arguments (resolution, frames, rank; rank 0: the encoder's automatic
// choice), built once.
const StageFixture& Fixture(const benchmark::State& state) {
  const int resolution = static_cast<int>(state.range(0));
  const int frame_count = static_cast<int>(state.range(1));
  const int forced_rank = static_cast<int>(state.range(2));
  static std::map<std::tuple<int, int, int>, std::unique_ptr<StageFixture>> cache;
  auto& slot = cache[{resolution, frame_count, forced_rank}];
  if (slot) return *slot;
  slot = std::make_unique<StageFixture>();
  StageFixture& s = *slot;
  const EncoderOptions defaults;
  s.sequence = &Walker(resolution, frame_count);
  const MeshSequence& sequence = *s.sequence;
  const int v_count = sequence.vertex_count();
  s.topology = BuildTopology(sequence.triangles(), v_count);
  s.vertex_order = format::BreadthFirstOrder(s.topology);
  s.trajectories = GatherTrajectories(sequence, 0, frame_count);
  const SegmentPca pca = ComputeSegmentPca(s.trajectories);

  const double diagonal = ComputeBoundingBox(sequence).diagonal();
  const double step = std::ldexp(diagonal, -defaults.residual_bits);
  const int max_rank = std::min(3 * frame_count, v_count - 1);
  int rank = 0;
  while (rank < max_rank && pca.eigenvalues[rank] > defaults.rank_threshold * v_count * step * step)
    ++rank;
  if (forced_rank > 0) rank = std::min(forced_rank, max_rank);
  format::SegmentHeader& h = s.syntax.header;
  h.frame_count = static_cast<uint32_t>(frame_count);
  h.rank = static_cast<uint32_t>(rank);
  h.operator_id = static_cast<uint8_t>(OperatorId::kDdl);
  h.basis_bits = static_cast<uint8_t>(defaults.basis_bits);
  h.weight_bits = static_cast<uint8_t>(defaults.weight_bits);
  h.weight_prediction = static_cast<uint8_t>(format::WeightPrediction::kReferenceProportional);
  h.mean_step = std::ldexp(diagonal, -18);
  h.residual_step = step;
  h.anchor_step = step * defaults.anchor_step_ratio;
  s.syntax.anchors = SpreadAnchors(s.topology);
  h.anchor_count = static_cast<uint32_t>(s.syntax.anchors.size());

  syntax::WriteMean(pca.mean, h, &s.syntax.mean);
  syntax::WriteBasis(pca.eigenvectors.leftCols(rank), h, &s.syntax.basis);
  const Eigen::MatrixXd projected =
      ProjectTrajectories(s.trajectories, s.syntax.mean, s.syntax.basis);
  s.coefficients =
      (s.syntax.basis.transpose() * s.syntax.basis).ldlt().solve(projected.transpose()).transpose();
  OperatorOptions operator_options;
  operator_options.ddl.mu = defaults.ddl_mu;
  s.fitted = *FitDdlSymmetric(s.topology, SourceFromTrajectories(s.coefficients), operator_options);
  syntax::WriteDdlWeights(s.fitted.weights.values, s.topology, defaults.weight_bits,
                          format::WeightPrediction::kReferenceProportional, &s.syntax.edge_weights);
  syntax::WriteAnchors(s.syntax.anchors, s.coefficients, h, &s.syntax.anchor_values);
  s.laplace = *RebuildSegmentOperator(s.topology, s.syntax);
  const Eigen::MatrixXd delta = s.laplace.matrix * s.coefficients;
  s.residual_payload =
      *syntax::WriteResiduals(delta, s.topology, s.vertex_order, h, &s.syntax.delta);
  return *slot;
}

void StageCounters(benchmark::State& state, const StageFixture& s, const PeakMemory& memory) {
  SetVertexFrameCounters(state, *s.sequence);
  state.counters["rank"] = static_cast<double>(s.syntax.header.rank);
  memory.Report(state);
}

// --- encoder stages ----------------------------------------------------------------------------

void BM_StagePca(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  PeakMemory memory;
  for (auto _ : state) {
    const SegmentTrajectories trajectories =
        GatherTrajectories(*s.sequence, 0, s.sequence->frame_count());
    SegmentPca pca = ComputeSegmentPca(trajectories);
    benchmark::DoNotOptimize(pca.eigenvalues.data());
  }
  StageCounters(state, s, memory);
}

void BM_StageDdlFit(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  OperatorOptions options;
  options.ddl.mu = EncoderOptions().ddl_mu;
  PeakMemory memory;
  for (auto _ : state) {
    auto fitted = FitDdlSymmetric(s.topology, SourceFromTrajectories(s.coefficients), options);
    benchmark::DoNotOptimize(fitted);
  }
  StageCounters(state, s, memory);
}

void BM_StageWeightCoding(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  std::vector<int64_t> decoded;
  PeakMemory memory;
  for (auto _ : state) {
    auto payload =
        syntax::WriteDdlWeights(s.fitted.weights.values, s.topology, s.syntax.header.weight_bits,
                                format::WeightPrediction::kReferenceProportional, &decoded);
    benchmark::DoNotOptimize(payload.data());
  }
  StageCounters(state, s, memory);
}

void BM_StageResidualCoding(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  const Eigen::MatrixXd delta = s.laplace.matrix * s.coefficients;
  Eigen::MatrixXd decoded;
  PeakMemory memory;
  for (auto _ : state) {
    auto payload =
        *syntax::WriteResiduals(delta, s.topology, s.vertex_order, s.syntax.header, &decoded);
    benchmark::DoNotOptimize(payload.data());
  }
  StageCounters(state, s, memory);
  state.counters["residual_bpfv"] =
      8.0 * static_cast<double>(s.residual_payload.size()) /
      (static_cast<double>(s.sequence->vertex_count()) * s.sequence->frame_count());
}

// --- decoder stages ----------------------------------------------------------------------------

void BM_StageResidualDecoding(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  SegmentSyntax syntax;
  syntax.header = s.syntax.header;
  PeakMemory memory;
  for (auto _ : state) {
    const Status status =
        syntax::ReadResiduals(s.residual_payload, s.topology, s.vertex_order, syntax);
    if (!status.ok()) state.SkipWithError(status.ToString().c_str());
    benchmark::DoNotOptimize(syntax.delta.data());
  }
  StageCounters(state, s, memory);
}

void BM_StageOperatorRebuild(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  PeakMemory memory;
  for (auto _ : state) {
    auto laplace = RebuildSegmentOperator(s.topology, s.syntax);
    benchmark::DoNotOptimize(laplace);
  }
  StageCounters(state, s, memory);
}

void BM_StageFactorisation(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  PeakMemory memory;
  for (auto _ : state) {
    auto solver = FactorSegmentOperator(s.topology, s.laplace, s.syntax);
    if (!solver.ok()) state.SkipWithError(solver.status().ToString().c_str());
    benchmark::DoNotOptimize(solver);
  }
  StageCounters(state, s, memory);
}

void BM_StageSolve(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  auto solver = FactorSegmentOperator(s.topology, s.laplace, s.syntax);
  if (!solver.ok()) {
    state.SkipWithError(solver.status().ToString().c_str());
    return;
  }
  PeakMemory memory;
  for (auto _ : state) {
    auto coefficients = solver->Solve(s.syntax.delta, s.syntax.anchor_values);
    benchmark::DoNotOptimize(coefficients);
  }
  StageCounters(state, s, memory);
}

void BM_StageBasisMultiply(benchmark::State& state) {
  const StageFixture& s = Fixture(state);
  const int frame_count = s.sequence->frame_count();
  std::vector<float> frames(static_cast<size_t>(s.sequence->vertex_count()) * frame_count * 3);
  PeakMemory memory;
  for (auto _ : state) {
    (void)SynthesizeFrames(s.syntax.mean, s.syntax.basis, s.coefficients, frame_count,
                           frames.data());
    benchmark::DoNotOptimize(frames.data());
  }
  StageCounters(state, s, memory);
  LabelSimdVariant(state);
}

// --- whole codec and the per-frame Draco reference ---------------------------------------------

// The comparison at equal quality: per-frame Draco at kDracoBits, and dmc with its residual step
// chosen so that its STED matches Draco's within a few percent (up to four encodes from the
// default 10 bits). Both STEDs are reported.
struct Comparison {
  DracoFrames draco;
  double draco_bpfv = 0.0;
  double draco_sted = 0.0;
  EncoderOptions options;  // dmc, matched
  std::vector<uint8_t> bytes;
  EncodeReport report;
};
// The walker of the benchmark's arguments (resolution, frames).
const MeshSequence& ComparedSequence(const benchmark::State& state) {
  return Walker(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
}

const Comparison& Compared(const benchmark::State& state) {
  static std::map<std::tuple<int64_t, int64_t, int64_t>, std::unique_ptr<Comparison>> cache;
  auto& slot = cache[{state.range(0), state.range(1), state.range(2)}];
  if (slot) return *slot;
  slot = std::make_unique<Comparison>();
  Comparison& c = *slot;
  const MeshSequence& sequence = ComparedSequence(state);
  c.draco = DracoEncodeFrames(sequence, kDracoBits);
  size_t draco_bytes = 0;
  for (const auto& frame : c.draco.frames) draco_bytes += frame.size();
  c.draco_bpfv = 8.0 * static_cast<double>(draco_bytes) /
                 (static_cast<double>(sequence.vertex_count()) * sequence.frame_count());
  c.draco_sted = DracoSted(sequence, c.draco);

  // Fixed-point iteration on the residual bits: STED is close to proportional to the step, so
  // each pass moves the bits by log2 of the remaining STED ratio. The automatic rank follows the
  // step, so the iteration can overshoot: up to eight encodes, keeping the closest.
  c.options.rank = static_cast<int>(state.range(2));
  double bits = c.options.residual_bits;
  const double diagonal = ComputeBoundingBox(sequence).diagonal();
  double best_miss = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 8 && c.draco_sted > 0.0; ++pass) {
    EncoderOptions trial = c.options;
    trial.residual_step = diagonal * std::exp2(-bits);
    EncodeReport report;
    auto bytes = Encode(sequence, trial, &report);
    if (!bytes.ok()) break;
    const double ratio = report.distortion.sted / c.draco_sted;
    if (!(ratio > 0.0)) break;
    if (std::abs(std::log(ratio)) < best_miss) {
      best_miss = std::abs(std::log(ratio));
      c.options = trial;
      c.bytes = *std::move(bytes);
      c.report = report;
    }
    if (best_miss < 0.03) break;
    bits += std::log2(ratio);
  }
  c.options.measure = false;
  return c;
}

void ComparisonCounters(benchmark::State& state, const Comparison& c) {
  state.counters["dmc_bpfv"] = c.report.bpfv;
  state.counters["dmc_sted"] = c.report.distortion.sted;
  state.counters["draco_bpfv"] = c.draco_bpfv;
  state.counters["draco_sted"] = c.draco_sted;
}

void BM_FullEncode(benchmark::State& state) {
  const Comparison& c = Compared(state);
  const MeshSequence& sequence = ComparedSequence(state);
  PeakMemory memory;
  for (auto _ : state) {
    auto bytes = Encode(sequence, c.options);
    if (!bytes.ok()) state.SkipWithError(bytes.status().ToString().c_str());
    benchmark::DoNotOptimize(bytes);
  }
  SetVertexFrameCounters(state, sequence);
  memory.Report(state);
  ComparisonCounters(state, c);
}

void BM_FullDecode(benchmark::State& state) {
  const Comparison& c = Compared(state);
  PeakMemory memory;
  for (auto _ : state) {
    auto decoded = Decode(c.bytes);
    if (!decoded.ok()) state.SkipWithError(decoded.status().ToString().c_str());
    benchmark::DoNotOptimize(decoded);
  }
  SetVertexFrameCounters(state, ComparedSequence(state));
  memory.Report(state);
  ComparisonCounters(state, c);
  LabelSimdVariant(state);
}

void BM_DracoPerFrameDecode(benchmark::State& state) {
  const Comparison& c = Compared(state);
  std::vector<float> positions;
  PeakMemory memory;
  for (auto _ : state) {
    if (DracoDecodeFrames(c.draco.frames, positions) < 0) state.SkipWithError("Draco failed");
    benchmark::DoNotOptimize(positions.data());
  }
  SetVertexFrameCounters(state, ComparedSequence(state));
  memory.Report(state);
  ComparisonCounters(state, c);
}

// The ratio read in one benchmark: every iteration decodes the dmc stream and then the
// per-frame Draco stream of the same sequence (matched STED), each timed on its own, so both see
// the same machine load; the counters are their mean wall times, their process CPU times (all
// threads) and the ratios Draco / dmc (above 1: dmc decodes faster).
void BM_DecodeVsDraco(benchmark::State& state) {
  const Comparison& c = Compared(state);
  std::vector<float> positions;
  double dmc_wall = 0.0, dmc_cpu = 0.0, draco_wall = 0.0, draco_cpu = 0.0;
  for (auto _ : state) {
    const ProcessClock dmc_clock;
    auto decoded = Decode(c.bytes);
    if (!decoded.ok()) state.SkipWithError(decoded.status().ToString().c_str());
    benchmark::DoNotOptimize(decoded);
    dmc_wall += dmc_clock.WallSeconds();
    dmc_cpu += dmc_clock.CpuSeconds();
    const ProcessClock draco_clock;
    if (DracoDecodeFrames(c.draco.frames, positions) < 0) state.SkipWithError("Draco failed");
    benchmark::DoNotOptimize(positions.data());
    draco_wall += draco_clock.WallSeconds();
    draco_cpu += draco_clock.CpuSeconds();
  }
  const auto iterations = static_cast<double>(state.iterations());
  state.counters["dmc_ms"] = 1e3 * dmc_wall / iterations;
  state.counters["dmc_cpu_ms"] = 1e3 * dmc_cpu / iterations;
  state.counters["draco_ms"] = 1e3 * draco_wall / iterations;
  state.counters["draco_cpu_ms"] = 1e3 * draco_cpu / iterations;
  state.counters["speedup"] = draco_wall / dmc_wall;
  state.counters["speedup_cpu"] = draco_cpu / dmc_cpu;
  state.counters["rank"] = c.report.rank;
  SetVertexFrameCounters(state, ComparedSequence(state));
  ComparisonCounters(state, c);
  LabelSimdVariant(state);
}

// Stages: the walker at 10k and 100k vertices × 60 frames with the automatic rank, and the
// issue's decode targets, 10k × 175 frames at ranks 60 and 100, the ranks real captures take at
// STED 0.03 to 0.015 (arguments: vertices, frames, rank; 0 = automatic).
void StageArguments(benchmark::internal::Benchmark* b) {
  b->Args({10000, 60, 0})
      ->Args({100000, 60, 0})
      ->Args({10000, 175, 60})
      ->Args({10000, 175, 100})
      ->ArgNames({"vertices", "frames", "rank"})
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

// The whole codec against per-frame Draco: the factorisation is paid once per segment and
// Draco's cost grows with every frame, so the ratio depends on the sequence length; it is read at
// 60 frames and at the 175 frames of the real captures with the automatic rank, and at 10k × 175
// with the rank forced to 60 and 100 (arguments: vertices, frames, rank; 0 = automatic).
void ComparisonArguments(benchmark::internal::Benchmark* b) {
  b->Args({10000, 60, 0})
      ->Args({10000, 175, 0})
      ->Args({100000, 60, 0})
      ->Args({100000, 175, 0})
      ->Args({10000, 175, 60})
      ->Args({10000, 175, 100})
      ->ArgNames({"vertices", "frames", "rank"})
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

#define DMC_STAGE_BENCHMARK(name) BENCHMARK(name)->Apply(StageArguments)
#define DMC_COMPARISON_BENCHMARK(name) BENCHMARK(name)->Apply(ComparisonArguments)

DMC_STAGE_BENCHMARK(BM_StagePca);
DMC_STAGE_BENCHMARK(BM_StageDdlFit);
DMC_STAGE_BENCHMARK(BM_StageWeightCoding);
DMC_STAGE_BENCHMARK(BM_StageResidualCoding);
DMC_STAGE_BENCHMARK(BM_StageResidualDecoding);
DMC_STAGE_BENCHMARK(BM_StageOperatorRebuild);
DMC_STAGE_BENCHMARK(BM_StageFactorisation);
DMC_STAGE_BENCHMARK(BM_StageSolve);
DMC_COMPARISON_BENCHMARK(BM_FullEncode);
DMC_COMPARISON_BENCHMARK(BM_FullDecode);
DMC_COMPARISON_BENCHMARK(BM_DracoPerFrameDecode);

// The synthesis and the decode-versus-Draco ratio once per SIMD variant the CPU runs
// (.../simd:avx2/...), so a CPU with AVX-512 also measures the AVX2 and baseline variants.
const bool kPerVariantRegistered = [] {
  RegisterPerSimdVariant("BM_StageBasisMultiply", BM_StageBasisMultiply, StageArguments);
  RegisterPerSimdVariant("BM_DecodeVsDraco", BM_DecodeVsDraco, ComparisonArguments);
  return true;
}();

}  // namespace
}  // namespace dmc::bench
