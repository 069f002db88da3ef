// Trajectory PCA: the shared math of reduced trajectories (dmc_fitting).
//
// A sequence of F frames and V vertices is the V×3F trajectory matrix X whose row v is vertex v's
// whole trajectory (x₀ y₀ z₀ x₁ y₁ z₁ …), i.e. X(v, 3f + axis). PCA writes
//   X ≈ 1·meanᵀ + C·Bᵀ,
// with mean the 1×3F average trajectory, B (3F×r) orthonormal principal directions in decreasing
// order of variance, and C = (X − 1·meanᵀ)·B the V×r coefficients: the "reduced trajectories" a
// DDL can be fitted to (dmc laplacian --rank, the Python bindings). Because B is orthonormal,
// ‖L·C‖ equals ‖L·X‖ restricted to the retained subspace for any unit-sum operator L (L·1 = 0
// removes the mean).
//
// Computed from the eigen-decomposition of the smaller Gram matrix: the 3F×3F XcᵀXc when 3F ≤ V
// (the usual case, cost V·(3F)² + (3F)³), otherwise the V×V XcXcᵀ. The 3F×3F path, the mean and
// the projection are the encoder's own segment PCA routines (fitting/segment_pca.h; the encoder
// calls those directly, per segment, and chooses the rank itself), deterministic for any thread
// count. Signs are fixed deterministically (each basis column's entry of largest magnitude is
// positive). On the V×V path a direction of numerically zero variance (eigenvalue ≤ 1e-12 × the
// largest) has no defined basis vector and is returned as a zero column with zero coefficients.
#pragma once

#include <Eigen/Core>

#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc {

struct TrajectoryPca {
  Eigen::RowVectorXd mean;       // 1×3F mean trajectory
  Eigen::MatrixXd basis;         // 3F×r, orthonormal columns
  Eigen::MatrixXd coefficients;  // V×r
  // Eigenvalues of the centred Gram matrix, decreasing, all min(V, 3F) of them: the energy
  // (squared Frobenius norm) each component carries; the first r are kept.
  Eigen::VectorXd eigenvalues;
};

// The V×3F trajectory matrix in double precision.
Eigen::MatrixXd TrajectoryMatrix(const MeshSequence& sequence);

// PCA of rank `rank`, clamped to min(V, 3F). kInvalidArgument for rank < 1 or an empty sequence.
StatusOr<TrajectoryPca> ComputeTrajectoryPca(const MeshSequence& sequence, int rank);
StatusOr<TrajectoryPca> ComputeTrajectoryPca(const Eigen::MatrixXd& trajectories, int rank);

// 1·meanᵀ + C·Bᵀ: the V×3F trajectories the PCA represents.
Eigen::MatrixXd ReconstructTrajectories(const TrajectoryPca& pca);

}  // namespace dmc
