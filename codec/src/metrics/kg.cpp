// KG error (Karni–Gotsman) and the per-vertex error statistics; see dmc/metrics.h.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "dmc/metrics.h"
#include "metrics/metrics_internal.h"

namespace dmc::metrics_internal {

StatusOr<KgReference> PrepareKg(const MeshSequence& original) {
  const int frame_count = original.frame_count();
  const int vertex_count = original.vertex_count();
  // ‖A − E(A)‖² frame by frame: centroid first, then squared deviations (two passes, so no
  // cancellation between Σp² and V·c²). Per-frame sums are added in frame order.
  std::vector<double> frame_sums(frame_count, 0.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, frame_count), [&](const tbb::blocked_range<int>& r) {
    for (int f = r.begin(); f < r.end(); ++f) {
      const auto positions = original.frame(f);
      double centroid[3] = {0.0, 0.0, 0.0};
      for (int v = 0; v < vertex_count; ++v) {
        for (int k = 0; k < 3; ++k) centroid[k] += positions(v, k);
      }
      for (double& coordinate : centroid) coordinate /= vertex_count;
      double sum = 0.0;
      for (int v = 0; v < vertex_count; ++v) {
        for (int k = 0; k < 3; ++k) {
          const double deviation = positions(v, k) - centroid[k];
          sum += deviation * deviation;
        }
      }
      frame_sums[f] = sum;
    }
  });
  KgReference reference;
  reference.centroid_deviation_squared = std::accumulate(frame_sums.begin(), frame_sums.end(), 0.0);
  if (!(reference.centroid_deviation_squared > 0.0)) {
    return InvalidSequenceError(
        "KG error is undefined: every frame of the original is a single point (||A - E(A)|| = 0)");
  }
  reference.bounding_box_diagonal = ComputeBoundingBox(original).diagonal();
  return reference;
}

VertexErrorStats ComputeVertexErrors(const MeshSequence& original, const MeshSequence& distorted) {
  const int frame_count = original.frame_count();
  const int vertex_count = original.vertex_count();
  std::vector<double> frame_sums(frame_count, 0.0);
  std::vector<double> frame_max(frame_count, 0.0);  // largest squared error per frame
  tbb::parallel_for(tbb::blocked_range<int>(0, frame_count), [&](const tbb::blocked_range<int>& r) {
    for (int f = r.begin(); f < r.end(); ++f) {
      const auto a = original.frame(f);
      const auto b = distorted.frame(f);
      double sum = 0.0;
      double largest = 0.0;
      for (int v = 0; v < vertex_count; ++v) {
        const double dx = static_cast<double>(a(v, 0)) - b(v, 0);
        const double dy = static_cast<double>(a(v, 1)) - b(v, 1);
        const double dz = static_cast<double>(a(v, 2)) - b(v, 2);
        const double squared = dx * dx + dy * dy + dz * dz;
        sum += squared;
        largest = std::max(largest, squared);
      }
      frame_sums[f] = sum;
      frame_max[f] = largest;
    }
  });
  VertexErrorStats stats;
  stats.squared_sum = std::accumulate(frame_sums.begin(), frame_sums.end(), 0.0);
  stats.max_error = std::sqrt(*std::max_element(frame_max.begin(), frame_max.end()));
  return stats;
}

}  // namespace dmc::metrics_internal

namespace dmc {

StatusOr<double> KgError(const MeshSequence& original, const MeshSequence& distorted) {
  DMC_RETURN_IF_ERROR(metrics_internal::CheckInputs(original, distorted));
  DMC_ASSIGN_OR_RETURN(const metrics_internal::KgReference reference,
                       metrics_internal::PrepareKg(original));
  const metrics_internal::VertexErrorStats errors =
      metrics_internal::ComputeVertexErrors(original, distorted);
  return 100.0 * std::sqrt(errors.squared_sum) / std::sqrt(reference.centroid_deviation_squared);
}

}  // namespace dmc
