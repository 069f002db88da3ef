// The restricted B-spline operator (dmc/bspline.h): setup time against the triangle count N and
// the depth d (the paper's O(N·d): clipping, exact cubature and assembly of every level), one
// multigrid W-cycle on a 100k-triangle mesh at depth 7, the spectrum at depth 5, and the operator
// registry's "bspline" row (one level, no hierarchy).
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <utility>

#include "dmc/bspline.h"
#include "dmc/operators.h"
#include "dmc/topology.h"
#include "synth/shapes.h"

namespace dmc {
namespace {

// Geodesic unit spheres: T = 20·frequency² triangles (frequency 71 → 100 820).
const synth::RestMesh& Sphere(int frequency) {
  static std::map<int, std::unique_ptr<synth::RestMesh>> cache;
  auto& slot = cache[frequency];
  if (!slot) slot = std::make_unique<synth::RestMesh>(synth::BuildGeodesicSphere(frequency));
  return *slot;
}

const BsplineOperator& Operator(int frequency, int depth) {
  static std::map<std::pair<int, int>, std::unique_ptr<BsplineOperator>> cache;
  auto& slot = cache[{frequency, depth}];
  if (!slot) {
    BsplineOptions options;
    options.depth = depth;
    const synth::RestMesh& mesh = Sphere(frequency);
    slot = std::make_unique<BsplineOperator>(
        *BuildBsplineOperator(mesh.triangles, mesh.positions, options));
  }
  return *slot;
}

// Args: geodesic frequency, depth. Counters: triangles, finest dimension, pieces per level sum.
void BM_BsplineSetup(benchmark::State& state) {
  const synth::RestMesh& mesh = Sphere(static_cast<int>(state.range(0)));
  BsplineOptions options;
  options.depth = static_cast<int>(state.range(1));
  int dimension = 0;
  int64_t pieces = 0;
  for (auto _ : state) {
    auto op = BuildBsplineOperator(mesh.triangles, mesh.positions, options);
    dimension = op->dimension();
    pieces = 0;
    for (const BsplineLevel& level : op->levels) pieces += level.pieces;
    benchmark::DoNotOptimize(op);
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.rows());
  state.counters["dimension"] = dimension;
  state.counters["pieces"] = static_cast<double>(pieces);
}
BENCHMARK(BM_BsplineSetup)
    ->ArgsProduct({{16, 32, 71}, {5, 6, 7}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One W-cycle of the screened system −L + D on the 100k-triangle sphere.
void BM_BsplineWCycle(benchmark::State& state) {
  const BsplineOperator& op = Operator(71, static_cast<int>(state.range(0)));
  const auto multigrid = BsplineMultigrid::Create(op, 1.0, 1.0);
  const Eigen::MatrixXd x = op.positions.col(0);
  const Eigen::VectorXd rhs = IntegrateValueLoad(op, x)->col(0);
  MultigridOptions options;
  options.cycle = MultigridCycle::kW;
  Eigen::VectorXd solution = Eigen::VectorXd::Zero(rhs.size());
  for (auto _ : state) {
    multigrid->Cycle(rhs, solution, options);
    benchmark::DoNotOptimize(solution.data());
  }
  state.counters["dimension"] = op.dimension();
  state.counters["levels"] = multigrid->level_count();
}
BENCHMARK(BM_BsplineWCycle)->Arg(7)->Unit(benchmark::kMillisecond)->UseRealTime();

// The first 16 eigenpairs at depth 5 (the paper's spectral setting) on a 20k-triangle sphere.
void BM_BsplineSpectrum(benchmark::State& state) {
  const BsplineOperator& op = Operator(32, 5);
  for (auto _ : state) {
    auto spectrum = ComputeBsplineSpectrum(op, 16);
    benchmark::DoNotOptimize(spectrum);
  }
  state.counters["dimension"] = op.dimension();
}
BENCHMARK(BM_BsplineSpectrum)->Unit(benchmark::kMillisecond)->UseRealTime();

// The registry row at one depth on the 100k-triangle sphere: what `dmc laplacian --operator
// bspline --depth D` builds (finest level only, plus the vertex evaluation matrix).
void BM_BsplineRegistryRow(benchmark::State& state) {
  const synth::RestMesh& mesh = Sphere(71);
  const MeshTopology topology =
      BuildTopology(mesh.triangles, static_cast<int>(mesh.positions.rows()));
  const OperatorSource source = SourceFromFrame(mesh.positions);
  OperatorOptions options;
  options.allow_any_domain = true;
  options.bspline.depth = static_cast<int>(state.range(0));
  Eigen::Index dimension = 0;
  for (auto _ : state) {
    auto op = BuildOperator("bspline", topology, source, options);
    dimension = op->matrix.rows();
    benchmark::DoNotOptimize(op->matrix.valuePtr());
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.rows());
  state.counters["dimension"] = static_cast<double>(dimension);
}
BENCHMARK(BM_BsplineRegistryRow)->Arg(5)->Arg(7)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace dmc
