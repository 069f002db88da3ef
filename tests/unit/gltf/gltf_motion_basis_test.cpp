// The basis layout's fit (gltf_motion_basis.h): exact low-rank motion takes its rank in targets,
// any motion is reproduced within the tolerance (largest and rms error), targets stay within
// their integer range, and blocks split where they are told to.
#include "io/gltf_motion_basis.h"

#include <gtest/gtest.h>

#include <random>

namespace dmc {
namespace {

using io_internal::glb::AxisTarget;
using io_internal::glb::FitAxisTargets;
using io_internal::glb::FitTolerance;
using io_internal::glb::FrameBlock;
using io_internal::glb::SplitBlocks;

// The fit's reconstruction, Σ_t weights_t(j)·values_t(v).
Eigen::MatrixXd Reconstruct(const std::vector<AxisTarget>& targets, Eigen::Index n,
                            Eigen::Index m) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, m);
  for (const AxisTarget& target : targets) {
    for (Eigen::Index v = 0; v < n; ++v) {
      for (Eigen::Index j = 0; j < m; ++j) {
        out(v, j) += static_cast<double>(target.weights[static_cast<size_t>(j)]) *
                     target.values[static_cast<size_t>(v)];
      }
    }
  }
  return out;
}

void ExpectWithin(const Eigen::MatrixXd& displacements, const std::vector<AxisTarget>& targets,
                  const FitTolerance& tolerance) {
  const Eigen::MatrixXd error =
      displacements - Reconstruct(targets, displacements.rows(), displacements.cols());
  EXPECT_LE(error.cwiseAbs().maxCoeff(), tolerance.max);
  EXPECT_LE(std::sqrt(error.squaredNorm() / static_cast<double>(error.size())), tolerance.rms);
  for (const AxisTarget& target : targets) {
    for (const int16_t value : target.values) EXPECT_LE(std::abs(value), tolerance.largest_value);
  }
}

TEST(GltfMotionBasisTest, ExactRankTakesThatManyTargets) {
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  for (const int rank : {1, 3, 8}) {
    const Eigen::Index n = 500, m = 90;
    Eigen::MatrixXd shapes(n, rank), motion(rank, m);
    for (Eigen::Index i = 0; i < shapes.size(); ++i) shapes.data()[i] = 2000 * normal(random);
    for (Eigen::Index i = 0; i < motion.size(); ++i) motion.data()[i] = normal(random);
    const Eigen::MatrixXd displacements = shapes * motion;
    const FitTolerance tolerance;
    const std::vector<AxisTarget> targets = FitAxisTargets(displacements, 2, tolerance);
    EXPECT_GE(targets.size(), static_cast<size_t>(rank)) << rank;
    EXPECT_LE(targets.size(), static_cast<size_t>(rank + 1)) << rank;
    for (const AxisTarget& target : targets) EXPECT_EQ(target.axis, 2);
    ExpectWithin(displacements, targets, tolerance);
  }
}

TEST(GltfMotionBasisTest, NoiseAndInt8TargetsStayWithinTheTolerance) {
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  const Eigen::Index n = 300, m = 40;
  Eigen::MatrixXd displacements(n, m);
  for (Eigen::Index i = 0; i < displacements.size(); ++i) {
    displacements.data()[i] = 50 * normal(random) + 5000 * std::sin(0.01 * static_cast<double>(i));
  }
  for (const FitTolerance tolerance :
       {FitTolerance{0.5, 1.0, 32767}, FitTolerance{20.0, 60.0, 32767},
        FitTolerance{20.0, 60.0, 127}}) {
    SCOPED_TRACE(tolerance.largest_value);
    ExpectWithin(displacements, FitAxisTargets(displacements, 0, tolerance), tolerance);
  }
}

// A rank-1 block under a tolerance it cannot meet at rank 1 (a vertex far beyond int16 with a tiny
// one): the fit grows its rank through directions the block does not move along and still ends.
TEST(GltfMotionBasisTest, DirectionsWithoutMotionDoNotStallTheFit) {
  Eigen::MatrixXd displacements = Eigen::MatrixXd::Zero(4, 6);
  for (Eigen::Index j = 0; j < 6; ++j) {
    displacements(0, j) = 1e9 * static_cast<double>(j);
    displacements(1, j) = 1e-3 * static_cast<double>(j);
  }
  const FitTolerance tolerance{1e-6, 1e-6, 32767};
  const std::vector<AxisTarget> targets = FitAxisTargets(displacements, 0, tolerance);
  EXPECT_LE(targets.size(), 6u);
}

TEST(GltfMotionBasisTest, StillAxesAndEmptyBlocksHaveNoTargets) {
  EXPECT_TRUE(FitAxisTargets(Eigen::MatrixXd::Zero(10, 5), 1, {}).empty());
  EXPECT_TRUE(FitAxisTargets(Eigen::MatrixXd::Constant(10, 5, 0.3), 1, {}).empty());
  EXPECT_TRUE(FitAxisTargets(Eigen::MatrixXd(0, 5), 1, {}).empty());
}

TEST(GltfMotionBasisTest, BlocksStartWhereToldAndStayShort) {
  const std::vector<FrameBlock> blocks = SplitBlocks(10, {4, 7}, 256);
  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_EQ(blocks[1].first, 4);
  EXPECT_EQ(blocks[1].count, 3);
  EXPECT_EQ(blocks[2].count, 3);
  const std::vector<FrameBlock> capped = SplitBlocks(600, {}, 256);
  ASSERT_EQ(capped.size(), 3u);
  EXPECT_EQ(capped[2].first, 512);
  EXPECT_EQ(capped[2].count, 88);
}

}  // namespace
}  // namespace dmc
