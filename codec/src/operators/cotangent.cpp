// Cotangent weights (Pinkall–Polthier / Meyer et al.) and the three operators built from them:
// unit-sum cotan, area-normalised cotan-area, and the symmetric DEC operator cotan-sym.
#include <algorithm>
#include <string>

#include "dmc/operator_formulas.h"
#include "operators/triangle_corners.h"

namespace dmc {
namespace {

using operators_internal::ClampedCotangent;
using operators_internal::ForEachCorner;
using operators_internal::IsDegenerateCorner;
using operators_internal::Position;

Status CheckPositions(const MeshTopology& topology, const FramePositionsD& positions) {
  if (positions.rows() != topology.vertex_count) {
    return MismatchError("reference frame has " + std::to_string(positions.rows()) +
                         " vertices, the mesh " + std::to_string(topology.vertex_count));
  }
  if (!positions.allFinite()) return InvalidArgumentError("reference frame is not finite");
  return Status::Ok();
}

// Per-edge k_ij copied onto both directed edges i→j and j→i.
std::vector<double> EdgeToDirected(const MeshTopology& topology, const std::vector<double>& edge) {
  std::vector<double> directed(topology.ring_neighbors.size());
  for (size_t k = 0; k < directed.size(); ++k) directed[k] = edge[topology.ring_edges[k]];
  return directed;
}

}  // namespace

std::vector<double> CotangentEdgeWeights(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options, OperatorStats* stats) {
  std::vector<double> weights(topology.edges.size(), 0.0);
  int clamped_count = 0, degenerate_count = 0;
  ForEachCorner(topology, [&](int e, int o, int i, int j) {
    const Eigen::Vector3d a = Position(positions, i) - Position(positions, o);
    const Eigen::Vector3d b = Position(positions, j) - Position(positions, o);
    bool clamped = false;
    weights[e] += 0.5 * ClampedCotangent(a, b, options.max_cotangent, &clamped);
    clamped_count += clamped ? 1 : 0;
    // Each triangle is met once per corner; count it at its smallest vertex only.
    if (o < i && IsDegenerateCorner(a, b)) ++degenerate_count;
  });
  if (stats != nullptr) {
    stats->clamped_cotangents += clamped_count;
    stats->degenerate_triangles += degenerate_count;
  }
  return weights;
}

Eigen::VectorXd MixedVoronoiAreas(const MeshTopology& topology, const FramePositionsD& positions) {
  Eigen::VectorXd areas = Eigen::VectorXd::Zero(topology.vertex_count);
  // Corner o = P of triangle (P, Q, R) = (o, i, j) adds its own share only.
  ForEachCorner(topology, [&](int, int o, int i, int j) {
    const Eigen::Vector3d p = Position(positions, o), q = Position(positions, i),
                          r = Position(positions, j);
    const Eigen::Vector3d pq = q - p, pr = r - p, qr = r - q;
    if (IsDegenerateCorner(pq, pr)) return;  // zero area: nothing to share
    const double double_area = pq.cross(pr).norm();
    const double area = 0.5 * double_area;
    const bool obtuse_p = pq.dot(pr) < 0.0;
    const bool obtuse_q = (-pq).dot(qr) < 0.0;
    const bool obtuse_r = (-pr).dot(-qr) < 0.0;
    if (obtuse_p) {
      areas[o] += 0.5 * area;
    } else if (obtuse_q || obtuse_r) {
      areas[o] += 0.25 * area;
    } else {
      // Voronoi share of P: (|PR|² cot Q + |PQ|² cot R) / 8, with cot = dot / (2·area); all
      // angles are ≤ 90° here, so both cotangents are finite and non-negative.
      const double cot_q = (-pq).dot(qr) / double_area;
      const double cot_r = (-pr).dot(-qr) / double_area;
      areas[o] += (pr.squaredNorm() * cot_q + pq.squaredNorm() * cot_r) / 8.0;
    }
  });
  return areas;
}

StatusOr<LaplaceOperator> BuildCotan(const MeshTopology& topology, const FramePositionsD& positions,
                                     const GeometricOptions& options) {
  DMC_RETURN_IF_ERROR(CheckPositions(topology, positions));
  OperatorStats stats;
  std::vector<double> directed =
      EdgeToDirected(topology, CotangentEdgeWeights(topology, positions, options, &stats));
  NormalizeRowsToUnitSum(topology, directed, options.min_row_sum_ratio, &stats);
  DMC_ASSIGN_OR_RETURN(
      LaplaceOperator result,
      OperatorFromWeights("cotan", topology, {WeightLayout::kPerDirectedEdge, std::move(directed)},
                          true));
  stats.isolated_vertices = result.stats.isolated_vertices;
  result.stats = stats;
  return result;
}

StatusOr<LaplaceOperator> BuildCotanSym(const MeshTopology& topology,
                                        const FramePositionsD& positions,
                                        const GeometricOptions& options) {
  DMC_RETURN_IF_ERROR(CheckPositions(topology, positions));
  OperatorStats stats;
  std::vector<double> edge = CotangentEdgeWeights(topology, positions, options, &stats);
  DMC_ASSIGN_OR_RETURN(
      LaplaceOperator result,
      OperatorFromWeights("cotan-sym", topology, {WeightLayout::kPerEdge, std::move(edge)}, false));
  stats.isolated_vertices = result.stats.isolated_vertices;
  result.stats = stats;
  result.mass = MixedVoronoiAreas(topology, positions);
  return result;
}

StatusOr<LaplaceOperator> BuildCotanArea(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options) {
  DMC_RETURN_IF_ERROR(CheckPositions(topology, positions));
  OperatorStats stats;
  std::vector<double> directed =
      EdgeToDirected(topology, CotangentEdgeWeights(topology, positions, options, &stats));
  Eigen::VectorXd areas = MixedVoronoiAreas(topology, positions);
  // A vertex whose triangles all have zero area would get infinite weights; floor its area at a
  // tiny fraction of the mean (or at 1, the thesis's "unit area" variant, if every area is zero).
  // Summed in vertex order, one addition at a time, as §9.5 states (Eigen's mean() reduces in
  // vector lanes: another order, another last bit).
  double area_sum = 0.0;
  for (Eigen::Index v = 0; v < areas.size(); ++v) area_sum += areas[v];
  const double mean_area = areas.size() > 0 ? area_sum / static_cast<double>(areas.size()) : 0.0;
  const double area_floor = mean_area > 0.0 ? 1e-12 * mean_area : 1.0;
  for (int v = 0; v < topology.vertex_count; ++v) {
    if (topology.degree(v) > 0 && !(areas[v] > area_floor)) {
      areas[v] = area_floor;
      ++stats.clamped_areas;
    }
    for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
      directed[k] /= areas[v];
    }
  }
  DMC_ASSIGN_OR_RETURN(
      LaplaceOperator result,
      OperatorFromWeights("cotan-area", topology,
                          {WeightLayout::kPerDirectedEdge, std::move(directed)}, false));
  stats.isolated_vertices = result.stats.isolated_vertices;
  result.stats = stats;
  result.mass = std::move(areas);
  return result;
}

}  // namespace dmc
