// Speed of the processing methods (dmc/processing.h), split like the API: precompute (the
// factorisation or eigensolve, once per operator and selection) and apply (one frame). Sizes:
// jittered planar grids of 100² (10k) and 316² (~100k) vertices, bent by a smooth motion (so
// they are not planar) — disks, so every method including param-barycentric applies.
//
//   dmc_bench --benchmark_filter=Processing
//
// The operator is built outside the timed region (bench_operators.cpp times operators): cotan
// for every method, cotan-sym for spectral-filter (it needs a symmetric operator). Selections:
// the first 1% of vertex indices are handles (moved up by 0.1), the last 10% fixed.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>

#include "dmc/processing.h"
#include "unit/operators/operator_test_meshes.h"

namespace {

using namespace dmc;

struct BenchCase {
  MeshSequence sequence;
  MeshTopology topology;
  LaplaceOperator laplace;
  FramePositionsD reference;
  Selection selection;
  ParameterValues parameters;
  std::unique_ptr<PreparedMethod> prepared;
};

std::string_view OperatorFor(std::string_view method) {
  return method == "spectral-filter" ? "cotan-sym" : "cotan";
}

std::map<std::string, std::string> ParametersFor(std::string_view method) {
  if (method == "spectral-filter") return {{"k", "20"}};
  if (method == "morph") return {{"frames", "2"}};
  return {};
}

// One case per (method, grid side), built and precomputed once.
BenchCase& Case(std::string_view method, int side) {
  static std::map<std::pair<std::string, int>, std::unique_ptr<BenchCase>> cache;
  auto& slot = cache[{std::string(method), side}];
  if (!slot) {
    slot = std::make_unique<BenchCase>();
    slot->sequence = dmc::testing::Animate(dmc::testing::JitteredPlanarGrid(side, 0.3), 2);
    slot->topology = BuildTopology(slot->sequence.triangles(), slot->sequence.vertex_count());
    slot->reference = MeanFrame(slot->sequence);
    slot->laplace =
        *BuildOperator(OperatorFor(method), slot->topology, SourceFromFrame(slot->reference));
    const int v_count = slot->sequence.vertex_count();
    for (int v = 0; v < v_count / 100; ++v) slot->selection.handles.push_back(v);
    for (int v = v_count - v_count / 10; v < v_count; ++v) slot->selection.fixed.push_back(v);
    slot->selection.transform(2, 3) = 0.1;
    const MethodInfo* info = *FindMethod(method);
    slot->parameters = *ParameterValues::Create(info->parameters, ParametersFor(method));
  }
  return *slot;
}

ProcessingContext ContextOf(const BenchCase& c) {
  return {.sequence = c.sequence,
          .topology = c.topology,
          .laplace = &c.laplace,
          .reference_frame = c.reference,
          .selection = c.selection,
          .parameters = c.parameters,
          .operator_name = c.laplace.name,
          .operator_options = {}};
}

void BM_ProcessingPrecompute(benchmark::State& state, const char* method) {
  BenchCase& c = Case(method, static_cast<int>(state.range(0)));
  const MethodInfo* info = *FindMethod(method);
  for (auto _ : state) {
    auto prepared = info->precompute(ContextOf(c));
    if (!prepared.ok()) state.SkipWithError(prepared.status().ToString().c_str());
    benchmark::DoNotOptimize(prepared);
  }
  state.counters["vertices"] = c.sequence.vertex_count();
}

void BM_ProcessingApply(benchmark::State& state, const char* method) {
  BenchCase& c = Case(method, static_cast<int>(state.range(0)));
  const MethodInfo* info = *FindMethod(method);
  if (!c.prepared) {
    auto prepared = info->precompute(ContextOf(c));
    if (!prepared.ok()) {
      state.SkipWithError(prepared.status().ToString().c_str());
      return;
    }
    c.prepared = std::move(prepared).value();
  }
  const FramePositionsD frame = c.sequence.frame_d(1);
  for (auto _ : state) {
    if (info->scope == MethodScope::kWholeSequence) {
      auto result = c.prepared->ApplySequence(c.sequence);
      if (!result.ok()) state.SkipWithError(result.status().ToString().c_str());
      benchmark::DoNotOptimize(result);
    } else {
      auto output = c.prepared->Apply(frame, 1);
      if (!output.ok()) state.SkipWithError(output.status().ToString().c_str());
      benchmark::DoNotOptimize(output);
    }
  }
  state.counters["vertices"] = c.sequence.vertex_count();
}

#define DMC_PROCESSING_BENCH(tag, method)                 \
  BENCHMARK_CAPTURE(BM_ProcessingPrecompute, tag, method) \
      ->Arg(100)                                          \
      ->Arg(316)                                          \
      ->Unit(benchmark::kMillisecond)                     \
      ->UseRealTime()                                     \
      ->Iterations(2);                                    \
  BENCHMARK_CAPTURE(BM_ProcessingApply, tag, method)      \
      ->Arg(100)                                          \
      ->Arg(316)                                          \
      ->Unit(benchmark::kMillisecond)                     \
      ->UseRealTime()

DMC_PROCESSING_BENCH(laplacian_edit, "laplacian-edit");
DMC_PROCESSING_BENCH(smooth_explicit, "smooth-explicit");
DMC_PROCESSING_BENCH(smooth_taubin, "smooth-taubin");
DMC_PROCESSING_BENCH(smooth_implicit, "smooth-implicit");
DMC_PROCESSING_BENCH(param_barycentric, "param-barycentric");
DMC_PROCESSING_BENCH(morph, "morph");
DMC_PROCESSING_BENCH(ls_mesh, "ls-mesh");
DMC_PROCESSING_BENCH(curvature, "curvature");
DMC_PROCESSING_BENCH(spectral_filter, "spectral-filter");

}  // namespace
