// Speed of the distortion metrics on a 10k-vertex × 150-frame synthetic pair (the encoder measures
// every encode, so STED must stay well under a second on 2 cores), and of the exact diameter on
// 200k points.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <utility>

#include "dmc/metrics.h"
#include "synth/grid_triangles.h"

namespace dmc {
namespace {

constexpr int kSide = 100;  // 100 × 100 = 10k vertices
constexpr int kFrames = 150;

// A 100×100 grid sheet waving smoothly over 150 frames, and a copy with small noise added.
const std::pair<MeshSequence, MeshSequence>& WavingSheetPair() {
  static const std::pair<MeshSequence, MeshSequence> pair = [] {
    const Triangles tris = synth::GridTriangles(kSide, kSide, synth::GridDiagonals::kUniform);
    MeshSequence original(kSide * kSide, tris, kFrames);
    MeshSequence distorted(kSide * kSide, tris, kFrames);
    std::mt19937 rng(1);
    std::normal_distribution<float> noise(0.0f, 1e-3f);
    for (int f = 0; f < kFrames; ++f) {
      const double time = 2.0 * std::numbers::pi * f / kFrames;
      for (int v = 0; v < kSide * kSide; ++v) {
        const double x = static_cast<double>(v % kSide) / (kSide - 1);
        const double y = static_cast<double>(v / kSide) / (kSide - 1);
        const double z = 0.1 * std::sin(6.0 * x + time) * std::cos(4.0 * y - 0.5 * time);
        original.frame(f).row(v) << static_cast<float>(x + 0.2 * time), static_cast<float>(y),
            static_cast<float>(z);
        for (int k = 0; k < 3; ++k) {
          distorted.frame(f)(v, k) = original.frame(f)(v, k) + noise(rng);
        }
      }
    }
    return std::make_pair(std::move(original), std::move(distorted));
  }();
  return pair;
}

void SetCounters(benchmark::State& state) {
  state.counters["vertex_frames"] = benchmark::Counter(
      static_cast<double>(kSide) * kSide * kFrames * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}

void BM_Sted(benchmark::State& state) {
  const auto& [original, distorted] = WavingSheetPair();
  for (auto _ : state) {
    auto result = Sted(original, distorted);
    benchmark::DoNotOptimize(result);
  }
  SetCounters(state);
}
BENCHMARK(BM_Sted)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_KgError(benchmark::State& state) {
  const auto& [original, distorted] = WavingSheetPair();
  for (auto _ : state) {
    auto result = KgError(original, distorted);
    benchmark::DoNotOptimize(result);
  }
  SetCounters(state);
}
BENCHMARK(BM_KgError)->Unit(benchmark::kMillisecond)->UseRealTime();

// KG + STED + RMSE + max error, including the per-original preparation.
void BM_MeasureDistortion(benchmark::State& state) {
  const auto& [original, distorted] = WavingSheetPair();
  for (auto _ : state) {
    auto result = MeasureDistortion(original, distorted);
    benchmark::DoNotOptimize(result);
  }
  SetCounters(state);
}
BENCHMARK(BM_MeasureDistortion)->Unit(benchmark::kMillisecond)->UseRealTime();

// The encoder's closed loop: the original is prepared once, each candidate is measured.
void BM_DistortionMeterMeasure(benchmark::State& state) {
  const auto& [original, distorted] = WavingSheetPair();
  const auto meter = DistortionMeter::Create(original);
  if (!meter.ok()) {
    state.SkipWithError(meter.status().ToString().c_str());
    return;
  }
  for (auto _ : state) {
    auto result = meter->Measure(distorted);
    benchmark::DoNotOptimize(result);
  }
  SetCounters(state);
}
BENCHMARK(BM_DistortionMeterMeasure)->Unit(benchmark::kMillisecond)->UseRealTime();

// 200k points on a sphere: every point is on the hull and near-antipodal pairs abound, the
// worst case of the pruned search. Argument 1 squashes it into an ellipsoid (a typical,
// elongated shape).
void BM_PointSetDiameter(benchmark::State& state) {
  const bool elongated = state.range(0) != 0;
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  FramePositions points(200000, 3);
  for (int i = 0; i < points.rows(); ++i) {
    Eigen::Vector3d p(g(rng), g(rng), g(rng));
    p.normalize();
    if (elongated) p = p.cwiseProduct(Eigen::Vector3d(0.3, 1.8, 0.5));
    points.row(i) = p.cast<float>().transpose();
  }
  for (auto _ : state) benchmark::DoNotOptimize(PointSetDiameter(points));
}
BENCHMARK(BM_PointSetDiameter)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace dmc
