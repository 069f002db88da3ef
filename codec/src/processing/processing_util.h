// Helpers shared by the processing methods (private to dmc_processing).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "dmc/operators.h"
#include "dmc/processing.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc::processing {

// Columns of `matrix` whose `column_index[c]` ≥ 0, renumbered to that index (`count` columns).
SparseMatrixD SelectColumns(const SparseMatrixD& matrix, std::span<const int> column_index,
                            int count);

// Rows of `matrix` whose `row_index[r]` ≥ 0, renumbered to that index (`count` rows).
SparseMatrixD SelectRows(const SparseMatrixD& matrix, std::span<const int> row_index, int count);

// Adds `value` to the diagonal entries listed in `indices` (entries are created when absent).
void AddToDiagonal(SparseMatrixD& matrix, std::span<const int> indices, double value);

// The thesis's step scaling (6.3): operators without unit row sum (kirchhoff, cotan-area,
// cotan-sym) have diagonals far from −1, so a smoothing coefficient λ is divided by s_L, the
// mean |L_ii| over non-isolated vertices; unit-sum operators get 1. Never 0.
double StepScale(const LaplaceOperator& laplace);
// A bound on the spectral radius of L (Gershgorin: the largest row sum of |L_ij|, diagonal
// included; 2 for a unit-sum operator with non-negative weights), and an estimate of the radius
// itself by power iteration (deterministic start; a lower bound that converges to it).
double SpectralRadiusBound(const SparseMatrixD& laplacian);
double SpectralRadiusEstimate(const SparseMatrixD& laplacian, int iterations = 200);

// Fails with kInvalidArgument unless every connected component that contains a vertex with
// `needs[v]` also contains a vertex with `pins[v]`; the message names the component's first
// vertex and says what `pins` should contain (e.g. "a handle, fixed vertex or anchor").
Status CheckComponentsPinned(const MeshTopology& topology, std::span<const uint8_t> needs,
                             std::span<const uint8_t> pins, std::string_view pin_description);

// Positions as a dense V×3 matrix (and back), for sparse products.
inline Eigen::MatrixXd ToDense(const FramePositionsD& positions) {
  return Eigen::MatrixXd(positions);
}
inline FramePositionsD ToFrame(const Eigen::MatrixXd& positions) {
  return FramePositionsD(positions);
}

// A vertex role mask of length V with 1 at each listed index.
std::vector<uint8_t> MaskOf(std::span<const int32_t> indices, int vertex_count);

}  // namespace dmc::processing
