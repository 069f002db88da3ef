// Dual quaternions, blending, weighted Kabsch and the kd-tree against brute force.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>
#include <vector>

#include "dmc/tvm.h"
#include "tvm/kd_tree.h"
#include "unit/tvm/tvm_fixtures.h"

namespace dmc::tvm {
namespace {

using testing::RigidMotion;

TEST(DualQuaternionTest, MatchesTheIsometryItWasMadeFrom) {
  const Eigen::Isometry3d m = RigidMotion(0.7, {1, 2, 3}, {0.5, -1.0, 2.0});
  const DualQuaternion q = DualQuaternion::FromIsometry(m);
  const Eigen::Vector3d p(0.3, -0.2, 1.1);
  EXPECT_LT((q.Apply(p) - m * p).norm(), 1e-14);
  EXPECT_LT((q.Translation() - m.translation()).norm(), 1e-14);
  EXPECT_LT((q.ToIsometry().matrix() - m.matrix()).norm(), 1e-14);
  EXPECT_NEAR(q.RotationAngle(), 0.7, 1e-14);
  EXPECT_NEAR(q.Norm(), 1.0, 1e-15);
}

TEST(DualQuaternionTest, ProductComposesAndConjugateInverts) {
  const Eigen::Isometry3d a = RigidMotion(0.4, {0, 1, 0}, {1, 0, 0});
  const Eigen::Isometry3d b = RigidMotion(-1.2, {1, 1, 0}, {0, 2, -1});
  const DualQuaternion qa = DualQuaternion::FromIsometry(a), qb = DualQuaternion::FromIsometry(b);
  const Eigen::Vector3d p(-0.4, 0.9, 0.25);
  EXPECT_LT(((qa * qb).Apply(p) - a * (b * p)).norm(), 1e-14);
  EXPECT_LT(((qa * qa.Conjugate()).Apply(p) - p).norm(), 1e-14);
  EXPECT_LT((qa.Conjugate().Apply(qa.Apply(p)) - p).norm(), 1e-14);
}

TEST(DualQuaternionTest, BlendingIdenticalOrAntipodalCopiesGivesTheSameMotion) {
  const DualQuaternion q = DualQuaternion::FromIsometry(RigidMotion(2.5, {0, 0, 1}, {3, 1, 0}));
  const std::vector<DualQuaternion> copies{q, q * -1.0, q};
  const std::vector<double> weights{0.2, 0.5, 0.3};
  const DualQuaternion blend = BlendDualQuaternions(copies, weights);
  const Eigen::Vector3d p(1, 2, 3);
  EXPECT_LT((blend.Apply(p) - q.Apply(p)).norm(), 1e-14);
}

TEST(DualQuaternionTest, BlendOfTwoRotationsAboutOneAxisIsTheMidRotation) {
  // Equal-weight DQB of rotations by 0 and 60 degrees about the same axis through (1,0,0) is the
  // 30-degree rotation about that axis (dual quaternion blending is exact on a common screw).
  const Eigen::Vector3d pivot(1, 0, 0);
  auto about_pivot = [&](double angle) {
    return DualQuaternion::FromTranslation(pivot) *
           DualQuaternion::FromRotation(
               Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()))) *
           DualQuaternion::FromTranslation(-pivot);
  };
  const std::vector<DualQuaternion> ends{about_pivot(0.0), about_pivot(std::numbers::pi / 3)};
  const std::vector<double> weights{1.0, 1.0};
  const DualQuaternion blend = BlendDualQuaternions(ends, weights);
  const Eigen::Vector3d p(2, 0, 0);
  EXPECT_LT((blend.Apply(p) - about_pivot(std::numbers::pi / 6).Apply(p)).norm(), 1e-14);
}

TEST(DualQuaternionTest, NormalizedProjectsOntoUnitDualQuaternions) {
  const DualQuaternion q = DualQuaternion::FromIsometry(RigidMotion(1.0, {1, 0, 0}, {0, 1, 0}));
  DualQuaternion skewed = q * 3.0;
  skewed = skewed + DualQuaternion({0, 0, 0, 0}, q.real()) * 0.5;  // dual part gains r itself
  const DualQuaternion unit = skewed.Normalized();
  EXPECT_NEAR(unit.Norm(), 1.0, 1e-15);
  EXPECT_NEAR(unit.real().coeffs().dot(unit.dual().coeffs()), 0.0, 1e-15);
  EXPECT_LT((unit.Translation() - q.Translation()).norm(), 1e-14);
}

TEST(WeightedKabschTest, RecoversAKnownRotationAndIgnoresZeroWeightOutliers) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  FramePositionsD source(20, 3), target(20, 3);
  const Eigen::Isometry3d m = RigidMotion(1.1, {0.3, -1, 0.5}, {4, 5, 6});
  std::vector<double> weights;
  for (int j = 0; j < 20; ++j) {
    const Eigen::Vector3d p(normal(rng), normal(rng), normal(rng));
    source.row(j) = p.transpose();
    target.row(j) = (m * p).transpose();
    weights.push_back(j < 15 ? 0.1 + 0.05 * j : 0.0);
    if (j >= 15) target.row(j) = Eigen::RowVector3d(100, -100, 50);  // outliers with weight 0
  }
  const Eigen::Matrix3d rotation = WeightedKabsch(source, target, weights);
  EXPECT_LT((rotation - m.linear()).norm(), 1e-12);
  EXPECT_NEAR(rotation.determinant(), 1.0, 1e-12);
}

TEST(WeightedKabschTest, AReflectedTargetStillGivesAProperRotation) {
  FramePositionsD source(4, 3), target(4, 3);
  source << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  target = source;
  target.col(2) *= -1.0;  // a mirror image
  const std::vector<double> weights{1, 1, 1, 1};
  EXPECT_NEAR(WeightedKabsch(source, target, weights).determinant(), 1.0, 1e-12);
}

TEST(KdTreeTest, AgreesWithBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1, 1);
  FramePositionsD points(500, 3);
  for (int i = 0; i < 500; ++i) points.row(i) << uniform(rng), uniform(rng), uniform(rng);
  points.row(7) = points.row(3);  // a duplicate: ties go to the lower index
  const tvm_internal::KdTree tree(points);
  for (int q = 0; q < 50; ++q) {
    const Eigen::Vector3d query = q == 0
                                      ? Eigen::Vector3d(points.row(3))
                                      : Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    std::vector<std::pair<double, int32_t>> all;
    for (int i = 0; i < 500; ++i)
      all.emplace_back((points.row(i).transpose() - query).squaredNorm(), i);
    std::sort(all.begin(), all.end());
    EXPECT_EQ(tree.Nearest(query), all[0].second);
    const auto knn = tree.KNearest(query, 12);
    ASSERT_EQ(knn.size(), 12u);
    for (size_t i = 0; i < 12; ++i) EXPECT_EQ(knn[i].second, all[i].second);
    std::vector<int32_t> within;
    tree.WithinRadius(query, 0.09, within);
    std::sort(within.begin(), within.end());
    std::vector<int32_t> expected;
    for (const auto& [d2, i] : all) {
      if (d2 <= 0.09) expected.push_back(i);
    }
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(within, expected);
  }
}

}  // namespace
}  // namespace dmc::tvm
