#include "dmc/pca.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <utility>

#include "fitting/segment_pca.h"

namespace dmc {

Eigen::MatrixXd TrajectoryMatrix(const MeshSequence& sequence) {
  Eigen::MatrixXd trajectories(sequence.vertex_count(), 3 * sequence.frame_count());
  for (int f = 0; f < sequence.frame_count(); ++f) {
    trajectories.middleCols(3 * f, 3) = sequence.frame(f).cast<double>();
  }
  return trajectories;
}

StatusOr<TrajectoryPca> ComputeTrajectoryPca(const MeshSequence& sequence, int rank) {
  return ComputeTrajectoryPca(TrajectoryMatrix(sequence), rank);
}

StatusOr<TrajectoryPca> ComputeTrajectoryPca(const Eigen::MatrixXd& trajectories, int rank) {
  const Eigen::Index v_count = trajectories.rows(), dims = trajectories.cols();
  if (v_count == 0 || dims == 0) {
    return InvalidArgumentError("trajectory PCA of an empty sequence");
  }
  if (rank < 1) return InvalidArgumentError(fmt::format("PCA rank must be ≥ 1, got {}", rank));
  if (!trajectories.allFinite()) return InvalidArgumentError("trajectories are not finite");
  const Eigen::Index kept = std::min<Eigen::Index>({rank, v_count, dims});

  TrajectoryPca pca;
  Eigen::VectorXd mean;
  if (dims <= v_count) {
    // The encoder's segment PCA: the 3F×3F Gram matrix of the centred trajectories.
    SegmentPca segment = ComputeSegmentPca(trajectories);
    mean = std::move(segment.mean);
    pca.eigenvalues = std::move(segment.eigenvalues);
    pca.basis = segment.eigenvectors.leftCols(kept);
  } else {
    // More coordinates than vertices: the V×V Gram XcXcᵀ shares the nonzero spectrum, and
    // B = Xcᵀ·U·Σ⁻¹ recovers the principal directions.
    mean = MeanTrajectory(trajectories);
    const Eigen::MatrixXd centred = trajectories.rowwise() - mean.transpose();
    Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(v_count, v_count);
    gram.selfadjointView<Eigen::Lower>().rankUpdate(centred);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(gram);
    pca.eigenvalues = eigen.eigenvalues().reverse().cwiseMax(0.0);
    const Eigen::MatrixXd u = eigen.eigenvectors().rightCols(kept).rowwise().reverse();
    pca.basis = centred.transpose() * u;
    // Xcᵀu has norm √λ. A direction of (numerically) zero variance has no defined basis vector:
    // normalising its rounding noise would break orthonormality, so it stays a zero column,
    // whose coefficients are then zero as well.
    const double negligible = 1e-12 * std::max(pca.eigenvalues[0], 0.0);
    for (Eigen::Index c = 0; c < kept; ++c) {
      if (pca.eigenvalues[c] > negligible && pca.eigenvalues[c] > 0.0) {
        pca.basis.col(c).normalize();
      } else {
        pca.basis.col(c).setZero();
      }
    }
  }
  for (Eigen::Index c = 0; c < kept; ++c) {
    Eigen::Index largest = 0;
    pca.basis.col(c).cwiseAbs().maxCoeff(&largest);
    if (pca.basis(largest, c) < 0.0) pca.basis.col(c) *= -1.0;
  }
  pca.coefficients = ProjectTrajectories(trajectories, mean, pca.basis);
  pca.mean = mean.transpose();
  return pca;
}

Eigen::MatrixXd ReconstructTrajectories(const TrajectoryPca& pca) {
  return (pca.coefficients * pca.basis.transpose()).rowwise() + pca.mean;
}

}  // namespace dmc
