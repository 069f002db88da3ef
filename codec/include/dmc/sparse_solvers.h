// Normal equations of anchored Laplacian systems: factor once, solve many (dmc_operators;
// decoder side).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "dmc/laplace_operator.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

// N = L̃ᵀL̃ for L̃ = [L; anchor_weight·P], P selecting the anchor rows: N = LᵀL + anchor_weight²·
// Σ_a e_a e_aᵀ. Sparse (2-ring pattern), symmetric; positive definite when every connected
// component holds an anchor and L has rank V − components.
SparseMatrixD BuildNormalMatrix(const SparseMatrixD& laplacian, std::span<const int32_t> anchors,
                                double anchor_weight = 1.0);

enum class SolverBackend : uint8_t {
  kAuto,            // the measured faster one for Laplacian normal matrices (see solvers/)
  kCholmod,         // CHOLMOD supernodal LLᵀ through Eigen's CholmodSupport
  kSimplicialLdlt,  // Eigen::SimplicialLDLT (AMD ordering)
};
std::string_view SolverBackendName(SolverBackend backend);
// Whether this build has the backend: kCholmod only when built with -DDMC_WITH_CHOLMOD=ON (it is
// GPL-2.0-or-later; licenses/README.md); Factor() with an absent one is kUnsupported.
bool SolverBackendAvailable(SolverBackend backend);

// Fill-reducing ordering of the CHOLMOD backend (SimplicialLDLT always uses AMD).
enum class SolverOrdering : uint8_t {
  kAuto,   // nested dissection (METIS) from 30000 unknowns on, AMD below
  kAmd,    // approximate minimum degree: cheapest analysis
  kMetis,  // nested dissection: less fill on large mesh-like graphs, costlier analysis
};

struct SolverOptions {
  SolverBackend backend = SolverBackend::kAuto;
  SolverOrdering ordering = SolverOrdering::kAuto;
  // The factorisation is rejected as numerically singular when its smallest pivot is below
  // min_pivot_ratio × its largest (an estimate of 1/cond(N)); a semidefinite N (an unanchored
  // component) lands near 1e-16 while real Laplacian normal matrices stay far above.
  double min_pivot_ratio = 1e-13;
  // A solve is rejected when X is non-finite, or when ‖N·x − b‖ > max_relative_residual × ‖b‖
  // summed (squared) over the columns whose index is a multiple of residual_check_spacing (1:
  // every column). The codec's normal matrices check one column in 16 (FactorSegmentOperator):
  // there the check guards against a factor spoilt by ill-conditioning, which shows in the
  // leading PCA columns as much as in any, and checking all r columns cost a fifth of the solve.
  double max_relative_residual = 1e-6;
  int residual_check_spacing = 1;
  // Largest normal matrix and factor accepted, in bytes (0: no bound): a factorisation whose
  // factor CHOLMOD's analysis predicts above it, or an AnchoredLaplacianSolver whose LᵀL could
  // hold more (12 bytes per entry, Σ over L's columns of their entry count squared), is refused
  // with kResourceLimit before the memory is taken. Their size follows the connectivity's
  // structure, not its size alone: one vertex of degree d puts d² entries in LᵀL.
  uint64_t max_matrix_bytes = 0;
};

// Factorisation of a symmetric positive definite sparse matrix, reused for many right-hand
// sides. Move-only. Failures: kInvalidArgument (not square, empty, non-finite entries),
// kNumericalFailure (not positive definite or numerically singular: never a garbage factor).
class SparseSpdSolver {
 public:
  static StatusOr<SparseSpdSolver> Factor(const SparseMatrixD& matrix,
                                          const SolverOptions& options = {});
  SparseSpdSolver(SparseSpdSolver&&) noexcept;
  SparseSpdSolver& operator=(SparseSpdSolver&&) noexcept;
  ~SparseSpdSolver();

  // Solves N·X = B for all columns of B (n×r) at once. kMismatch on a row-count mismatch,
  // kNumericalFailure if the result is non-finite or its residual exceeds the tolerance.
  StatusOr<Eigen::MatrixXd> Solve(const Eigen::MatrixXd& rhs) const;
  // The same, overwriting B with X: with CHOLMOD one n×r matrix live instead of two (only the
  // columns the residual check samples are copied). The bits are Solve's. On failure
  // `rhs_to_solution` holds partial results.
  Status SolveInPlace(Eigen::MatrixXd& rhs_to_solution) const;

  SolverBackend backend() const;
  int size() const;
  double pivot_ratio() const;  // smallest / largest pivot of the factor

 private:
  struct Impl;
  explicit SparseSpdSolver(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Least-squares reconstruction from differential coordinates and anchors, the decoder's core:
// X = argmin ‖L·X − Δ‖² + anchor_weight²·‖P·X − A‖², i.e. N·X = Lᵀ·Δ + anchor_weight²·Pᵀ·A.
// Create() checks that every connected component has an anchor (otherwise N is singular:
// kNumericalFailure naming the component) and factors N once.
class AnchoredLaplacianSolver {
 public:
  static StatusOr<AnchoredLaplacianSolver> Create(const MeshTopology& topology,
                                                  const SparseMatrixD& laplacian,
                                                  std::vector<int32_t> anchors,
                                                  double anchor_weight = 1.0,
                                                  const SolverOptions& options = {});

  // delta: V×r differential coordinates, anchor_values: (anchor count)×r. Returns V×r.
  StatusOr<Eigen::MatrixXd> Solve(const Eigen::MatrixXd& delta,
                                  const Eigen::MatrixXd& anchor_values) const;
  // The same, turning `delta_to_solution` into the V×r solution in place (the right-hand side is
  // formed column by column over it): a decoder holds one V×r matrix, not three. The bits are
  // Solve's; on failure the matrix holds partial results.
  Status SolveInPlace(Eigen::MatrixXd& delta_to_solution,
                      const Eigen::MatrixXd& anchor_values) const;

  const std::vector<int32_t>& anchors() const { return anchors_; }

 private:
  AnchoredLaplacianSolver(SparseMatrixD laplacian_transpose, std::vector<int32_t> anchors,
                          double anchor_weight, SparseSpdSolver solver);
  SparseMatrixD laplacian_transpose_;
  std::vector<int32_t> anchors_;
  double anchor_weight_;
  SparseSpdSolver solver_;
};

}  // namespace dmc
