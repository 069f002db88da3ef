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

double FrameCentroidDeviationSquared(const float* positions, int vertex_count) {
  double centroid[3] = {0.0, 0.0, 0.0};
  for (int v = 0; v < vertex_count; ++v) {
    for (int k = 0; k < 3; ++k) centroid[k] += positions[3 * v + k];
  }
  for (double& coordinate : centroid) coordinate /= vertex_count;
  double sum = 0.0;
  for (int v = 0; v < vertex_count; ++v) {
    for (int k = 0; k < 3; ++k) {
      const double deviation = positions[3 * v + k] - centroid[k];
      sum += deviation * deviation;
    }
  }
  return sum;
}

Status CheckKgDefined(double centroid_deviation_squared) {
  if (!(centroid_deviation_squared > 0.0)) {
    return InvalidSequenceError(
        "KG error is undefined: every frame of the original is a single point (||A - E(A)|| = 0)");
  }
  return Status::Ok();
}

StatusOr<KgReference> PrepareKg(const MeshSequence& original) {
  const int frame_count = original.frame_count();
  const int vertex_count = original.vertex_count();
  const FrameWindow frames = WholeSequence(original);
  // ‖A − E(A)‖² frame by frame, frame-parallel; the per-frame sums are added in frame order.
  std::vector<double> frame_sums(frame_count, 0.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, frame_count), [&](const tbb::blocked_range<int>& r) {
    for (int f = r.begin(); f < r.end(); ++f) {
      frame_sums[f] = FrameCentroidDeviationSquared(frames.frame(f), vertex_count);
    }
  });
  KgReference reference;
  reference.centroid_deviation_squared = std::accumulate(frame_sums.begin(), frame_sums.end(), 0.0);
  DMC_RETURN_IF_ERROR(CheckKgDefined(reference.centroid_deviation_squared));
  reference.bounding_box_diagonal = ComputeBoundingBox(original).diagonal();
  return reference;
}

double KgFromSums(double squared_error_sum, double centroid_deviation_squared) {
  return 100.0 * std::sqrt(squared_error_sum) / std::sqrt(centroid_deviation_squared);
}

void AccumulateVertexErrors(const FrameWindow& original, const FrameWindow& distorted, int f_begin,
                            int f_end, VertexErrorSums& sums) {
  const int vertex_count = original.vertex_count;
  const int count = f_end - f_begin;
  std::vector<double> frame_sums(count, 0.0);
  std::vector<double> frame_max(count, 0.0);  // largest squared error per frame
  tbb::parallel_for(tbb::blocked_range<int>(0, count), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const float* a = original.frame(f_begin + i);
      const float* b = distorted.frame(f_begin + i);
      double sum = 0.0;
      double largest = 0.0;
      for (int v = 0; v < vertex_count; ++v) {
        const double dx = static_cast<double>(a[3 * v]) - b[3 * v];
        const double dy = static_cast<double>(a[3 * v + 1]) - b[3 * v + 1];
        const double dz = static_cast<double>(a[3 * v + 2]) - b[3 * v + 2];
        const double squared = dx * dx + dy * dy + dz * dz;
        sum += squared;
        largest = std::max(largest, squared);
      }
      frame_sums[i] = sum;
      frame_max[i] = largest;
    }
  });
  for (int i = 0; i < count; ++i) {
    sums.squared_sum += frame_sums[i];
    sums.largest_squared = std::max(sums.largest_squared, frame_max[i]);
  }
}

}  // namespace dmc::metrics_internal

namespace dmc {

StatusOr<double> KgError(const MeshSequence& original, const MeshSequence& distorted) {
  DMC_RETURN_IF_ERROR(metrics_internal::CheckInputs(original, distorted));
  DMC_ASSIGN_OR_RETURN(const metrics_internal::KgReference reference,
                       metrics_internal::PrepareKg(original));
  metrics_internal::VertexErrorSums errors;
  metrics_internal::AccumulateVertexErrors(metrics_internal::WholeSequence(original),
                                           metrics_internal::WholeSequence(distorted), 0,
                                           original.frame_count(), errors);
  return metrics_internal::KgFromSums(errors.squared_sum, reference.centroid_deviation_squared);
}

}  // namespace dmc
