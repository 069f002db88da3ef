// Speed of the operator module: DDL fits (targets: 10k vertices at r = 64 under 1 s, 100k under
// 15 s, on 2 cores), the non-fitted operators (milliseconds), trajectory PCA, and the normal-
// equation solver backends the decoder chooses between (factor once, solve 64 columns).
//
//   dmc_bench --benchmark_filter='Ddl|Operator|Pca|Normal'
//
// Meshes are jittered planar grids (irregular valences) animated by a smooth non-rigid motion,
// so the numbers do not depend on ../shared/data.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>

#include "dmc/operators.h"
#include "dmc/pca.h"
#include "unit/operators/operator_test_meshes.h"

namespace {

using namespace dmc;

struct BenchMesh {
  MeshSequence sequence;
  MeshTopology topology;
  OperatorSource source;  // reference frame = mean frame, trajectories = PCA coefficients (r=64)
};

// Grid side n → n² vertices, 24 frames, PCA rank 64; built once per size.
const BenchMesh& Mesh(int side) {
  static std::map<int, std::unique_ptr<BenchMesh>> cache;
  auto& slot = cache[side];
  if (!slot) {
    slot = std::make_unique<BenchMesh>();
    slot->sequence = dmc::testing::Animate(dmc::testing::JitteredPlanarGrid(side, 0.3), 24);
    slot->topology = BuildTopology(slot->sequence.triangles(), slot->sequence.vertex_count());
    slot->source = SourceFromSequence(slot->sequence);
    slot->source.trajectories = ComputeTrajectoryPca(slot->sequence, 64)->coefficients;
  }
  return *slot;
}

void SetVertexCounters(benchmark::State& state, const BenchMesh& mesh) {
  state.counters["vertices"] = mesh.topology.vertex_count;
  state.counters["rank"] = static_cast<double>(mesh.source.trajectories->cols());
}

void BM_DdlSymmetricFit(benchmark::State& state) {
  const BenchMesh& mesh = Mesh(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto ddl = FitDdlSymmetric(mesh.topology, mesh.source);
    if (!ddl.ok()) state.SkipWithError(ddl.status().ToString().c_str());
    benchmark::DoNotOptimize(ddl);
  }
  SetVertexCounters(state, mesh);
}
BENCHMARK(BM_DdlSymmetricFit)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DdlSymmetricFit)->Arg(316)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_DdlAsymmetricFit(benchmark::State& state) {
  const BenchMesh& mesh = Mesh(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto ddl = FitDdlAsymmetric(mesh.topology, mesh.source);
    benchmark::DoNotOptimize(ddl);
  }
  SetVertexCounters(state, mesh);
}
BENCHMARK(BM_DdlAsymmetricFit)->Arg(100)->Arg(316)->Unit(benchmark::kMillisecond)->UseRealTime();

// Every non-fitted registry operator on the 10k-vertex mesh.
void BM_GeometricOperator(benchmark::State& state, const char* name) {
  const BenchMesh& mesh = Mesh(100);
  for (auto _ : state) {
    auto op = BuildOperator(name, mesh.topology, mesh.source);
    if (!op.ok()) state.SkipWithError(op.status().ToString().c_str());
    benchmark::DoNotOptimize(op);
  }
  SetVertexCounters(state, mesh);
}
BENCHMARK_CAPTURE(BM_GeometricOperator, kirchhoff, "kirchhoff")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GeometricOperator, tutte, "tutte")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GeometricOperator, cotan, "cotan")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GeometricOperator, cotan_area, "cotan-area")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GeometricOperator, cotan_sym, "cotan-sym")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GeometricOperator, mean_value, "mean-value")->Unit(benchmark::kMillisecond);

void BM_TrajectoryPca(benchmark::State& state) {
  const BenchMesh& mesh = Mesh(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto pca = ComputeTrajectoryPca(mesh.sequence, 64);
    benchmark::DoNotOptimize(pca);
  }
  state.counters["vertices"] = mesh.topology.vertex_count;
  state.counters["frames"] = mesh.sequence.frame_count();
}
BENCHMARK(BM_TrajectoryPca)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();

// The decoder's work: N = L̃ᵀL̃ of the Tutte operator with 100 spread anchors, factored once,
// then 64 columns solved. Args: grid side, backend, ordering.
void BM_NormalEquations(benchmark::State& state) {
  const BenchMesh& mesh = Mesh(static_cast<int>(state.range(0)));
  SolverOptions options;
  options.backend = static_cast<SolverBackend>(state.range(1));
  options.ordering = static_cast<SolverOrdering>(state.range(2));
  const auto tutte = BuildTutte(mesh.topology);
  std::vector<int32_t> anchors;
  for (int k = 0; k < 100; ++k) anchors.push_back(k * (mesh.topology.vertex_count / 100));
  const SparseMatrixD normal = BuildNormalMatrix(tutte->matrix, anchors);
  const Eigen::MatrixXd rhs = normal * *mesh.source.trajectories;
  for (auto _ : state) {
    auto solver = SparseSpdSolver::Factor(normal, options);
    if (!solver.ok()) {
      state.SkipWithError(solver.status().ToString().c_str());
      break;
    }
    auto solved = solver->Solve(rhs);
    benchmark::DoNotOptimize(solved);
  }
  state.SetLabel(std::string(SolverBackendName(options.backend)) +
                 (options.ordering == SolverOrdering::kMetis ? "/metis"
                  : options.ordering == SolverOrdering::kAmd ? "/amd"
                                                             : "/auto"));
  state.counters["vertices"] = mesh.topology.vertex_count;
}
BENCHMARK(BM_NormalEquations)
    ->ArgsProduct({{100},
                   {static_cast<int>(SolverBackend::kCholmod)},
                   {static_cast<int>(SolverOrdering::kAmd),
                    static_cast<int>(SolverOrdering::kMetis)}})
    ->Args({100, static_cast<int>(SolverBackend::kSimplicialLdlt), 0})
    ->Args({316, static_cast<int>(SolverBackend::kCholmod), static_cast<int>(SolverOrdering::kAmd)})
    ->Args({316, static_cast<int>(SolverBackend::kCholmod),
            static_cast<int>(SolverOrdering::kMetis)})
    ->Args({316, static_cast<int>(SolverBackend::kSimplicialLdlt), 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
