// The one Laplacian assembly routine (off-diagonals = weights, diagonal = −row sum) and the
// small helpers every builder shares.
#include <algorithm>
#include <cmath>
#include <string>

#include "dmc/laplace_operator.h"
#include "dmc/operator_formulas.h"

namespace dmc {

int RingSlot(const MeshTopology& topology, int i, int j) {
  const auto begin = topology.ring_neighbors.begin() + topology.ring_offsets[i];
  const auto end = topology.ring_neighbors.begin() + topology.ring_offsets[i + 1];
  const auto it = std::lower_bound(begin, end, j);  // rings are sorted ascending
  if (it == end || *it != j) return -1;
  return static_cast<int>(it - topology.ring_neighbors.begin());
}

StatusOr<SparseMatrixD> AssembleLaplacian(const MeshTopology& topology,
                                          const OperatorWeights& weights) {
  const int v_count = topology.vertex_count;
  const size_t directed_count = topology.ring_neighbors.size();
  const bool per_edge = weights.layout == WeightLayout::kPerEdge;
  const size_t expected = per_edge ? topology.edges.size() : directed_count;
  if (weights.values.size() != expected) {
    return MismatchError("operator weights: " + std::to_string(weights.values.size()) +
                         " values for a mesh with " + std::to_string(expected) +
                         (per_edge ? " edges" : " directed edges"));
  }
  for (size_t k = 0; k < weights.values.size(); ++k) {
    if (!std::isfinite(weights.values[k])) {
      return InvalidArgumentError("operator weight " + std::to_string(k) + " is not finite");
    }
  }

  // Column-major storage of L: column c holds L(i, c) for the neighbours i of c plus the diagonal.
  // Rings are symmetric (j ∈ N(i) ⇔ i ∈ N(j)) and sorted, so column c's row indices are c's ring
  // with c inserted in order: the pattern is built directly, without triplet sorting.
  SparseMatrixD matrix(v_count, v_count);
  std::vector<int> column_sizes(v_count);
  for (int c = 0; c < v_count; ++c) column_sizes[c] = topology.degree(c) + 1;
  matrix.reserve(column_sizes);

  // Row sums in ring order, the order the decoder must reproduce bit for bit.
  Eigen::VectorXd diagonal(v_count);
  auto weight_of = [&](int slot) {
    return per_edge ? weights.values[topology.ring_edges[slot]] : weights.values[slot];
  };
  for (int i = 0; i < v_count; ++i) {
    double sum = 0.0;
    for (int k = topology.ring_offsets[i]; k < topology.ring_offsets[i + 1]; ++k) {
      sum += weight_of(k);
    }
    diagonal[i] = -sum;
  }

  for (int c = 0; c < v_count; ++c) {
    bool diagonal_done = false;
    for (int k = topology.ring_offsets[c]; k < topology.ring_offsets[c + 1]; ++k) {
      const int i = topology.ring_neighbors[k];  // row index: L(i, c) = w_ic
      if (!diagonal_done && i > c) {
        matrix.insert(c, c) = diagonal[c];
        diagonal_done = true;
      }
      // w_ic is the weight of the directed edge i → c: the slot of c in i's ring.
      const int slot = per_edge ? k : RingSlot(topology, i, c);
      matrix.insert(i, c) = weight_of(slot);
    }
    if (!diagonal_done) matrix.insert(c, c) = diagonal[c];
  }
  matrix.makeCompressed();
  return matrix;
}

std::vector<double> TutteDirectedWeights(const MeshTopology& topology) {
  std::vector<double> directed(topology.ring_neighbors.size());
  for (int i = 0; i < topology.vertex_count; ++i) {
    const int degree = topology.degree(i);
    for (int k = topology.ring_offsets[i]; k < topology.ring_offsets[i + 1]; ++k) {
      directed[k] = 1.0 / degree;
    }
  }
  return directed;
}

void NormalizeRowsToUnitSum(const MeshTopology& topology, std::vector<double>& directed,
                            double min_row_sum_ratio, OperatorStats* stats) {
  for (int i = 0; i < topology.vertex_count; ++i) {
    const int begin = topology.ring_offsets[i], end = topology.ring_offsets[i + 1];
    if (begin == end) continue;
    double sum = 0.0, abs_sum = 0.0;
    for (int k = begin; k < end; ++k) {
      sum += directed[k];
      abs_sum += std::abs(directed[k]);
    }
    // A row whose weights nearly cancel would be amplified without bound by the normalisation:
    // use the barycentre of the neighbours instead, which is always defined.
    if (!(sum > min_row_sum_ratio * abs_sum) || !(sum > 0.0)) {
      for (int k = begin; k < end; ++k) directed[k] = 1.0 / (end - begin);
      if (stats != nullptr) ++stats->fallback_rows;
      continue;
    }
    for (int k = begin; k < end; ++k) directed[k] /= sum;
  }
}

StatusOr<LaplaceOperator> OperatorFromWeights(std::string name, const MeshTopology& topology,
                                              OperatorWeights weights, bool unit_sum) {
  LaplaceOperator result;
  DMC_ASSIGN_OR_RETURN(result.matrix, AssembleLaplacian(topology, weights));
  result.name = std::move(name);
  result.symmetric = weights.layout == WeightLayout::kPerEdge;
  result.unit_sum = unit_sum;
  result.weights = std::move(weights);
  result.stats.isolated_vertices = topology.isolated_vertex_count;
  return result;
}

FramePositionsD MeanFrame(const MeshSequence& sequence) {
  FramePositionsD mean = FramePositionsD::Zero(sequence.vertex_count(), 3);
  for (int f = 0; f < sequence.frame_count(); ++f) mean += sequence.frame(f).cast<double>();
  if (sequence.frame_count() > 0) mean /= sequence.frame_count();
  return mean;
}

}  // namespace dmc
