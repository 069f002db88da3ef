// The geometric and combinatorial weight formulas, the builders of the non-fitted operators, and
// the rebuild of an operator from its wire ID (dmc_operators; decoder side). Sign convention and
// weight layouts: dmc/laplace_operator.h.
//
//   name        weights w_ij                               symmetric  diagonal L_ii
//   kirchhoff   1                                          yes        −deg(i)
//   tutte       1/deg(i)                                   no         −1 (unit sum)
//   cotan       k_ij / Σ_j k_ij                            no         −1 (unit sum)
//   cotan-area  k_ij / A_i  (mixed Voronoi area A_i)       no         −Σ_j k_ij / A_i
//   cotan-sym   k_ij                                       yes        −Σ_j k_ij
//   mean-value  Floater's weights / their row sum          no         −1 (unit sum)
//   ddl         fitted, one per edge, rows unit sum        yes        −1 (unit sum)
//   ddl-asym    fitted, one per directed edge, unit sum    no         −1 (unit sum)
//
// with k_ij = (cot α_ij + cot β_ij)/2 over the (one or two) angles opposite edge ij. Isolated
// vertices (no edge) have an all-zero row everywhere, so "unit sum" holds on every other row.
// cotan-area applied to positions approximates the mean-curvature normal: δ_i ≈ −2 H_i n_i, so on
// a sphere of radius R, ‖δ_i‖/2 ≈ 1/R. The mass matrix (diagonal, mixed Voronoi areas) is
// provided by the cotangent operators only; M⁻¹·(cotan-sym) = cotan-area.
//
// Robustness of the geometric formulas: cotangents are clamped to ±GeometricOptions::max_cotangent
// (default cot 1° ≈ 57.29), zero-area triangles contribute nothing to areas and their angles are
// clamped, rows whose normalising sum is not safely positive fall back to Tutte weights, and every
// such repair is counted in OperatorStats. No formula ever produces NaN or infinity from finite
// input positions.
#pragma once

#include <string_view>
#include <vector>

#include "dmc/laplace_operator.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"
#include "dmc/wire_ids.h"

namespace dmc {

struct GeometricOptions {
  // Cotangents are clamped to [−max_cotangent, max_cotangent]. The default, cot(1°) ≈ 57.29,
  // only touches angles below 1° or above 179° (slivers); the count is reported.
  double max_cotangent = 57.289961630759425;
  // A row whose normalising sum (Σ k_ij for cotan, Σ of mean-value weights) is below
  // min_row_sum_ratio × Σ |k_ij| is treated as degenerate and replaced by the Tutte row.
  double min_row_sum_ratio = 1e-6;
};

// Per-edge k_ij = (cot α_ij + cot β_ij)/2 (one term on boundary edges), clamped as above.
// `positions` is V×3. `stats` (may be null) receives clamping counts.
std::vector<double> CotangentEdgeWeights(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options = {},
                                         OperatorStats* stats = nullptr);

// Mixed Voronoi vertex areas (Meyer et al. 2003): the Voronoi region inside non-obtuse
// triangles, and area/2 (obtuse corner) or area/4 (other corners) inside obtuse ones. Each
// triangle is visited through the topology's edge/opposite table, so triangles beyond the
// second on a non-manifold edge are not counted.
// Degenerate (zero-area) triangles contribute nothing.
Eigen::VectorXd MixedVoronoiAreas(const MeshTopology& topology, const FramePositionsD& positions);

// Floater's mean value weights per directed edge, not yet normalised:
// w_ij = (tan(α⁻/2) + tan(α⁺/2)) / ‖x_j − x_i‖ with α± the angles at i of the triangles on edge
// ij, tan(α/2) capped at max_cotangent. Non-negative; edges of (near) zero length use a floored
// length.
std::vector<double> MeanValueDirectedWeights(const MeshTopology& topology,
                                             const FramePositionsD& positions,
                                             const GeometricOptions& options = {},
                                             OperatorStats* stats = nullptr);

// Directed Tutte weights 1/deg(i); the reference the DDL regulariser pulls toward by default.
std::vector<double> TutteDirectedWeights(const MeshTopology& topology);

// Scales each row of directed weights to unit sum. Rows whose sum is ≤ min_row_sum_ratio × Σ|w|
// get Tutte weights instead (counted in stats->fallback_rows).
void NormalizeRowsToUnitSum(const MeshTopology& topology, std::vector<double>& directed,
                            double min_row_sum_ratio, OperatorStats* stats);

// Builders of the non-fitted operators. Geometric ones take one frame of positions (V×3); for a
// sequence pass a reference frame such as MeanFrame(). Fail with kMismatch on a size mismatch.
StatusOr<LaplaceOperator> BuildKirchhoff(const MeshTopology& topology);
StatusOr<LaplaceOperator> BuildTutte(const MeshTopology& topology);
StatusOr<LaplaceOperator> BuildCotan(const MeshTopology& topology, const FramePositionsD& positions,
                                     const GeometricOptions& options = {});
StatusOr<LaplaceOperator> BuildCotanArea(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options = {});
StatusOr<LaplaceOperator> BuildCotanSym(const MeshTopology& topology,
                                        const FramePositionsD& positions,
                                        const GeometricOptions& options = {});
StatusOr<LaplaceOperator> BuildMeanValue(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options = {});

// What a decoder needs to rebuild the operator a stream names: combinatorial operators need
// nothing, geometric ones `reference_frame` (V×3), DDL ones `weights` in their layout (kPerEdge
// for kDdl, kPerDirectedEdge for kDdlAsym). Missing input → kInvalidArgument; unknown ID →
// kNotFound listing the known IDs.
StatusOr<LaplaceOperator> RebuildOperator(OperatorId id, const MeshTopology& topology,
                                          const FramePositionsD* reference_frame,
                                          const OperatorWeights* weights);

// Registry name of a wire ID ("ddl"), or "" for an unknown ID.
std::string_view OperatorIdName(OperatorId id);

// Mean over frames of every vertex position (V×3, double).
FramePositionsD MeanFrame(const MeshSequence& sequence);

}  // namespace dmc
