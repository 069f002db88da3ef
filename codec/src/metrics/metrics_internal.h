// Building blocks shared by the metric implementations: KG, STED, DistortionMeter (whole
// sequences in memory) and StreamingDistortion (segment by segment). Internal: callers outside
// src/metrics use dmc/metrics.h or metrics/streaming_distortion.h.
//
// Every formula of ../shared/docs/metrics.md is written once, here and in kg.cpp / sted.cpp; the
// in-memory and the streaming measurement differ only in how many frames they hand to the
// Accumulate* functions at a time. Their results are bit for bit equal because every sum is
// formed in one fixed order whatever the segmentation and the thread count:
//  - per-frame sums (STED_s, ‖A − A′‖², ‖A − E(A)‖²) are added to their running total in frame
//    order;
//  - STED_t is summed per block of kTemporalBlock vertices in frame order (each block's sum
//    carries over from one segment to the next), and the block sums are added in block order
//    at the end;
//  - extrema (maximum error, bounding box) do not depend on the order.
//
// Every "Prepare" step depends on the original only and is done once per original; every
// "Accumulate"/"Compute" step is done per distorted sequence (or segment of it) and assumes its
// inputs were already checked (CheckComparable, ValidateSequence, finite coordinates).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dmc/metrics.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc::metrics_internal {

// OK, or kInvalidSequence / kMismatch describing why `distorted` cannot be measured against
// `original` (each named as such in the message).
Status CheckInputs(const MeshSequence& original, const MeshSequence& distorted);

// Consecutive frames of one sequence, V × 3 floats each, stored one after the other from frame
// `first` on. `before_first`, when set, is frame first − 1 stored elsewhere: the streaming
// measurement keeps the previous segment's last decoded frame that way, because STED_t at a
// segment's first frame needs it.
struct FrameWindow {
  const float* data = nullptr;  // frame `first`
  int64_t first = 0;
  int vertex_count = 0;
  const float* before_first = nullptr;

  // Frame f; the caller guarantees that f is held (f >= first, or f == first − 1 with
  // before_first set).
  const float* frame(int64_t f) const {
    if (f < first) return before_first;
    return data + static_cast<size_t>(f - first) * static_cast<size_t>(vertex_count) * 3;
  }
};

// All frames of `sequence`.
inline FrameWindow WholeSequence(const MeshSequence& sequence) {
  return FrameWindow{sequence.data(), 0, sequence.vertex_count(), nullptr};
}

// ---- KG and the vertex-error statistics ----------------------------------------------------

// One frame's share of ‖A − E(A)‖²: Σ_v ‖p(v) − c‖², c the frame's centroid. Two passes
// (centroid, then squared deviations) so that there is no cancellation between Σp² and V·c².
double FrameCentroidDeviationSquared(const float* positions, int vertex_count);

// What KG and the vertex-error statistics need from the original, computed once.
struct KgReference {
  double centroid_deviation_squared = 0.0;  // ‖A − E(A)‖_F²
  double bounding_box_diagonal = 0.0;       // of A over all frames
};

// kInvalidSequence when KG's denominator ‖A − E(A)‖_F is 0 (every frame a single point).
Status CheckKgDefined(double centroid_deviation_squared);

// Requires a valid original. Fails as CheckKgDefined does.
StatusOr<KgReference> PrepareKg(const MeshSequence& original);

// KG = 100 · ‖A − A′‖_F / ‖A − E(A)‖_F from the two squared norms.
double KgFromSums(double squared_error_sum, double centroid_deviation_squared);

// Running vertex-error statistics.
struct VertexErrorSums {
  double squared_sum = 0.0;  // Σ_{f,v} ‖p − p′‖² = ‖A − A′‖_F², added frame by frame
  double largest_squared = 0.0;  // max_{f,v} ‖p − p′‖²
};

// Adds frames [f_begin, f_end) of both windows to `sums` (frame-parallel; per-frame sums are
// added in frame order).
void AccumulateVertexErrors(const FrameWindow& original, const FrameWindow& distorted, int f_begin,
                            int f_end, VertexErrorSums& sums);

// ---- STED ----------------------------------------------------------------------------------

// The STED neighbourhoods N(v) in CSR form: the edge indices of vertex v are
// edge_indices[offsets[v] .. offsets[v+1]), sorted ascending, each edge once.
struct Neighbourhoods {
  std::vector<int64_t> offsets;  // size V + 1
  std::vector<int32_t> edge_indices;
};

// N(v) = every edge with at least one endpoint within `width` one-ring steps of v.
Neighbourhoods BuildNeighbourhoods(const MeshTopology& topology, int width);

// What STED needs from the original, computed once.
struct StedReference {
  StedOptions options;
  int vertex_count = 0;
  std::vector<std::array<int32_t, 2>> edges;  // MeshTopology::edges
  Neighbourhoods neighbourhoods;
  double diameter = 0.0;  // D, diameter of frame 0 of the original
};

// kInvalidSequence when STED_t is undefined: F > 1 and D = 0.
Status CheckStedDefined(int frame_count, double diameter);

// Requires a valid original and valid options. The reference depends on the triangles and
// frame 0 only; it fails as CheckStedDefined(original.frame_count(), D) does.
StatusOr<StedReference> PrepareSted(const MeshSequence& original, const StedOptions& options);

// The speed window half-width s actually used: options.window capped at F (a wider window
// covers the whole sequence anyway, and the cap bounds the per-block ring buffer).
int64_t EffectiveWindow(const StedOptions& options, int frame_count);

// Vertices per block of the temporal part. Fixed (not derived from the thread count) so that
// the order of the partial sums, hence the result, never depends on the machine.
constexpr int kTemporalBlock = 256;

// Running STED sums of one distorted sequence.
struct StedSums {
  double spatial_total = 0.0;               // Σ_f Σ_v dev(v), added in frame order
  std::vector<double> temporal_block_sums;  // per block of kTemporalBlock vertices
};

// Zero sums, one temporal block sum per kTemporalBlock vertices of the reference.
StedSums StartSted(const StedReference& reference);

// Adds frames [f_begin, f_end) of a sequence of `frame_count` frames to `sums`: the spatial
// terms of those frames (frame-parallel) and the temporal terms of frames max(f_begin, 1) ..
// f_end − 1 (vertex-block-parallel). `original` must hold the frames
// [max(0, f_begin − s), min(F, f_end + s)) with s = EffectiveWindow (the local speed s̄ looks s
// frames ahead and te looks one frame back), `distorted` the frames [f_begin, f_end) and, when
// f_begin > 0, frame f_begin − 1.
void AccumulateSted(const StedReference& reference, int frame_count, const FrameWindow& original,
                    const FrameWindow& distorted, int f_begin, int f_end, StedSums& sums);

// STED_s, STED_t and STED from the sums over all `frame_count` frames.
StedResult FinishSted(const StedReference& reference, const StedSums& sums, int frame_count);

// STED of checked whole sequences: StartSted, AccumulateSted over all frames, FinishSted.
StedResult ComputeSted(const StedReference& reference, const MeshSequence& original,
                       const MeshSequence& distorted);

// ---- The full report -----------------------------------------------------------------------

// The DistortionReport of a sequence of `frame_count` × `vertex_count` from the finished STED
// values and the vertex-error sums over all frames.
DistortionReport AssembleReport(const StedResult& sted, const VertexErrorSums& errors,
                                const KgReference& kg, int frame_count, int vertex_count);

}  // namespace dmc::metrics_internal
