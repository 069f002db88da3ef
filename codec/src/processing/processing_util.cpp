// Helpers shared by the processing methods.
#include "processing/processing_util.h"

#include <fmt/format.h>

#include <cmath>

namespace dmc::processing {

SparseMatrixD SelectColumns(const SparseMatrixD& matrix, std::span<const int> column_index,
                            int count) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(matrix.nonZeros()));
  for (int c = 0; c < matrix.outerSize(); ++c) {
    if (column_index[c] < 0) continue;
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      triplets.emplace_back(static_cast<int>(it.row()), column_index[c], it.value());
    }
  }
  SparseMatrixD selected(matrix.rows(), count);
  selected.setFromTriplets(triplets.begin(), triplets.end());
  return selected;
}

SparseMatrixD SelectRows(const SparseMatrixD& matrix, std::span<const int> row_index, int count) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(matrix.nonZeros()));
  for (int c = 0; c < matrix.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      const int row = row_index[it.row()];
      if (row >= 0) triplets.emplace_back(row, c, it.value());
    }
  }
  SparseMatrixD selected(count, matrix.cols());
  selected.setFromTriplets(triplets.begin(), triplets.end());
  return selected;
}

void AddToDiagonal(SparseMatrixD& matrix, std::span<const int> indices, double value) {
  if (indices.empty()) return;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(indices.size());
  for (int index : indices) triplets.emplace_back(index, index, value);
  SparseMatrixD diagonal(matrix.rows(), matrix.cols());
  diagonal.setFromTriplets(triplets.begin(), triplets.end());
  matrix += diagonal;
}

double StepScale(const LaplaceOperator& laplace) {
  if (laplace.unit_sum) return 1.0;
  double sum = 0.0;
  int count = 0;
  for (Eigen::Index v = 0; v < laplace.matrix.rows(); ++v) {
    const double diagonal = std::abs(laplace.matrix.coeff(v, v));
    if (diagonal > 0.0) {
      sum += diagonal;
      ++count;
    }
  }
  return count > 0 && sum > 0.0 ? sum / count : 1.0;
}

double SpectralRadiusBound(const SparseMatrixD& laplacian) {
  Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(laplacian.rows());
  for (Eigen::Index c = 0; c < laplacian.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(laplacian, c); it; ++it) {
      row_sums[it.row()] += std::abs(it.value());
    }
  }
  return row_sums.size() > 0 ? row_sums.maxCoeff() : 0.0;
}

double SpectralRadiusEstimate(const SparseMatrixD& laplacian, int iterations) {
  const Eigen::Index n = laplacian.rows();
  if (n == 0) return 0.0;
  // A start with every frequency in it: alternating signs plus a slow ramp.
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = (i % 2 == 0 ? 1.0 : -1.0) + 1e-3 * static_cast<double>(i) / static_cast<double>(n);
  }
  double radius = 0.0;
  for (int k = 0; k < iterations; ++k) {
    const double norm = x.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) break;
    x /= norm;
    const Eigen::VectorXd y = laplacian * x;
    radius = std::max(radius, y.norm());
    x = y;
  }
  return radius;
}

Status CheckComponentsPinned(const MeshTopology& topology, std::span<const uint8_t> needs,
                             std::span<const uint8_t> pins, std::string_view pin_description) {
  std::vector<uint8_t> component_needs(topology.component_count, 0);
  std::vector<uint8_t> component_pinned(topology.component_count, 0);
  std::vector<int> first_vertex(topology.component_count, -1);
  for (int v = 0; v < topology.vertex_count; ++v) {
    const int component = topology.component_of_vertex[v];
    if (first_vertex[component] < 0) first_vertex[component] = v;
    if (needs[v]) component_needs[component] = 1;
    if (pins[v]) component_pinned[component] = 1;
  }
  for (int c = 0; c < topology.component_count; ++c) {
    if (component_needs[c] && !component_pinned[c]) {
      return InvalidArgumentError(fmt::format(
          "the connected component of vertex {} has no {}: its position is undetermined",
          first_vertex[c], pin_description));
    }
  }
  return Status::Ok();
}

std::vector<uint8_t> MaskOf(std::span<const int32_t> indices, int vertex_count) {
  std::vector<uint8_t> mask(vertex_count, 0);
  for (int32_t v : indices) mask[v] = 1;
  return mask;
}

}  // namespace dmc::processing
