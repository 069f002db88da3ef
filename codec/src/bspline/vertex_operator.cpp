// The B-spline operator moved to per-vertex values, L_V = Rᵀ L R with R the lumped L² projection
// from hat functions to the elements, and the triangle recovery the registry factories share.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "bspline/bspline_internal.h"

namespace dmc {

Triangles TrianglesFromTopology(const MeshTopology& topology) {
  // Each triangle is seen from its three edges, hence the sort and de-duplication.
  std::vector<std::array<int32_t, 3>> corners;
  for (size_t e = 0; e < topology.edges.size(); ++e) {
    for (int32_t opposite : topology.edge_opposite[e]) {
      if (opposite < 0) continue;
      std::array<int32_t, 3> triangle{topology.edges[e][0], topology.edges[e][1], opposite};
      std::sort(triangle.begin(), triangle.end());
      corners.push_back(triangle);
    }
  }
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  Triangles triangles(static_cast<Eigen::Index>(corners.size()), 3);
  for (size_t t = 0; t < corners.size(); ++t) {
    for (int k = 0; k < 3; ++k) triangles(static_cast<Eigen::Index>(t), k) = corners[t][k];
  }
  return triangles;
}

int AutomaticBsplineDepth(const Triangles& triangles, const FramePositionsD& positions) {
  double edge_sum = 0.0;
  Eigen::Vector3d low = Eigen::Vector3d::Constant(INFINITY), high = -low;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = positions.row(triangles(t, k)).transpose();
      const Eigen::Vector3d b = positions.row(triangles(t, (k + 1) % 3)).transpose();
      edge_sum += (b - a).norm();
      low = low.cwiseMin(a);
      high = high.cwiseMax(a);
    }
  }
  if (triangles.rows() == 0) return 2;
  const double mean_edge = edge_sum / (3.0 * static_cast<double>(triangles.rows()));
  const double cube = (high - low).maxCoeff();
  if (!(mean_edge > 0.0) || !(cube > 0.0)) return 2;
  // The largest depth whose voxel (cube / 2^d) is still at least one mean edge long.
  return std::clamp(static_cast<int>(std::floor(std::log2(cube / mean_edge))), 2, 7);
}

StatusOr<LaplaceOperator> BuildBsplineVertexOperator(const MeshTopology& topology,
                                                     const FramePositionsD& positions, int depth) {
  if (positions.rows() != topology.vertex_count) {
    return MismatchError("bspline operator: " + std::to_string(positions.rows()) +
                         " positions for a topology of " + std::to_string(topology.vertex_count) +
                         " vertices");
  }
  const Triangles triangles = TrianglesFromTopology(topology);
  BsplineOptions options;
  options.depth = depth > 0 ? depth : AutomaticBsplineDepth(triangles, positions);
  options.coarsest_depth = options.depth;  // one level: no multigrid needed here
  DMC_ASSIGN_OR_RETURN(const BsplineOperator op,
                       BuildBsplineOperator(triangles, positions, options));

  const SparseMatrixD coupling = bspline_detail::HatFunctionCoupling(op);
  const Eigen::VectorXd element_integral = coupling * Eigen::VectorXd::Ones(coupling.cols());
  Eigen::VectorXd inverse(element_integral.size());
  for (Eigen::Index i = 0; i < inverse.size(); ++i) {
    inverse[i] = element_integral[i] > 0.0 ? 1.0 / element_integral[i] : 0.0;
  }
  const SparseMatrixD projection = inverse.asDiagonal() * coupling;  // R, rows sum to one
  const SparseMatrixD product =
      SparseMatrixD(projection.transpose()) * (op.finest().laplacian * projection);
  // Exactly symmetric (x + y == y + x in IEEE arithmetic), then the diagonal is set to minus the
  // row's off-diagonal sum so constants are in the null space to the rounding of one sum.
  SparseMatrixD matrix = 0.5 * (product + SparseMatrixD(product.transpose()));
  matrix.prune(0.0);
  Eigen::VectorXd off_diagonal_sum = Eigen::VectorXd::Zero(matrix.rows());
  for (int c = 0; c < matrix.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      if (it.row() != it.col()) off_diagonal_sum[it.row()] += it.value();
    }
  }
  for (int c = 0; c < matrix.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      if (it.row() == it.col()) it.valueRef() = -off_diagonal_sum[it.row()];
    }
  }

  LaplaceOperator result;
  result.name = "bspline";
  result.matrix = std::move(matrix);
  result.weights.layout = WeightLayout::kPerEdge;  // empty: the stencil is wider than the mesh's
  result.mass = SparseMatrixD(coupling.transpose()) * Eigen::VectorXd::Ones(coupling.rows());
  result.symmetric = true;
  result.unit_sum = false;
  for (int v = 0; v < topology.vertex_count; ++v) {
    if (topology.degree(v) == 0) ++result.stats.isolated_vertices;
  }
  return result;
}

}  // namespace dmc
