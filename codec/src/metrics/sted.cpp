// STED (Váša & Skala 2011) exactly as ../shared/docs/metrics.md defines it; see dmc/metrics.h for
// the definition and the cost model.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

#include "dmc/metrics.h"
#include "metrics/metrics_internal.h"

namespace dmc::metrics_internal {
namespace {

// Per-worker scratch of the neighbourhood search. Stamps equal to the current generation mark
// what the current vertex has already reached, so nothing is cleared between vertices.
struct NeighbourhoodScratch {
  NeighbourhoodScratch(int vertex_count, int edge_count)
      : vertex_stamp(vertex_count, 0), edge_stamp(edge_count, 0) {}
  uint32_t generation = 0;
  std::vector<uint32_t> vertex_stamp;
  std::vector<uint32_t> edge_stamp;
  std::vector<int32_t> layer, next_layer, members;
  std::vector<int32_t> edges;  // the result: N(vertex), sorted
};

// Fills scratch.edges with N(vertex): breadth-first `width` one-ring steps give S_w, then every
// edge incident to a member of S_w is taken once.
void CollectNeighbourhood(const MeshTopology& topology, int width, int vertex,
                          NeighbourhoodScratch& scratch) {
  const uint32_t stamp = ++scratch.generation;
  scratch.members.assign(1, vertex);
  scratch.layer.assign(1, vertex);
  scratch.vertex_stamp[vertex] = stamp;
  for (int step = 0; step < width && !scratch.layer.empty(); ++step) {
    scratch.next_layer.clear();
    for (const int32_t u : scratch.layer) {
      for (int32_t k = topology.ring_offsets[u]; k < topology.ring_offsets[u + 1]; ++k) {
        const int32_t neighbour = topology.ring_neighbors[k];
        if (scratch.vertex_stamp[neighbour] == stamp) continue;
        scratch.vertex_stamp[neighbour] = stamp;
        scratch.next_layer.push_back(neighbour);
        scratch.members.push_back(neighbour);
      }
    }
    std::swap(scratch.layer, scratch.next_layer);
  }
  scratch.edges.clear();
  for (const int32_t u : scratch.members) {
    for (int32_t k = topology.ring_offsets[u]; k < topology.ring_offsets[u + 1]; ++k) {
      const int32_t edge = topology.ring_edges[k];
      if (scratch.edge_stamp[edge] == stamp) continue;
      scratch.edge_stamp[edge] = stamp;
      scratch.edges.push_back(edge);
    }
  }
  // Ascending edge order: deterministic sums and a cache-friendly walk over per-edge arrays.
  std::sort(scratch.edges.begin(), scratch.edges.end());
}

// Per-worker scratch of the spatial part: l(e) and ed(e) of the frame being measured.
struct SpatialScratch {
  std::vector<double> length;
  std::vector<double> relative_difference;
};

double EdgeLength(const float* positions, int32_t i, int32_t j) {
  const double dx = static_cast<double>(positions[3 * i]) - positions[3 * j];
  const double dy = static_cast<double>(positions[3 * i + 1]) - positions[3 * j + 1];
  const double dz = static_cast<double>(positions[3 * i + 2]) - positions[3 * j + 2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Σ_v dev(v) of one frame; `original` and `distorted` point at that frame's positions.
double SpatialFrameSum(const StedReference& reference, const float* original,
                       const float* distorted, SpatialScratch& scratch) {
  const auto& edges = reference.edges;
  const int edge_count = static_cast<int>(edges.size());
  scratch.length.resize(edge_count);
  scratch.relative_difference.resize(edge_count);
  for (int e = 0; e < edge_count; ++e) {
    const double l = EdgeLength(original, edges[e][0], edges[e][1]);
    const double l_distorted = EdgeLength(distorted, edges[e][0], edges[e][1]);
    scratch.length[e] = l;
    // ed = (l − l′)/l. For l = 0 the quotient is NaN or ±infinity and l·ed is NaN either way;
    // storing NaN makes that explicit and poisons avg(v) of every vertex whose N(v) holds e.
    scratch.relative_difference[e] =
        l > 0.0 ? (l - l_distorted) / l : std::numeric_limits<double>::quiet_NaN();
  }
  const auto& offsets = reference.neighbourhoods.offsets;
  const auto& indices = reference.neighbourhoods.edge_indices;
  double frame_sum = 0.0;
  for (int v = 0; v < reference.vertex_count; ++v) {
    const int32_t* begin = indices.data() + offsets[v];
    const int32_t* end = indices.data() + offsets[v + 1];
    double length_sum = 0.0;
    double weighted_sum = 0.0;
    for (const int32_t* e = begin; e != end; ++e) {
      length_sum += scratch.length[*e];
      weighted_sum += scratch.length[*e] * scratch.relative_difference[*e];
    }
    const double average = weighted_sum / length_sum;
    // NaN: a zero-length edge in N(v), or N(v) empty (0/0). The vertex contributes 0.
    if (std::isnan(average)) continue;
    double deviation_sum = 0.0;
    for (const int32_t* e = begin; e != end; ++e) {
      const double l = scratch.length[*e];
      if (l > 0.0) {
        const double centred = scratch.relative_difference[*e] - average;
        deviation_sum += l * centred * centred;
      }
    }
    frame_sum += std::sqrt(deviation_sum / length_sum);
  }
  return frame_sum;
}

// te = sqrt(‖(current − previous) / D‖² + dt²) of one vertex, `current` and `previous` its
// positions in frames f and f − 1.
inline double TemporalEdgeLength(const float* current, const float* previous, double diameter,
                                 double dt) {
  const double x = (static_cast<double>(current[0]) - previous[0]) / diameter;
  const double y = (static_cast<double>(current[1]) - previous[1]) / diameter;
  const double z = (static_cast<double>(current[2]) - previous[2]) / diameter;
  return std::sqrt(x * x + y * y + z * z + dt * dt);
}

// Adds Σ_{f in [f_begin, f_end)} Σ_{v in block} |te′ − te| / s̄ to `block_sum`, f >= 1, for the
// vertices [v_begin, v_end). `ring` holds the te values of A for the frames of the current
// window: frame g lives in slot g mod ring_frames, ring_frames = 2·s covers the window
// [f−s+1, f+s] exactly.
double TemporalBlockSum(const StedReference& reference, int frame_count,
                        const FrameWindow& original, const FrameWindow& distorted, int v_begin,
                        int v_end, int f_begin, int f_end, int64_t window, double block_sum,
                        std::vector<double>& ring) {
  const int block = v_end - v_begin;
  const double diameter = reference.diameter;
  const double dt = reference.options.dt;
  const int64_t ring_frames = 2 * window;
  ring.resize(static_cast<size_t>(ring_frames) * block);
  auto slot = [&](int64_t g) { return ring.data() + static_cast<size_t>(g % ring_frames) * block; };

  // te of A is in the ring for frames [.., computed_up_to]; the first window starts here.
  int64_t computed_up_to = std::max<int64_t>(1, f_begin - window + 1) - 1;
  for (int f = f_begin; f < f_end; ++f) {
    const int64_t first = std::max<int64_t>(1, f - window + 1);
    const int64_t last = std::min<int64_t>(frame_count - 1, f + window);
    for (int64_t g = computed_up_to + 1; g <= last; ++g) {
      const float* current = original.frame(g);
      const float* previous = original.frame(g - 1);
      double* te = slot(g);
      for (int v = v_begin; v < v_end; ++v) {
        te[v - v_begin] = TemporalEdgeLength(current + 3 * v, previous + 3 * v, diameter, dt);
      }
    }
    computed_up_to = std::max(computed_up_to, last);
    const double window_frames = static_cast<double>(last - first + 1);
    const double* te_now = slot(f);
    const float* current = distorted.frame(f);
    const float* previous = distorted.frame(f - 1);
    for (int v = v_begin; v < v_end; ++v) {
      // Summed in frame order, as the definition's mean reads.
      double speed_sum = 0.0;
      for (int64_t g = first; g <= last; ++g) speed_sum += slot(g)[v - v_begin];
      const double local_speed = speed_sum / window_frames;
      const double te_distorted =
          TemporalEdgeLength(current + 3 * v, previous + 3 * v, diameter, dt);
      const double term = std::abs(te_distorted - te_now[v - v_begin]) / local_speed;
      // NaN only when dt = 0 and the vertex rests in both sequences (0/0): no difference.
      if (!std::isnan(term)) block_sum += term;
    }
  }
  return block_sum;
}

}  // namespace

Neighbourhoods BuildNeighbourhoods(const MeshTopology& topology, int width) {
  const int vertex_count = topology.vertex_count;
  const int edge_count = topology.edge_count();
  Neighbourhoods result;
  result.offsets.assign(static_cast<size_t>(vertex_count) + 1, 0);
  auto make_scratch = [&] { return NeighbourhoodScratch(vertex_count, edge_count); };
  // Two passes (sizes, then contents) keep the peak memory at the CSR itself.
  {
    tbb::enumerable_thread_specific<NeighbourhoodScratch> scratches(make_scratch);
    tbb::parallel_for(tbb::blocked_range<int>(0, vertex_count, 512),
                      [&](const tbb::blocked_range<int>& range) {
                        NeighbourhoodScratch& scratch = scratches.local();
                        for (int v = range.begin(); v < range.end(); ++v) {
                          CollectNeighbourhood(topology, width, v, scratch);
                          result.offsets[v + 1] = static_cast<int64_t>(scratch.edges.size());
                        }
                      });
  }
  std::partial_sum(result.offsets.begin(), result.offsets.end(), result.offsets.begin());
  result.edge_indices.resize(static_cast<size_t>(result.offsets.back()));
  tbb::enumerable_thread_specific<NeighbourhoodScratch> scratches(make_scratch);
  tbb::parallel_for(tbb::blocked_range<int>(0, vertex_count, 512),
                    [&](const tbb::blocked_range<int>& range) {
                      NeighbourhoodScratch& scratch = scratches.local();
                      for (int v = range.begin(); v < range.end(); ++v) {
                        CollectNeighbourhood(topology, width, v, scratch);
                        std::copy(scratch.edges.begin(), scratch.edges.end(),
                                  result.edge_indices.begin() + result.offsets[v]);
                      }
                    });
  return result;
}

Status CheckStedDefined(int frame_count, double diameter) {
  if (frame_count > 1 && !(diameter > 0.0)) {
    return InvalidSequenceError(
        "STED_t is undefined: frame 0 of the original is a single point (diameter D = 0)");
  }
  return Status::Ok();
}

StatusOr<StedReference> PrepareSted(const MeshSequence& original, const StedOptions& options) {
  StedReference reference;
  reference.options = options;
  reference.vertex_count = original.vertex_count();
  MeshTopology topology = BuildTopology(original.triangles(), original.vertex_count());
  reference.neighbourhoods = BuildNeighbourhoods(topology, options.width);
  reference.edges = std::move(topology.edges);
  reference.diameter = PointSetDiameter(original.frame(0));
  DMC_RETURN_IF_ERROR(CheckStedDefined(original.frame_count(), reference.diameter));
  return reference;
}

int64_t EffectiveWindow(const StedOptions& options, int frame_count) {
  return std::min<int64_t>(options.window, frame_count);
}

StedSums StartSted(const StedReference& reference) {
  StedSums sums;
  sums.temporal_block_sums.assign((reference.vertex_count + kTemporalBlock - 1) / kTemporalBlock,
                                  0.0);
  return sums;
}

void AccumulateSted(const StedReference& reference, int frame_count, const FrameWindow& original,
                    const FrameWindow& distorted, int f_begin, int f_end, StedSums& sums) {
  const int vertex_count = reference.vertex_count;

  // Spatial part: frame-parallel, one Σ_v dev(v) per frame, added up in frame order.
  const int count = f_end - f_begin;
  std::vector<double> frame_sums(count, 0.0);
  tbb::enumerable_thread_specific<SpatialScratch> spatial_scratches;
  tbb::parallel_for(tbb::blocked_range<int>(0, count), [&](const tbb::blocked_range<int>& range) {
    SpatialScratch& scratch = spatial_scratches.local();
    for (int i = range.begin(); i < range.end(); ++i) {
      frame_sums[i] = SpatialFrameSum(reference, original.frame(f_begin + i),
                                      distorted.frame(f_begin + i), scratch);
    }
  });
  for (const double frame_sum : frame_sums) sums.spatial_total += frame_sum;

  // Temporal part (frames >= 1): vertex-block-parallel, each block sweeping the frames with its
  // ring buffer and continuing its own running sum.
  const int temporal_begin = std::max(f_begin, 1);
  if (temporal_begin >= f_end) return;
  const int64_t window = EffectiveWindow(reference.options, frame_count);
  const int block_count = static_cast<int>(sums.temporal_block_sums.size());
  tbb::enumerable_thread_specific<std::vector<double>> rings;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, block_count, 1), [&](const tbb::blocked_range<int>& range) {
        std::vector<double>& ring = rings.local();
        for (int b = range.begin(); b < range.end(); ++b) {
          const int v_begin = b * kTemporalBlock;
          const int v_end = std::min(vertex_count, v_begin + kTemporalBlock);
          sums.temporal_block_sums[b] =
              TemporalBlockSum(reference, frame_count, original, distorted, v_begin, v_end,
                               temporal_begin, f_end, window, sums.temporal_block_sums[b], ring);
        }
      });
}

StedResult FinishSted(const StedReference& reference, const StedSums& sums, int frame_count) {
  const double vertex_count = reference.vertex_count;
  StedResult result;
  result.sted_s = sums.spatial_total / (vertex_count * frame_count);
  if (frame_count > 1) {
    const double temporal_total =
        std::accumulate(sums.temporal_block_sums.begin(), sums.temporal_block_sums.end(), 0.0);
    result.sted_t = temporal_total / (vertex_count * (frame_count - 1));
  }
  const double c = reference.options.c;
  result.sted = std::sqrt(result.sted_s * result.sted_s + c * c * result.sted_t * result.sted_t);
  return result;
}

StedResult ComputeSted(const StedReference& reference, const MeshSequence& original,
                       const MeshSequence& distorted) {
  const int frame_count = original.frame_count();
  StedSums sums = StartSted(reference);
  AccumulateSted(reference, frame_count, WholeSequence(original), WholeSequence(distorted), 0,
                 frame_count, sums);
  return FinishSted(reference, sums, frame_count);
}

}  // namespace dmc::metrics_internal

namespace dmc {

StatusOr<StedResult> Sted(const MeshSequence& original, const MeshSequence& distorted,
                          const StedOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateStedOptions(options));
  DMC_RETURN_IF_ERROR(metrics_internal::CheckInputs(original, distorted));
  DMC_ASSIGN_OR_RETURN(const metrics_internal::StedReference reference,
                       metrics_internal::PrepareSted(original, options));
  return metrics_internal::ComputeSted(reference, original, distorted);
}

}  // namespace dmc
