// AssembleLaplacian and the decoder-side rebuild: hand-computed matrices and error cases.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dmc/operators.h"
#include "test_support.h"
#include "unit/operators/operator_checks.h"

namespace dmc {
namespace {

using ::testing::HasSubstr;

// Two triangles sharing edge (1, 2): 0-1-2 and 1-3-2. Edges, sorted: (0,1) (0,2) (1,2) (1,3) (2,3).
Triangles TwoTriangles() {
  Triangles tris(2, 3);
  tris << 0, 1, 2, 1, 3, 2;
  return tris;
}

TEST(AssembleLaplacian, PerEdgeWeightsGiveSymmetricMatrixWithNegativeRowSumDiagonal) {
  const MeshTopology topo = BuildTopology(TwoTriangles(), 4);
  ASSERT_EQ(topo.edge_count(), 5);
  const auto matrix = AssembleLaplacian(topo, {WeightLayout::kPerEdge, {1, 2, 3, 4, 5}});
  ASSERT_TRUE(matrix.ok()) << matrix.status().ToString();
  Eigen::Matrix4d expected;
  expected << -3, 1, 2, 0,  //
      1, -8, 3, 4,          //
      2, 3, -10, 5,         //
      0, 4, 5, -9;
  EXPECT_EQ(Eigen::Matrix4d(Eigen::MatrixXd(*matrix)), expected);
}

TEST(AssembleLaplacian, PerDirectedEdgeWeightsFollowRingOrder) {
  const MeshTopology topo = BuildTopology(TwoTriangles(), 4);
  // Rings: 0:{1,2} 1:{0,2,3} 2:{0,1,3} 3:{1,2}; ten directed slots numbered in that order.
  std::vector<double> values(10);
  for (int k = 0; k < 10; ++k) values[k] = k + 1;
  const auto matrix = AssembleLaplacian(topo, {WeightLayout::kPerDirectedEdge, values});
  ASSERT_TRUE(matrix.ok());
  Eigen::Matrix4d expected;
  expected << -3, 1, 2, 0,  //
      3, -12, 4, 5,         //
      6, 7, -21, 8,         //
      0, 9, 10, -19;
  EXPECT_EQ(Eigen::Matrix4d(Eigen::MatrixXd(*matrix)), expected);
  EXPECT_EQ(RingSlot(topo, 2, 3), 7);
  EXPECT_EQ(RingSlot(topo, 0, 3), -1);
}

TEST(AssembleLaplacian, KeepsZeroWeightsInThePattern) {
  const MeshTopology topo = BuildTopology(TwoTriangles(), 4);
  const auto matrix = AssembleLaplacian(topo, {WeightLayout::kPerEdge, {0, 0, 0, 0, 0}});
  ASSERT_TRUE(matrix.ok());
  EXPECT_EQ(matrix->nonZeros(), 4 + 2 * 5);
}

TEST(AssembleLaplacian, RejectsWrongCountsAndNonFiniteWeights) {
  const MeshTopology topo = BuildTopology(TwoTriangles(), 4);
  const auto wrong = AssembleLaplacian(topo, {WeightLayout::kPerDirectedEdge, {1, 2, 3, 4, 5}});
  EXPECT_EQ(wrong.status().code(), ErrorCode::kMismatch);
  EXPECT_THAT(wrong.status().message(), HasSubstr("10 directed edges"));
  const auto nan = AssembleLaplacian(topo, {WeightLayout::kPerEdge, {1, 2, NAN, 4, 5}});
  EXPECT_EQ(nan.status().code(), ErrorCode::kInvalidArgument);
}

TEST(AssembleLaplacian, IsolatedVertexGetsAZeroRow) {
  const MeshTopology topo = BuildTopology(TwoTriangles(), 5);
  const auto op = BuildTutte(topo);
  ASSERT_TRUE(op.ok());
  testing::ExpectOperatorIdentities(*op, topo);
  EXPECT_EQ(op->matrix.coeff(4, 4), 0.0);
  EXPECT_EQ(op->stats.isolated_vertices, 1);
}

TEST(RebuildOperator, RebuildsDdlFromDecodedWeightsExactly) {
  const MeshTopology topo = BuildTopology(TwoTriangles(), 4);
  const OperatorWeights weights{WeightLayout::kPerEdge, {0.5, 0.5, 0.25, 0.75, 0.125}};
  const auto rebuilt = RebuildOperator(OperatorId::kDdl, topo, nullptr, &weights);
  ASSERT_TRUE(rebuilt.ok()) << rebuilt.status().ToString();
  const auto direct = AssembleLaplacian(topo, weights);
  EXPECT_EQ((rebuilt->matrix - *direct).norm(), 0.0);
  EXPECT_EQ(rebuilt->name, "ddl");
  EXPECT_TRUE(rebuilt->symmetric);
}

TEST(RebuildOperator, GeometricOperatorsMatchTheirBuilders) {
  const MeshSequence grid = testing::PlanarGrid(5);
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  const FramePositionsD frame = grid.frame_d(0);
  const auto rebuilt = RebuildOperator(OperatorId::kMeanValue, topo, &frame, nullptr);
  const auto built = BuildMeanValue(topo, frame);
  ASSERT_TRUE(rebuilt.ok() && built.ok());
  EXPECT_EQ((rebuilt->matrix - built->matrix).norm(), 0.0);
  EXPECT_EQ(OperatorIdName(OperatorId::kCotanArea), "cotan-area");
}

TEST(RebuildOperator, ReportsMissingInputsAndUnknownIds) {
  const MeshTopology topo = BuildTopology(TwoTriangles(), 4);
  const auto no_frame = RebuildOperator(OperatorId::kCotan, topo, nullptr, nullptr);
  EXPECT_EQ(no_frame.status().code(), ErrorCode::kInvalidArgument);
  const OperatorWeights directed{WeightLayout::kPerDirectedEdge, std::vector<double>(10, 0.5)};
  const auto wrong_layout = RebuildOperator(OperatorId::kDdl, topo, nullptr, &directed);
  EXPECT_EQ(wrong_layout.status().code(), ErrorCode::kInvalidArgument);
  const auto unknown = RebuildOperator(static_cast<OperatorId>(42), topo, nullptr, nullptr);
  EXPECT_EQ(unknown.status().code(), ErrorCode::kNotFound);
  EXPECT_THAT(unknown.status().message(), HasSubstr("7 (ddl)"));
  const auto invalid = RebuildOperator(OperatorId::kInvalid, topo, nullptr, nullptr);
  EXPECT_EQ(invalid.status().code(), ErrorCode::kNotFound);
}

TEST(WireIds, AreFrozen) {
  // These values are in published streams: this test fails if anyone renumbers them.
  EXPECT_EQ(static_cast<int>(OperatorId::kInvalid), 0);
  EXPECT_EQ(static_cast<int>(OperatorId::kKirchhoff), 1);
  EXPECT_EQ(static_cast<int>(OperatorId::kTutte), 2);
  EXPECT_EQ(static_cast<int>(OperatorId::kCotan), 3);
  EXPECT_EQ(static_cast<int>(OperatorId::kCotanArea), 4);
  EXPECT_EQ(static_cast<int>(OperatorId::kCotanSym), 5);
  EXPECT_EQ(static_cast<int>(OperatorId::kMeanValue), 6);
  EXPECT_EQ(static_cast<int>(OperatorId::kDdl), 7);
  EXPECT_EQ(static_cast<int>(OperatorId::kDdlAsym), 8);
}

}  // namespace
}  // namespace dmc
