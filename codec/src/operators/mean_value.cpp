// Floater's mean value weights: positive for star-shaped one-rings and linearly precise in the
// plane, normalised to unit row sum.
#include <string>

#include "dmc/operator_formulas.h"
#include "operators/triangle_corners.h"

namespace dmc {

using operators_internal::ForEachCorner;
using operators_internal::Position;

std::vector<double> MeanValueDirectedWeights(const MeshTopology& topology,
                                             const FramePositionsD& positions,
                                             const GeometricOptions& options,
                                             OperatorStats* stats) {
  // Edges shorter than this (relative to the mean edge) would make 1/‖x_j − x_i‖ explode.
  double mean_length = 0.0;
  for (const auto& edge : topology.edges) {
    mean_length += (Position(positions, edge[1]) - Position(positions, edge[0])).norm();
  }
  if (!topology.edges.empty()) mean_length /= static_cast<double>(topology.edges.size());
  const double length_floor = mean_length > 0.0 ? 1e-12 * mean_length : 1.0;
  // tan(α/2) grows without bound as α → π; cap it like the cotangents (tan(α/2) = cot((π−α)/2)).
  const double max_half_tangent = options.max_cotangent;

  std::vector<double> directed(topology.ring_neighbors.size(), 0.0);
  int clamped_count = 0, degenerate_count = 0;
  // Corner o of triangle {o, i, j}: the angle at o between o→i and o→j adds tan(α/2)/‖x_i − x_o‖
  // to w_oi and tan(α/2)/‖x_j − x_o‖ to w_oj.
  ForEachCorner(topology, [&](int, int o, int i, int j) {
    const Eigen::Vector3d a = Position(positions, i) - Position(positions, o);
    const Eigen::Vector3d b = Position(positions, j) - Position(positions, o);
    const double length_a = a.norm(), length_b = b.norm();
    if (o < i && operators_internal::IsDegenerateCorner(a, b)) ++degenerate_count;
    // tan(α/2) = sin α / (1 + cos α) = ‖a×b‖ / (‖a‖‖b‖ + a·b): no trigonometry, no cancellation
    // for small α, and exactly 0 for a zero-length side.
    const double denominator = length_a * length_b + a.dot(b);
    const double numerator = a.cross(b).norm();
    double half_tangent = 0.0;
    if (numerator > 0.0) {
      if (numerator < max_half_tangent * denominator) {
        half_tangent = numerator / denominator;
      } else {
        half_tangent = max_half_tangent;
        ++clamped_count;
      }
    }
    // A corner that adds nothing is skipped: among them the corners of a triangle with a
    // repeated vertex (o = i or o = j, so a or b is zero), whose edge o → o does not exist.
    if (half_tangent == 0.0) return;
    double safe_a = length_a, safe_b = length_b;
    if (!(safe_a > length_floor)) safe_a = length_floor;
    if (!(safe_b > length_floor)) safe_b = length_floor;
    directed[RingSlot(topology, o, i)] += half_tangent / safe_a;
    directed[RingSlot(topology, o, j)] += half_tangent / safe_b;
  });
  if (stats != nullptr) {
    stats->clamped_cotangents += clamped_count;
    stats->degenerate_triangles += degenerate_count;
  }
  return directed;
}

StatusOr<LaplaceOperator> BuildMeanValue(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options) {
  if (positions.rows() != topology.vertex_count) {
    return MismatchError("reference frame has " + std::to_string(positions.rows()) +
                         " vertices, the mesh " + std::to_string(topology.vertex_count));
  }
  if (!positions.allFinite()) return InvalidArgumentError("reference frame is not finite");
  OperatorStats stats;
  std::vector<double> directed = MeanValueDirectedWeights(topology, positions, options, &stats);
  NormalizeRowsToUnitSum(topology, directed, options.min_row_sum_ratio, &stats);
  DMC_ASSIGN_OR_RETURN(
      LaplaceOperator result,
      OperatorFromWeights("mean-value", topology,
                          {WeightLayout::kPerDirectedEdge, std::move(directed)}, true));
  stats.isolated_vertices = result.stats.isolated_vertices;
  result.stats = stats;
  return result;
}

}  // namespace dmc
