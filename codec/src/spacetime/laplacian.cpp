// Assembly of the symmetric spacetime Laplacian Δ = ⋆0^{−1/2}·W·⋆0^{−1/2}, the stiffness W and
// the unsymmetrised Δu = ⋆0⁻¹·W straight into preallocated compressed storage (spacetime.h).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "dmc/spacetime.h"

namespace dmc {
namespace {

// Spatial edges below this fraction of the mean edge length get weight zero: their dual-to-
// primal ratio would be a division by (almost) zero.
constexpr double kShortEdgeRatio = 1e-10;

// Each vertex's neighbours sorted by index with their edge, and where the vertex itself falls
// among them (the diagonal's slot in a sorted column).
struct SortedRings {
  std::vector<int32_t> offsets;
  std::vector<std::pair<int32_t, int32_t>> entries;  // (neighbour, edge)
  std::vector<int32_t> diagonal_slot;                // within the vertex's own range
};

SortedRings SortRings(const MeshTopology& topology) {
  SortedRings rings;
  rings.offsets = topology.ring_offsets;
  rings.entries.resize(topology.ring_neighbors.size());
  rings.diagonal_slot.resize(topology.vertex_count);
  for (int v = 0; v < topology.vertex_count; ++v) {
    const int begin = topology.ring_offsets[v], end = topology.ring_offsets[v + 1];
    for (int s = begin; s < end; ++s) {
      rings.entries[s] = {topology.ring_neighbors[s], topology.ring_edges[s]};
    }
    std::sort(rings.entries.begin() + begin, rings.entries.begin() + end);
    const auto first_above =
        std::lower_bound(rings.entries.begin() + begin, rings.entries.begin() + end,
                         std::pair<int32_t, int32_t>{v, -1});
    rings.diagonal_slot[v] = static_cast<int32_t>(first_above - (rings.entries.begin() + begin));
  }
  return rings;
}

// Entry (r, c) = w_rc · row_scale[r] · col_scale[c] off the diagonal, −Σ_c w_rc · row_scale[r] ·
// col_scale[r] on it, for the spacetime graph with spatial weights (E×F) and temporal weights
// (V×(F−1)). Column k·V + i holds, by increasing row: the previous frame's i, frame k's sorted
// ring of i with i itself, the next frame's i. Exactly SpacetimeNonzeroCount entries, written in
// place after one resizeNonZeros.
SparseMatrixD AssembleBlockTridiagonal(const MeshTopology& topology, const SortedRings& rings,
                                       int f_count, const Eigen::MatrixXd& spatial_weight,
                                       const Eigen::MatrixXd& temporal_weight,
                                       const Eigen::VectorXd& row_scale,
                                       const Eigen::VectorXd& col_scale) {
  const int v_count = topology.vertex_count;
  const Eigen::Index n = static_cast<Eigen::Index>(v_count) * f_count;
  SparseMatrixD matrix(n, n);
  const int64_t nnz = SpacetimeNonzeroCount(topology, f_count);
  matrix.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  int* outer = matrix.outerIndexPtr();
  int* inner = matrix.innerIndexPtr();
  double* value = matrix.valuePtr();
  outer[0] = 0;
  for (int k = 0; k < f_count; ++k) {
    for (int i = 0; i < v_count; ++i) {
      const int column = k * v_count + i;
      outer[column + 1] =
          outer[column] + topology.degree(i) + 1 + (k > 0 ? 1 : 0) + (k + 1 < f_count ? 1 : 0);
    }
  }
  tbb::parallel_for(0, f_count, [&](int k) {
    for (int i = 0; i < v_count; ++i) {
      const int column = k * v_count + i;
      int slot = outer[column];
      double diagonal_sum = 0.0;
      const auto put = [&](int row, double weight) {
        inner[slot] = row;
        // Scales multiplied first: s_r·s_c == s_c·s_r exactly, so Δ is bitwise symmetric.
        value[slot++] = weight * (row_scale[row] * col_scale[column]);
        diagonal_sum += weight;
      };
      if (k > 0) put(column - v_count, temporal_weight(i, k - 1));
      const int begin = rings.offsets[i], end = rings.offsets[i + 1];
      int diagonal_index = -1;
      for (int s = begin; s <= end; ++s) {
        if (s - begin == rings.diagonal_slot[i] && diagonal_index < 0) {
          diagonal_index = slot;
          inner[slot++] = column;  // value written once the row's weights are summed
        }
        if (s == end) break;
        put(k * v_count + rings.entries[s].first, spatial_weight(rings.entries[s].second, k));
      }
      if (k + 1 < f_count) put(column + v_count, temporal_weight(i, k));
      value[diagonal_index] = -diagonal_sum * row_scale[column] * col_scale[column];
    }
  });
  matrix.finalize();
  return matrix;
}

struct Weights {
  Eigen::MatrixXd spatial;   // E × F, |⋆e|/|e|
  Eigen::MatrixXd temporal;  // V × (F−1)
  int short_edges = 0;
};

Weights DualPrimalRatios(const SpacetimeGeometry& g) {
  Weights w;
  const double mean_length = g.spatial_edge_length.size() > 0 ? g.spatial_edge_length.mean() : 0;
  const double floor = kShortEdgeRatio * mean_length;
  w.spatial.resize(g.spatial_edge_length.rows(), g.spatial_edge_length.cols());
  for (Eigen::Index k = 0; k < w.spatial.cols(); ++k) {
    for (Eigen::Index e = 0; e < w.spatial.rows(); ++e) {
      const double length = g.spatial_edge_length(e, k);
      if (length <= floor) {
        w.spatial(e, k) = 0.0;
        ++w.short_edges;
      } else {
        w.spatial(e, k) = g.spatial_edge_dual_area(e, k) / length;
      }
    }
  }
  // Temporal lengths are ≥ sqrt(α)·Δt > 0 by validation.
  w.temporal = g.temporal_edge_dual_area.cwiseQuotient(g.temporal_edge_length);
  return w;
}

Eigen::VectorXd FlatMass(const SpacetimeGeometry& g) {
  return Eigen::Map<const Eigen::VectorXd>(g.vertex_dual_volume.data(),
                                           g.vertex_dual_volume.size());
}

// 1/sqrt(m) (or 1/m with power 1), zero for empty duals.
Eigen::VectorXd InversePower(const Eigen::VectorXd& mass, double power) {
  Eigen::VectorXd result(mass.size());
  for (Eigen::Index r = 0; r < mass.size(); ++r) {
    result[r] = mass[r] > 0.0 ? std::pow(mass[r], -power) : 0.0;
  }
  return result;
}

}  // namespace

int64_t SpacetimeNonzeroCount(const MeshTopology& topology, int frame_count) {
  const int64_t v = topology.vertex_count, e = topology.edge_count(), f = frame_count;
  return f * (v + 2 * e) + 2 * v * std::max<int64_t>(f - 1, 0);
}

StatusOr<SpacetimeLaplacian> BuildSpacetimeLaplacian(const MeshTopology& topology,
                                                     const Triangles& triangles,
                                                     std::span<const FramePositionsD> frames,
                                                     const SpacetimeOptions& options) {
  DMC_ASSIGN_OR_RETURN(SpacetimeGeometry geometry,
                       ComputeSpacetimeGeometry(topology, triangles, frames, options));
  const Weights weights = DualPrimalRatios(geometry);
  geometry.stats.short_spatial_edges = weights.short_edges;

  SpacetimeLaplacian result;
  result.vertex_count = topology.vertex_count;
  result.frame_count = static_cast<int>(frames.size());
  result.alpha = options.alpha;
  result.mass = FlatMass(geometry);
  const SortedRings rings = SortRings(topology);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(result.mass.size());
  const Eigen::VectorXd inverse_root = InversePower(result.mass, 0.5);
  result.stiffness = AssembleBlockTridiagonal(topology, rings, result.frame_count, weights.spatial,
                                              weights.temporal, ones, ones);
  result.matrix = AssembleBlockTridiagonal(topology, rings, result.frame_count, weights.spatial,
                                           weights.temporal, inverse_root, inverse_root);
  result.geometry = std::move(geometry);
  return result;
}

StatusOr<SpacetimeLaplacian> BuildSpacetimeLaplacian(const MeshSequence& sequence,
                                                     const SpacetimeOptions& options) {
  std::vector<FramePositionsD> frames;
  frames.reserve(sequence.frame_count());
  for (int f = 0; f < sequence.frame_count(); ++f) frames.push_back(sequence.frame_d(f));
  SpacetimeOptions resolved = options;
  if (resolved.frame_times.empty() && sequence.frame_rate > 0.0) {
    for (int f = 0; f < sequence.frame_count(); ++f) {
      resolved.frame_times.push_back(f / sequence.frame_rate);
    }
  }
  const MeshTopology topology = BuildTopology(sequence.triangles(), sequence.vertex_count());
  return BuildSpacetimeLaplacian(topology, sequence.triangles(), frames, resolved);
}

SparseMatrixD UnsymmetrisedSpacetimeLaplacian(const SpacetimeLaplacian& laplacian) {
  return UnsymmetrisedSpacetimeLaplacian(laplacian.stiffness, laplacian.mass);
}

SparseMatrixD UnsymmetrisedSpacetimeLaplacian(const SparseMatrixD& stiffness,
                                              const Eigen::VectorXd& mass) {
  // Δu = ⋆0⁻¹·W: scale the rows of W (CSC: every stored entry's row index).
  SparseMatrixD result = stiffness;
  const Eigen::VectorXd inverse = InversePower(mass, 1.0);
  for (int c = 0; c < result.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(result, c); it; ++it) it.valueRef() *= inverse[it.row()];
  }
  return result;
}

SparseMatrixD SymmetrisedSpacetimeLaplacian(const SparseMatrixD& stiffness,
                                            const Eigen::VectorXd& mass) {
  SparseMatrixD result = stiffness;
  const Eigen::VectorXd inverse_root = InversePower(mass, 0.5);
  for (int c = 0; c < result.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(result, c); it; ++it) {
      it.valueRef() *= inverse_root[it.row()] * inverse_root[c];
    }
  }
  return result;
}

SparseMatrixD SpacetimeBlock(const SparseMatrixD& matrix, int vertex_count, int row_frame,
                             int column_frame) {
  return matrix.block(static_cast<Eigen::Index>(row_frame) * vertex_count,
                      static_cast<Eigen::Index>(column_frame) * vertex_count, vertex_count,
                      vertex_count);
}

}  // namespace dmc
