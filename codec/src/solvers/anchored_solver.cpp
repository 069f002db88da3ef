// Normal equations of a Laplacian with anchors: N = LᵀL + w²PᵀP, factored once, solved for all
// columns of the differential coordinates at once.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "dmc/sparse_solvers.h"

namespace dmc {

namespace {

// LᵀL + diag(d), given L and its transpose, computed exactly as Eigen's
//   (SparseMatrixD(Lᵀ) * L) + diagonal(d)
// computes it — the same sparsity pattern (every structurally touched entry kept, zeros too), the
// same products summed in the same order, the same "+ 0" on entries only one operand holds — so
// the factorisation, and the decoded frames, do not change by a bit (tests/unit/decoder
// /fast_paths_test.cpp compares the two). What differs: one pass, the diagonal merged in, and the
// columns computed in parallel (each column's entries depend on that column alone). Eigen's
// product: for each column j of L, for each of its entries (k, y) in storage order, for each entry
// (i, x) of column k of Lᵀ in storage order, value(i) = x·y on first touch and += x·y after; the
// column's rows are then sorted (Eigen transposes twice).
SparseMatrixD NormalMatrixWithDiagonal(const SparseMatrixD& laplacian,
                                       const SparseMatrixD& transpose,
                                       const Eigen::VectorXd& diagonal) {
  const Eigen::Index n = laplacian.cols();
  constexpr Eigen::Index kColumnsPerChunk = 512;
  const Eigen::Index chunk_count = (n + kColumnsPerChunk - 1) / kColumnsPerChunk;
  struct Chunk {
    std::vector<int> rows;
    std::vector<double> values;
    std::vector<int> column_sizes;
  };
  std::vector<Chunk> chunks(static_cast<size_t>(chunk_count));
  struct Scratch {
    std::vector<uint8_t> touched;
    std::vector<double> values;
    std::vector<int> rows;
  };
  core_internal::PerThread<Scratch> scratches;
  core_internal::ParallelFor(Eigen::Index{0}, chunk_count, [&](Eigen::Index c) {
    Scratch& scratch = scratches.local();
    scratch.touched.resize(static_cast<size_t>(n), 0);
    scratch.values.resize(static_cast<size_t>(n));
    Chunk& chunk = chunks[static_cast<size_t>(c)];
    const Eigen::Index end = std::min(n, (c + 1) * kColumnsPerChunk);
    for (Eigen::Index j = c * kColumnsPerChunk; j < end; ++j) {
      scratch.rows.clear();
      for (SparseMatrixD::InnerIterator right(laplacian, j); right; ++right) {
        const double y = right.value();
        for (SparseMatrixD::InnerIterator left(transpose, right.index()); left; ++left) {
          const auto i = static_cast<size_t>(left.index());
          if (!scratch.touched[i]) {
            scratch.touched[i] = 1;
            scratch.values[i] = left.value() * y;
            scratch.rows.push_back(static_cast<int>(i));
          } else {
            scratch.values[i] += left.value() * y;
          }
        }
      }
      std::sort(scratch.rows.begin(), scratch.rows.end());
      const size_t before = chunk.rows.size();
      bool diagonal_done = false;
      for (const int i : scratch.rows) {
        if (!diagonal_done && i > j) {  // LᵀL lacks (j, j): the diagonal operand's entry alone
          chunk.rows.push_back(static_cast<int>(j));
          chunk.values.push_back(0.0 + diagonal[j]);
          diagonal_done = true;
        }
        chunk.rows.push_back(i);
        chunk.values.push_back(scratch.values[static_cast<size_t>(i)] +
                               (i == j ? diagonal[j] : 0.0));
        diagonal_done = diagonal_done || i == j;
        scratch.touched[static_cast<size_t>(i)] = 0;
      }
      if (!diagonal_done) {
        chunk.rows.push_back(static_cast<int>(j));
        chunk.values.push_back(0.0 + diagonal[j]);
      }
      chunk.column_sizes.push_back(static_cast<int>(chunk.rows.size() - before));
    }
  });
  SparseMatrixD normal(n, n);
  Eigen::Index nonzeros = 0;
  for (const Chunk& chunk : chunks) nonzeros += static_cast<Eigen::Index>(chunk.rows.size());
  normal.resizeNonZeros(nonzeros);
  int* outer = normal.outerIndexPtr();
  outer[0] = 0;
  Eigen::Index column = 0;
  std::vector<Eigen::Index> chunk_offsets(static_cast<size_t>(chunk_count) + 1, 0);
  for (Eigen::Index c = 0; c < chunk_count; ++c) {
    const Chunk& chunk = chunks[static_cast<size_t>(c)];
    for (const int size : chunk.column_sizes) {
      outer[column + 1] = outer[column] + size;
      ++column;
    }
    chunk_offsets[static_cast<size_t>(c) + 1] =
        chunk_offsets[static_cast<size_t>(c)] + static_cast<Eigen::Index>(chunk.rows.size());
  }
  core_internal::ParallelFor(Eigen::Index{0}, chunk_count, [&](Eigen::Index c) {
    const Chunk& chunk = chunks[static_cast<size_t>(c)];
    const Eigen::Index offset = chunk_offsets[static_cast<size_t>(c)];
    std::copy(chunk.rows.begin(), chunk.rows.end(), normal.innerIndexPtr() + offset);
    std::copy(chunk.values.begin(), chunk.values.end(), normal.valuePtr() + offset);
  });
  return normal;
}

// Σ_a anchor_weight² e_a e_aᵀ as a vector, accumulated in anchor order.
Eigen::VectorXd AnchorDiagonal(Eigen::Index size, std::span<const int32_t> anchors,
                               double anchor_weight) {
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(size);
  for (const int32_t a : anchors) diagonal[a] += anchor_weight * anchor_weight;
  // Eigen's diag(d) · I, as the reference formula builds the operand: d·1 = d.
  return diagonal;
}

}  // namespace

SparseMatrixD BuildNormalMatrix(const SparseMatrixD& laplacian, std::span<const int32_t> anchors,
                                double anchor_weight) {
  // Anchor rows only touch the diagonal, which is always present in LᵀL for a mesh Laplacian
  // (but may not be for an isolated vertex): NormalMatrixWithDiagonal inserts it where missing.
  return NormalMatrixWithDiagonal(laplacian, SparseMatrixD(laplacian.transpose()),
                                  AnchorDiagonal(laplacian.cols(), anchors, anchor_weight));
}

AnchoredLaplacianSolver::AnchoredLaplacianSolver(SparseMatrixD laplacian_transpose,
                                                 std::vector<int32_t> anchors, double anchor_weight,
                                                 SparseSpdSolver solver)
    : laplacian_transpose_(std::move(laplacian_transpose)),
      anchors_(std::move(anchors)),
      anchor_weight_(anchor_weight),
      solver_(std::move(solver)) {}

StatusOr<AnchoredLaplacianSolver> AnchoredLaplacianSolver::Create(const MeshTopology& topology,
                                                                  const SparseMatrixD& laplacian,
                                                                  std::vector<int32_t> anchors,
                                                                  double anchor_weight,
                                                                  const SolverOptions& options) {
  const int v_count = topology.vertex_count;
  if (laplacian.rows() != v_count || laplacian.cols() != v_count) {
    return MismatchError("Laplacian is " + std::to_string(laplacian.rows()) + "×" +
                         std::to_string(laplacian.cols()) + ", the mesh has " +
                         std::to_string(v_count) + " vertices");
  }
  if (!(anchor_weight > 0.0) || !std::isfinite(anchor_weight)) {
    return InvalidArgumentError("anchor weight must be positive and finite");
  }
  std::vector<char> component_anchored(topology.component_count, 0);
  for (const int32_t a : anchors) {
    if (a < 0 || a >= v_count) {
      return InvalidArgumentError("anchor vertex " + std::to_string(a) + " is outside [0, " +
                                  std::to_string(v_count) + ")");
    }
    component_anchored[topology.component_of_vertex[a]] = 1;
  }
  // Without an anchor a component's positions are free up to translation: N is singular there.
  for (int v = 0; v < v_count; ++v) {
    const int component = topology.component_of_vertex[v];
    if (!component_anchored[component]) {
      return NumericalFailureError("connected component " + std::to_string(component) +
                                   " (containing vertex " + std::to_string(v) +
                                   ") has no anchor: the normal matrix LᵀL is singular there");
    }
  }
  if (options.max_matrix_bytes != 0) {
    // Column j of L with n_j entries contributes at most n_j² entries to LᵀL.
    uint64_t entries = 0;
    for (Eigen::Index j = 0; j < laplacian.outerSize(); ++j) {
      const auto n = static_cast<uint64_t>(
          laplacian.isCompressed() ? laplacian.outerIndexPtr()[j + 1] - laplacian.outerIndexPtr()[j]
                                   : laplacian.innerNonZeroPtr()[j]);
      entries += n * n;
    }
    if (12 * entries > options.max_matrix_bytes) {
      return ResourceLimitError("the " + std::to_string(v_count) + "×" + std::to_string(v_count) +
                                " normal matrix LᵀL could hold " + std::to_string(entries) +
                                " entries (" + std::to_string(12 * entries) +
                                " bytes), above the limit of " +
                                std::to_string(options.max_matrix_bytes) + " bytes");
    }
  }
  SparseMatrixD transpose = laplacian.transpose();
  DMC_ASSIGN_OR_RETURN(
      SparseSpdSolver solver,
      SparseSpdSolver::Factor(
          NormalMatrixWithDiagonal(laplacian, transpose,
                                   AnchorDiagonal(laplacian.cols(), anchors, anchor_weight)),
          options));
  return AnchoredLaplacianSolver(std::move(transpose), std::move(anchors), anchor_weight,
                                 std::move(solver));
}

StatusOr<Eigen::MatrixXd> AnchoredLaplacianSolver::Solve(
    const Eigen::MatrixXd& delta, const Eigen::MatrixXd& anchor_values) const {
  Eigen::MatrixXd solution = delta;
  DMC_RETURN_IF_ERROR(SolveInPlace(solution, anchor_values));
  return solution;
}

Status AnchoredLaplacianSolver::SolveInPlace(Eigen::MatrixXd& delta_to_solution,
                                             const Eigen::MatrixXd& anchor_values) const {
  const Eigen::Index v_count = laplacian_transpose_.rows();
  Eigen::MatrixXd& x = delta_to_solution;
  if (x.rows() != v_count) {
    return MismatchError("differential coordinates have " + std::to_string(x.rows()) +
                         " rows for " + std::to_string(v_count) + " vertices");
  }
  if (anchor_values.rows() != static_cast<Eigen::Index>(anchors_.size()) ||
      anchor_values.cols() != x.cols()) {
    return MismatchError("anchor values are " + std::to_string(anchor_values.rows()) + "×" +
                         std::to_string(anchor_values.cols()) + ", expected " +
                         std::to_string(anchors_.size()) + "×" + std::to_string(x.cols()));
  }
  // Lᵀ·Δ column by column, the columns in parallel, each through one column of scratch: Eigen's
  // sparse × dense product handles each column on its own in the same order, so this is bit for
  // bit the one-shot product.
  core_internal::PerThread<Eigen::VectorXd> scratch{Eigen::VectorXd(v_count)};
  core_internal::ParallelFor(Eigen::Index{0}, x.cols(), [&](Eigen::Index column) {
    Eigen::VectorXd& product = scratch.local();
    product.noalias() = laplacian_transpose_ * x.col(column);
    x.col(column) = product;
  });
  const double weight_squared = anchor_weight_ * anchor_weight_;
  for (size_t k = 0; k < anchors_.size(); ++k) {
    x.row(anchors_[k]) += weight_squared * anchor_values.row(static_cast<Eigen::Index>(k));
  }
  return solver_.SolveInPlace(x);
}

}  // namespace dmc
