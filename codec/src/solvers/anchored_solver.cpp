// Normal equations of a Laplacian with anchors: N = LᵀL + w²PᵀP, factored once, solved for all
// columns of the differential coordinates at once.
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "dmc/operators.h"

namespace dmc {

SparseMatrixD BuildNormalMatrix(const SparseMatrixD& laplacian, std::span<const int32_t> anchors,
                                double anchor_weight) {
  SparseMatrixD normal = SparseMatrixD(laplacian.transpose()) * laplacian;
  // Anchor rows only touch the diagonal, which is always present in LᵀL for a mesh Laplacian
  // (but may not be for an isolated vertex), so add them as a sparse diagonal.
  Eigen::VectorXd anchor_diagonal = Eigen::VectorXd::Zero(laplacian.cols());
  for (const int32_t a : anchors) anchor_diagonal[a] += anchor_weight * anchor_weight;
  SparseMatrixD diagonal(laplacian.cols(), laplacian.cols());
  diagonal.setIdentity();
  diagonal = anchor_diagonal.asDiagonal() * diagonal;
  normal += diagonal;
  normal.makeCompressed();
  return normal;
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
  DMC_ASSIGN_OR_RETURN(
      SparseSpdSolver solver,
      SparseSpdSolver::Factor(BuildNormalMatrix(laplacian, anchors, anchor_weight), options));
  return AnchoredLaplacianSolver(laplacian.transpose(), std::move(anchors), anchor_weight,
                                 std::move(solver));
}

StatusOr<Eigen::MatrixXd> AnchoredLaplacianSolver::Solve(
    const Eigen::MatrixXd& delta, const Eigen::MatrixXd& anchor_values) const {
  const Eigen::Index v_count = laplacian_transpose_.rows();
  if (delta.rows() != v_count) {
    return MismatchError("differential coordinates have " + std::to_string(delta.rows()) +
                         " rows for " + std::to_string(v_count) + " vertices");
  }
  if (anchor_values.rows() != static_cast<Eigen::Index>(anchors_.size()) ||
      anchor_values.cols() != delta.cols()) {
    return MismatchError("anchor values are " + std::to_string(anchor_values.rows()) + "×" +
                         std::to_string(anchor_values.cols()) + ", expected " +
                         std::to_string(anchors_.size()) + "×" + std::to_string(delta.cols()));
  }
  // Lᵀ·Δ column by column, the columns in parallel: Eigen's sparse × dense product handles each
  // column on its own in the same order, so this is bit for bit the one-shot product.
  Eigen::MatrixXd rhs(v_count, delta.cols());
  tbb::parallel_for(Eigen::Index{0}, delta.cols(), [&](Eigen::Index column) {
    rhs.col(column).noalias() = laplacian_transpose_ * delta.col(column);
  });
  const double weight_squared = anchor_weight_ * anchor_weight_;
  for (size_t k = 0; k < anchors_.size(); ++k) {
    rhs.row(anchors_[k]) += weight_squared * anchor_values.row(static_cast<Eigen::Index>(k));
  }
  return solver_.Solve(rhs);
}

}  // namespace dmc
