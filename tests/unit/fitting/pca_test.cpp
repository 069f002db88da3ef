// Trajectory PCA: exact reconstruction at full rank, orthonormality, energy bookkeeping, both Gram
// paths, zero columns, sign convention, errors, and that the public PCA is the encoder's segment
// PCA (fitting/segment_pca.h) on the 3F×3F path.
#include "dmc/pca.h"

#include <gtest/gtest.h>

#include "fitting/segment_pca.h"
#include "test_support.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc {
namespace {

TEST(TrajectoryPca, FullRankReconstructsExactlyAndBasisIsOrthonormal) {
  const MeshSequence seq = testing::Animate(testing::Icosphere(2), 10);  // V = 162, 3F = 30
  const auto pca = ComputeTrajectoryPca(seq, 30);
  ASSERT_TRUE(pca.ok()) << pca.status().ToString();
  ASSERT_EQ(pca->basis.rows(), 30);
  ASSERT_EQ(pca->basis.cols(), 30);
  ASSERT_EQ(pca->coefficients.rows(), 162);
  const Eigen::MatrixXd x = TrajectoryMatrix(seq);
  EXPECT_LE((ReconstructTrajectories(*pca) - x).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LE((pca->basis.transpose() * pca->basis - Eigen::MatrixXd::Identity(30, 30))
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_LE((pca->mean - x.colwise().mean()).norm(), 1e-14);
}

TEST(TrajectoryPca, KeepsTheLargestComponentsAndTheirEnergy) {
  const MeshSequence seq = testing::Animate(testing::JitteredPlanarGrid(8, 0.2), 12);
  const auto pca = ComputeTrajectoryPca(seq, 5);
  ASSERT_TRUE(pca.ok());
  ASSERT_EQ(pca->coefficients.cols(), 5);
  for (int k = 1; k < pca->eigenvalues.size(); ++k) {
    EXPECT_GE(pca->eigenvalues[k - 1], pca->eigenvalues[k]);
  }
  // Each coefficient column carries its eigenvalue's energy; the discarded ones are the error.
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(pca->coefficients.col(k).squaredNorm(), pca->eigenvalues[k],
                1e-9 * pca->eigenvalues[0]);
  }
  const Eigen::MatrixXd x = TrajectoryMatrix(seq);
  const double error = (ReconstructTrajectories(*pca) - x).squaredNorm();
  EXPECT_NEAR(error, pca->eigenvalues.tail(pca->eigenvalues.size() - 5).sum(),
              1e-8 * pca->eigenvalues[0]);
}

TEST(TrajectoryPca, VertexGramPathAgreesWhenThereAreMoreCoordinatesThanVertices) {
  // V = 4 < 3F = 60: the V×V Gram path. Centred data have rank ≤ V − 1 = 3.
  const MeshSequence seq = testing::Animate(testing::Tetrahedron(), 20);
  const auto pca = ComputeTrajectoryPca(seq, 10);  // clamped to min(V, 3F) = 4
  ASSERT_TRUE(pca.ok());
  EXPECT_EQ(pca->basis.cols(), 4);
  EXPECT_LE((ReconstructTrajectories(*pca) - TrajectoryMatrix(seq)).cwiseAbs().maxCoeff(), 1e-10);
  const Eigen::MatrixXd gram = pca->basis.leftCols(3).transpose() * pca->basis.leftCols(3);
  EXPECT_LE((gram - Eigen::MatrixXd::Identity(3, 3)).cwiseAbs().maxCoeff(), 1e-12);
  // The fourth direction has no variance: a zero column with zero coefficients, not noise.
  EXPECT_LE(pca->eigenvalues[3], 1e-12 * pca->eigenvalues[0]);
  EXPECT_TRUE(pca->basis.col(3).isZero(0.0));
  EXPECT_TRUE(pca->coefficients.col(3).isZero(0.0));
}

TEST(TrajectoryPca, IsTheEncodersSegmentPcaOnTheCoordinateGramPath) {
  const MeshSequence seq = testing::Animate(testing::Icosphere(2), 8);  // V = 162 ≥ 3F = 24
  const auto pca = ComputeTrajectoryPca(seq, 6);
  ASSERT_TRUE(pca.ok()) << pca.status().ToString();
  const SegmentTrajectories trajectories = GatherTrajectories(seq, 0, seq.frame_count());
  const SegmentPca segment = ComputeSegmentPca(trajectories);
  EXPECT_EQ(pca->mean, segment.mean.transpose());
  EXPECT_EQ(pca->eigenvalues, segment.eigenvalues);
  for (int c = 0; c < 6; ++c) {  // the same eigenvectors, up to the sign fixed here
    const Eigen::VectorXd column = segment.eigenvectors.col(c);
    EXPECT_TRUE(pca->basis.col(c) == column || pca->basis.col(c) == -column) << "column " << c;
  }
  EXPECT_EQ(pca->coefficients, ProjectTrajectories(trajectories, segment.mean, pca->basis));
}

// The double overloads the public PCA uses run the float ones' sums on the same values.
TEST(SegmentPca, DoubleTrajectoriesGiveTheFloatResultsBitForBit) {
  const MeshSequence seq = testing::Animate(testing::JitteredPlanarGrid(70, 0.2), 5);  // 2 blocks
  const SegmentTrajectories floats = GatherTrajectories(seq, 0, seq.frame_count());
  const Eigen::MatrixXd doubles = floats.cast<double>();
  ASSERT_GT(floats.rows(), 4096);
  const SegmentPca a = ComputeSegmentPca(floats);
  const SegmentPca b = ComputeSegmentPca(doubles);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(MeanTrajectory(doubles), a.mean);
  EXPECT_EQ(a.eigenvalues, b.eigenvalues);
  EXPECT_EQ(a.eigenvectors, b.eigenvectors);
  const Eigen::MatrixXd basis = a.eigenvectors.leftCols(4);
  EXPECT_EQ(ProjectTrajectories(floats, a.mean, basis),
            ProjectTrajectories(doubles, a.mean, basis));
}

TEST(TrajectoryPca, SignsAreFixedDeterministically) {
  const MeshSequence seq = testing::Animate(testing::Icosphere(1), 6);
  const auto pca = ComputeTrajectoryPca(seq, 4);
  ASSERT_TRUE(pca.ok());
  for (int c = 0; c < 4; ++c) {
    Eigen::Index largest = 0;
    pca->basis.col(c).cwiseAbs().maxCoeff(&largest);
    EXPECT_GT(pca->basis(largest, c), 0.0);
  }
}

TEST(TrajectoryPca, RejectsBadRanksAndEmptyInput) {
  const MeshSequence seq = testing::Animate(testing::Tetrahedron(), 2);
  EXPECT_EQ(ComputeTrajectoryPca(seq, 0).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(ComputeTrajectoryPca(Eigen::MatrixXd(), 3).status().code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc
