// Building blocks shared by the metric implementations (KG, STED, DistortionMeter). Internal:
// callers outside src/metrics use dmc/metrics.h.
//
// Every "Prepare" step depends on the original only and is done once per original; every
// "Compute" step is done once per distorted sequence and assumes its inputs were already checked
// (CheckComparable, ValidateSequence).
#pragma once

#include <array>
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
  std::vector<std::array<int32_t, 2>> edges;  // MeshTopology::edges
  Neighbourhoods neighbourhoods;
  double diameter = 0.0;  // D, diameter of frame 0 of the original
};

// Requires a valid original and valid options. Fails with kInvalidSequence when F > 1 and D = 0.
StatusOr<StedReference> PrepareSted(const MeshSequence& original, const StedOptions& options);

// STED of checked inputs.
StedResult ComputeSted(const StedReference& reference, const MeshSequence& original,
                       const MeshSequence& distorted);

// What KG and the vertex-error statistics need from the original, computed once.
struct KgReference {
  double centroid_deviation_squared = 0.0;  // ‖A − E(A)‖_F²
  double bounding_box_diagonal = 0.0;       // of A over all frames
};

// Requires a valid original. Fails with kInvalidSequence when ‖A − E(A)‖_F = 0.
StatusOr<KgReference> PrepareKg(const MeshSequence& original);

struct VertexErrorStats {
  double squared_sum = 0.0;  // Σ_{f,v} ‖p − p′‖² = ‖A − A′‖_F²
  double max_error = 0.0;    // max_{f,v} ‖p − p′‖
};

// Per-vertex error statistics of checked inputs.
VertexErrorStats ComputeVertexErrors(const MeshSequence& original, const MeshSequence& distorted);

}  // namespace dmc::metrics_internal
