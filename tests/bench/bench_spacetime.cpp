// The 3D+t spacetime Laplacian: assembly cost, block LDLᵀ against sparse Cholesky (CHOLMOD) on
// its block-tridiagonal systems, and spacetime ARAP on a 10k-vertex × 10-frame window
// (iterations and time). Inputs come from `dmc synth cloth` (frame rate 30).
//
//   dmc_bench --benchmark_filter=Spacetime
#include <benchmark/benchmark.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "bench/bench_support.h"
#include "dmc/operators.h"
#include "dmc/spacetime.h"
#include "dmc/synth.h"

namespace dmc {
namespace {

const MeshSequence& Cloth(int resolution, int frames) {
  return bench::Synthesized("cloth", resolution, frames);
}

void BM_SpacetimeBuild(benchmark::State& state) {
  const MeshSequence& seq = Cloth(static_cast<int>(state.range(0)), 10);
  for (auto _ : state) {
    auto op = BuildSpacetimeLaplacian(seq, {});
    benchmark::DoNotOptimize(op->matrix.valuePtr());
  }
  state.counters["vertices"] = seq.vertex_count();
  state.counters["unknowns"] = static_cast<double>(seq.vertex_count()) * seq.frame_count();
}
BENCHMARK(BM_SpacetimeBuild)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

// The same operator through the operator registry's "spacetime" row (trajectories V×3F, triangles
// recovered from the topology): what `dmc laplacian --operator spacetime` pays.
void BM_SpacetimeRegistryRow(benchmark::State& state) {
  const MeshSequence& seq = Cloth(static_cast<int>(state.range(0)), 10);
  const MeshTopology topology = BuildTopology(seq.triangles(), seq.vertex_count());
  const OperatorSource source = SourceFromSequence(seq);
  OperatorOptions options;
  options.allow_any_domain = true;
  options.spacetime.frame_rate = seq.frame_rate;
  for (auto _ : state) {
    auto op = BuildOperator("spacetime", topology, source, options);
    benchmark::DoNotOptimize(op->matrix.valuePtr());
  }
  state.counters["vertices"] = seq.vertex_count();
  state.counters["unknowns"] = static_cast<double>(seq.vertex_count()) * seq.frame_count();
}
BENCHMARK(BM_SpacetimeRegistryRow)->Arg(10000)->Unit(benchmark::kMillisecond);

// −W plus unit soft anchors on the first frame: the ARAP system's shape.
SparseMatrixD AnchoredSystem(const MeshSequence& seq) {
  const auto op = BuildSpacetimeLaplacian(seq, {});
  SparseMatrixD system = -op->stiffness;
  const double scale = system.diagonal().mean();
  for (int v = 0; v < seq.vertex_count(); ++v) system.coeffRef(v, v) += scale;
  return system;
}

// Factor + one 4-column solve (a full ARAP global step's cost once factorised is the solve).
void BM_SpacetimeSolveBlockLdlt(benchmark::State& state) {
  const MeshSequence& seq = Cloth(static_cast<int>(state.range(0)), 10);
  const SparseMatrixD system = AnchoredSystem(seq);
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Ones(system.rows(), 4);
  for (auto _ : state) {
    auto solver = BlockTridiagonalSolver::Factor(system, seq.vertex_count());
    auto x = solver->Solve(rhs);
    benchmark::DoNotOptimize(x->data());
  }
  state.counters["vertices"] = seq.vertex_count();
}
BENCHMARK(BM_SpacetimeSolveBlockLdlt)
    ->Arg(250)
    ->Arg(1000)
    ->Arg(2000)
    ->Unit(benchmark::kMillisecond);

void BM_SpacetimeSolveSparseCholesky(benchmark::State& state) {
  const MeshSequence& seq = Cloth(static_cast<int>(state.range(0)), 10);
  const SparseMatrixD system = AnchoredSystem(seq);
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Ones(system.rows(), 4);
  for (auto _ : state) {
    auto solver = SparseSpdSolver::Factor(system);
    auto x = solver->Solve(rhs);
    benchmark::DoNotOptimize(x->data());
  }
  state.counters["vertices"] = seq.vertex_count();
}
BENCHMARK(BM_SpacetimeSolveSparseCholesky)
    ->Arg(250)
    ->Arg(1000)
    ->Arg(2000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond);

// Spacetime ARAP on a 10-frame window (key frame 5, window 5: frames 0..9 of a 10-frame
// sequence): the cloth's free end (largest x) lifted by 0.1, its pinned edge (smallest x) fixed.
// Time = operator + factorisation + all iterations; the counters report the iterations.
void BM_SpacetimeArap(benchmark::State& state) {
  const MeshSequence& seq = Cloth(static_cast<int>(state.range(0)), 10);
  const FramePositionsD key = seq.frame_d(5);
  const double x_min = key.col(0).minCoeff(), x_max = key.col(0).maxCoeff();
  SpacetimeArapConstraints constraints;
  for (int v = 0; v < seq.vertex_count(); ++v) {
    if (key(v, 0) > x_max - 0.1 * (x_max - x_min)) constraints.handles.push_back(v);
    if (key(v, 0) < x_min + 0.1 * (x_max - x_min)) constraints.fixed.push_back(v);
  }
  Eigen::MatrixXd targets(constraints.handles.size(), 3);
  for (size_t h = 0; h < constraints.handles.size(); ++h) {
    targets.row(static_cast<Eigen::Index>(h)) = key.row(constraints.handles[h]);
  }
  targets.col(2).array() += 0.1;
  SpacetimeArapOptions options;
  options.alpha = static_cast<double>(state.range(1)) / 100.0;
  options.key_frame = 5;
  options.window = 5;
  options.tolerance = 1e-4;
  int iterations = 0;
  bool converged = false;
  for (auto _ : state) {
    auto editor = SpacetimeArapEditor::Create(seq, constraints, options);
    auto result = editor->Solve(targets);
    iterations = result->iterations;
    converged = result->converged;
    benchmark::DoNotOptimize(result->sequence.data());
  }
  state.counters["vertices"] = seq.vertex_count();
  state.counters["frames"] = 10;
  state.counters["alpha"] = options.alpha;
  state.counters["iterations"] = iterations;
  state.counters["converged"] = converged ? 1 : 0;
}
BENCHMARK(BM_SpacetimeArap)
    ->Args({10000, 100})
    ->Args({10000, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace dmc
