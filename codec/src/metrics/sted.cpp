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

// Per-worker scratch of the spatial part: l(e) and l(e)·ed(e) of the frame being measured.
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
  const int vertex_count = static_cast<int>(offsets.size()) - 1;
  double frame_sum = 0.0;
  for (int v = 0; v < vertex_count; ++v) {
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

// Vertices per task of the temporal part. Fixed (not derived from the thread count) so that the
// order of the partial sums, hence the result, never depends on the machine.
constexpr int kTemporalBlock = 256;

// te(f, v) = sqrt(‖(p(f,v) − p(f−1,v)) / D‖² + dt²) of one sequence; f >= 1.
inline double TemporalEdgeLength(const MeshSequence& sequence, int f, int v, double diameter,
                                 double dt) {
  const float* current =
      sequence.data() + (static_cast<size_t>(f) * sequence.vertex_count() + v) * 3;
  const float* previous = current - static_cast<size_t>(sequence.vertex_count()) * 3;
  const double x = (static_cast<double>(current[0]) - previous[0]) / diameter;
  const double y = (static_cast<double>(current[1]) - previous[1]) / diameter;
  const double z = (static_cast<double>(current[2]) - previous[2]) / diameter;
  return std::sqrt(x * x + y * y + z * z + dt * dt);
}

// Σ_{f>=1} Σ_{v in block} |te′ − te| / s̄ for the vertices [v_begin, v_end). `ring` holds the te
// values of A for the frames of the current window: frame g lives in slot g mod ring_frames,
// ring_frames = 2·s covers the window [f−s+1, f+s] exactly.
double TemporalBlockSum(const StedReference& reference, const MeshSequence& original,
                        const MeshSequence& distorted, int v_begin, int v_end, int64_t window,
                        int64_t ring_frames, std::vector<double>& ring) {
  const int frame_count = original.frame_count();
  const int block = v_end - v_begin;
  const double diameter = reference.diameter;
  const double dt = reference.options.dt;
  ring.resize(static_cast<size_t>(ring_frames) * block);
  auto slot = [&](int64_t g) { return ring.data() + static_cast<size_t>(g % ring_frames) * block; };

  double block_sum = 0.0;
  int64_t computed_up_to = 0;  // te of A is in the ring for frames (.., computed_up_to]
  for (int f = 1; f < frame_count; ++f) {
    const int64_t first = std::max<int64_t>(1, f - window + 1);
    const int64_t last = std::min<int64_t>(frame_count - 1, f + window);
    for (int64_t g = computed_up_to + 1; g <= last; ++g) {
      double* te = slot(g);
      for (int v = v_begin; v < v_end; ++v) {
        te[v - v_begin] = TemporalEdgeLength(original, static_cast<int>(g), v, diameter, dt);
      }
    }
    computed_up_to = std::max(computed_up_to, last);
    const double window_frames = static_cast<double>(last - first + 1);
    const double* te_now = slot(f);
    for (int v = v_begin; v < v_end; ++v) {
      // Summed in frame order, as the definition's mean reads.
      double speed_sum = 0.0;
      for (int64_t g = first; g <= last; ++g) speed_sum += slot(g)[v - v_begin];
      const double local_speed = speed_sum / window_frames;
      const double te_distorted = TemporalEdgeLength(distorted, f, v, diameter, dt);
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

StatusOr<StedReference> PrepareSted(const MeshSequence& original, const StedOptions& options) {
  StedReference reference;
  reference.options = options;
  MeshTopology topology = BuildTopology(original.triangles(), original.vertex_count());
  reference.neighbourhoods = BuildNeighbourhoods(topology, options.width);
  reference.edges = std::move(topology.edges);
  reference.diameter = PointSetDiameter(original.frame(0));
  if (original.frame_count() > 1 && !(reference.diameter > 0.0)) {
    return InvalidSequenceError(
        "STED_t is undefined: frame 0 of the original is a single point (diameter D = 0)");
  }
  return reference;
}

StedResult ComputeSted(const StedReference& reference, const MeshSequence& original,
                       const MeshSequence& distorted) {
  const int frame_count = original.frame_count();
  const int vertex_count = original.vertex_count();
  const size_t frame_stride = static_cast<size_t>(vertex_count) * 3;
  StedResult result;

  // Spatial part: frame-parallel, one Σ_v dev(v) per frame, added up in frame order.
  std::vector<double> frame_sums(frame_count, 0.0);
  tbb::enumerable_thread_specific<SpatialScratch> spatial_scratches;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, frame_count), [&](const tbb::blocked_range<int>& range) {
        SpatialScratch& scratch = spatial_scratches.local();
        for (int f = range.begin(); f < range.end(); ++f) {
          frame_sums[f] = SpatialFrameSum(reference, original.data() + f * frame_stride,
                                          distorted.data() + f * frame_stride, scratch);
        }
      });
  const double spatial_total = std::accumulate(frame_sums.begin(), frame_sums.end(), 0.0);
  result.sted_s = spatial_total / (static_cast<double>(vertex_count) * frame_count);

  // Temporal part: vertex-block-parallel, each block sweeping the frames with its ring buffer.
  if (frame_count > 1) {
    // A window wider than the sequence covers it all; capping it bounds the ring buffer.
    const int64_t window = std::min<int64_t>(reference.options.window, frame_count);
    const int64_t ring_frames = 2 * window;
    const int block_count = (vertex_count + kTemporalBlock - 1) / kTemporalBlock;
    std::vector<double> block_sums(block_count, 0.0);
    tbb::enumerable_thread_specific<std::vector<double>> rings;
    tbb::parallel_for(tbb::blocked_range<int>(0, block_count, 1),
                      [&](const tbb::blocked_range<int>& range) {
                        std::vector<double>& ring = rings.local();
                        for (int b = range.begin(); b < range.end(); ++b) {
                          const int v_begin = b * kTemporalBlock;
                          const int v_end = std::min(vertex_count, v_begin + kTemporalBlock);
                          block_sums[b] = TemporalBlockSum(reference, original, distorted, v_begin,
                                                           v_end, window, ring_frames, ring);
                        }
                      });
    const double temporal_total = std::accumulate(block_sums.begin(), block_sums.end(), 0.0);
    result.sted_t = temporal_total / (static_cast<double>(vertex_count) * (frame_count - 1));
  }

  const double c = reference.options.c;
  result.sted = std::sqrt(result.sted_s * result.sted_s + c * c * result.sted_t * result.sted_t);
  return result;
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
