// The non-fitted operators: identities on many meshes, hand-computed weights, linear precision,
// the mean-curvature normal on a sphere, and robustness on defective meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "dmc/operators.h"
#include "test_support.h"
#include "unit/operators/operator_checks.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc {
namespace {

struct NamedBuilder {
  const char* name;
  std::function<StatusOr<LaplaceOperator>(const MeshTopology&, const FramePositionsD&)> build;
};

std::vector<NamedBuilder> AllBuilders() {
  return {
      {"kirchhoff",
       [](const MeshTopology& t, const FramePositionsD&) { return BuildKirchhoff(t); }},
      {"tutte", [](const MeshTopology& t, const FramePositionsD&) { return BuildTutte(t); }},
      {"cotan", [](const MeshTopology& t, const FramePositionsD& p) { return BuildCotan(t, p); }},
      {"cotan-area",
       [](const MeshTopology& t, const FramePositionsD& p) { return BuildCotanArea(t, p); }},
      {"cotan-sym",
       [](const MeshTopology& t, const FramePositionsD& p) { return BuildCotanSym(t, p); }},
      {"mean-value",
       [](const MeshTopology& t, const FramePositionsD& p) { return BuildMeanValue(t, p); }},
  };
}

std::vector<std::pair<std::string, MeshSequence>> TestMeshes() {
  return {
      {"tetrahedron", testing::Tetrahedron()},
      {"grid", testing::PlanarGrid(7)},
      {"jittered-grid", testing::JitteredPlanarGrid(9, 0.3)},
      {"icosphere", testing::Icosphere(2)},
      {"strip", testing::Strip(12)},
      {"components", testing::TwoTetrahedraAndIsolatedVertex()},
      {"defective", testing::DefectiveGrid()},
  };
}

TEST(GeometricOperators, SatisfyTheLaplacianIdentitiesOnManyMeshes) {
  for (const auto& [mesh_name, mesh] : TestMeshes()) {
    SCOPED_TRACE(mesh_name);
    const MeshTopology topo = BuildTopology(mesh.triangles(), mesh.vertex_count());
    const FramePositionsD frame = mesh.frame_d(0);
    for (const auto& builder : AllBuilders()) {
      const auto op = builder.build(topo, frame);
      ASSERT_TRUE(op.ok()) << builder.name << ": " << op.status().ToString();
      EXPECT_EQ(op->name, builder.name);
      testing::ExpectOperatorIdentities(*op, topo);
    }
  }
}

TEST(GeometricOperators, DiagonalConventionPerOperator) {
  const MeshSequence sphere = testing::Icosphere(1);
  const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
  const FramePositionsD frame = sphere.frame_d(0);
  const auto kirchhoff = BuildKirchhoff(topo);
  const auto cotan_sym = BuildCotanSym(topo, frame);
  const auto cotan_area = BuildCotanArea(topo, frame);
  ASSERT_TRUE(kirchhoff.ok() && cotan_sym.ok() && cotan_area.ok());
  const std::vector<double> k = CotangentEdgeWeights(topo, frame);
  for (int v = 0; v < topo.vertex_count; ++v) {
    EXPECT_EQ(kirchhoff->matrix.coeff(v, v), -topo.degree(v));
    double k_sum = 0.0;
    for (int s = topo.ring_offsets[v]; s < topo.ring_offsets[v + 1]; ++s)
      k_sum += k[topo.ring_edges[s]];
    EXPECT_NEAR(cotan_sym->matrix.coeff(v, v), -k_sum, 1e-12);
    EXPECT_NEAR(cotan_area->matrix.coeff(v, v), -k_sum / cotan_area->mass[v], 1e-9);
  }
  // M⁻¹·(cotan-sym) = cotan-area.
  const SparseMatrixD scaled = cotan_sym->mass.cwiseInverse().asDiagonal() * cotan_sym->matrix;
  EXPECT_LE((scaled - cotan_area->matrix).norm(), 1e-10 * cotan_area->matrix.norm());
}

TEST(CotangentWeights, RightIsoscelesTriangleByHand) {
  // Angles: 90° at vertex 0, 45° at vertices 1 and 2. Edges (0,1) (0,2) (1,2).
  Triangles tris(1, 3);
  tris << 0, 1, 2;
  const MeshTopology topo = BuildTopology(tris, 3);
  FramePositionsD frame(3, 3);
  frame << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  const std::vector<double> k = CotangentEdgeWeights(topo, frame);
  ASSERT_EQ(k.size(), 3u);
  EXPECT_NEAR(k[0], 0.5, 1e-15);  // opposite the 45° at vertex 2: cot 45° / 2
  EXPECT_NEAR(k[1], 0.5, 1e-15);
  EXPECT_NEAR(k[2], 0.0, 1e-15);  // opposite the right angle
  const Eigen::VectorXd areas = MixedVoronoiAreas(topo, frame);
  EXPECT_NEAR(areas[0], 0.25, 1e-15);  // (1·cot 45° + 1·cot 45°) / 8
  EXPECT_NEAR(areas[1], 0.125, 1e-15);
  EXPECT_NEAR(areas[2], 0.125, 1e-15);
}

TEST(CotangentWeights, ObtuseTriangleUsesHalfAndQuarterAreas) {
  Triangles tris(1, 3);
  tris << 0, 1, 2;
  const MeshTopology topo = BuildTopology(tris, 3);
  FramePositionsD frame(3, 3);
  frame << 0, 0, 0, 2, 0, 0, 1, 0.2, 0;  // obtuse at vertex 2, area 0.2
  const Eigen::VectorXd areas = MixedVoronoiAreas(topo, frame);
  EXPECT_NEAR(areas[2], 0.1, 1e-15);
  EXPECT_NEAR(areas[0], 0.05, 1e-15);
  EXPECT_NEAR(areas[1], 0.05, 1e-15);
  // cot of the obtuse angle is negative: (−1, −0.2)·(1, −0.2) / |cross| = −0.96 / 0.4.
  const std::vector<double> k = CotangentEdgeWeights(topo, frame);
  EXPECT_NEAR(k[0], 0.5 * (-0.96 / 0.4), 1e-12);
}

TEST(CotangentWeights, VoronoiAreasSumToTheSurfaceArea) {
  const MeshSequence grid = testing::JitteredPlanarGrid(10, 0.35);
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  EXPECT_NEAR(MixedVoronoiAreas(topo, grid.frame_d(0)).sum(), 1.0, 1e-12);
}

TEST(MeanValueWeights, RegularHexagonFanGivesEqualWeights) {
  Triangles tris(6, 3);
  FramePositionsD frame(7, 3);
  frame.row(0) << 0, 0, 0;
  for (int k = 0; k < 6; ++k) {
    const double angle = k * std::numbers::pi / 3.0;
    frame.row(k + 1) << std::cos(angle), std::sin(angle), 0;
    tris.row(k) << 0, k + 1, (k + 1) % 6 + 1;
  }
  const MeshTopology topo = BuildTopology(tris, 7);
  const std::vector<double> raw = MeanValueDirectedWeights(topo, frame);
  for (int s = topo.ring_offsets[0]; s < topo.ring_offsets[1]; ++s) {
    EXPECT_NEAR(raw[s], 2.0 * std::tan(std::numbers::pi / 6.0), 1e-14);  // 2 tan(30°) / 1
  }
  const auto op = BuildMeanValue(topo, frame);
  ASSERT_TRUE(op.ok());
  for (int j = 1; j <= 6; ++j) EXPECT_NEAR(op->matrix.coeff(0, j), 1.0 / 6.0, 1e-15);
}

TEST(GeometricOperators, LinearPrecisionOnAnIrregularPlanarMesh) {
  const int n = 12;
  const MeshSequence grid = testing::JitteredPlanarGrid(n, 0.3);
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  const FramePositionsD frame = grid.frame_d(0);
  for (const auto& builder : AllBuilders()) {
    const auto op = builder.build(topo, frame);
    ASSERT_TRUE(op.ok());
    const Eigen::MatrixXd delta = op->matrix * Eigen::MatrixXd(frame);
    double max_interior = 0.0;
    for (int v = 0; v < topo.vertex_count; ++v) {
      if (!topo.is_boundary_vertex(v)) max_interior = std::max(max_interior, delta.row(v).norm());
    }
    const std::string name = builder.name;
    if (name == "tutte" || name == "kirchhoff") {
      // The barycentre of an irregular one-ring is not the vertex (jitter ≈ 0.3 cells ≈ 0.03).
      EXPECT_GT(max_interior, 5e-3) << name;
    } else {
      // Scale: coordinates ≈ 1, cotan-area entries ≈ 1/area ≈ 100.
      EXPECT_LT(max_interior, 1e-11) << name << " is linearly precise";
    }
  }
}

TEST(GeometricOperators, CotanAreaApproximatesTheMeanCurvatureNormalOnASphere) {
  const double radius = 2.0;
  const MeshSequence sphere = testing::Icosphere(3, radius);  // 642 vertices
  const MeshTopology topo = BuildTopology(sphere.triangles(), sphere.vertex_count());
  const FramePositionsD frame = sphere.frame_d(0);
  const auto op = BuildCotanArea(topo, frame);
  ASSERT_TRUE(op.ok());
  const Eigen::MatrixXd delta = op->matrix * Eigen::MatrixXd(frame);
  double max_relative_error = 0.0;
  for (int v = 0; v < topo.vertex_count; ++v) {
    const double curvature = delta.row(v).norm() / 2.0;  // ‖δ‖ = 2H, H = 1/R
    max_relative_error = std::max(max_relative_error, std::abs(curvature * radius - 1.0));
    // δ = −2Hn: it points to the centre.
    EXPECT_LT(delta.row(v).normalized().dot(frame.row(v).normalized()), -0.999) << v;
  }
  // Measured 3.7e-5 here (1.4e-4 at 162 vertices, 2.0e-5 at 2562): the icosphere's vertices lie
  // on the sphere up to float rounding. Stated tolerance: 0.1 %.
  EXPECT_LT(max_relative_error, 1e-3);
}

TEST(GeometricOperators, DefectiveTrianglesAreClampedAndCountedNeverNaN) {
  const MeshSequence mesh = testing::DefectiveGrid();
  const MeshTopology topo = BuildTopology(mesh.triangles(), mesh.vertex_count());
  const FramePositionsD frame = mesh.frame_d(0);
  const auto cotan = BuildCotan(topo, frame);
  const auto area = BuildCotanArea(topo, frame);
  const auto mean_value = BuildMeanValue(topo, frame);
  ASSERT_TRUE(cotan.ok() && area.ok() && mean_value.ok());
  EXPECT_GT(cotan->stats.clamped_cotangents, 0);
  EXPECT_GT(cotan->stats.degenerate_triangles, 0);
  EXPECT_GT(mean_value->stats.degenerate_triangles, 0);
  for (const auto* op : {&*cotan, &*area, &*mean_value}) {
    EXPECT_TRUE(Eigen::MatrixXd(op->matrix).allFinite()) << op->name;
  }
  // Every weight is within the documented clamp: |k_ij| ≤ max_cotangent (two halves).
  const std::vector<double> k = CotangentEdgeWeights(topo, frame);
  for (const double w : k) EXPECT_LE(std::abs(w), GeometricOptions{}.max_cotangent);
}

// A triangle with a repeated vertex (allowed by indexed connectivity; RobotExpressive has three)
// has a corner o equal to i or j: it adds nothing, and no weight o → o is ever touched (the mean
// value loop once indexed slot -1 there).
TEST(GeometricOperators, TrianglesWithARepeatedVertexAddNothing) {
  MeshSequence grid = testing::PlanarGrid(4);
  Triangles tris(grid.triangles().rows() + 2, 3);
  tris.topRows(grid.triangles().rows()) = grid.triangles();
  // On edges the grid does not have (0–15 and 3–12), so the grid's own corners are unchanged.
  tris.row(grid.triangles().rows()) << 0, 0, 15;
  tris.row(grid.triangles().rows() + 1) << 3, 12, 12;
  const MeshTopology with = BuildTopology(tris, grid.vertex_count());
  const MeshTopology without = BuildTopology(grid.triangles(), grid.vertex_count());
  const FramePositionsD frame = grid.frame_d(0);
  const std::vector<double> weights = MeanValueDirectedWeights(with, frame);
  const std::vector<double> reference = MeanValueDirectedWeights(without, frame);
  for (int v = 0; v < without.vertex_count; ++v) {
    for (int s = without.ring_offsets[v]; s < without.ring_offsets[v + 1]; ++s) {
      EXPECT_EQ(weights[RingSlot(with, v, without.ring_neighbors[s])], reference[s]);
    }
  }
  for (const auto& [a, b] : {std::pair{0, 15}, std::pair{3, 12}}) {
    EXPECT_EQ(weights[RingSlot(with, a, b)], 0.0);
    EXPECT_EQ(weights[RingSlot(with, b, a)], 0.0);
  }
  for (const auto& builder : AllBuilders()) {
    const auto op = builder.build(with, frame);
    ASSERT_TRUE(op.ok()) << builder.name;
    EXPECT_TRUE(Eigen::MatrixXd(op->matrix).allFinite()) << builder.name;
  }
}

TEST(GeometricOperators, AllDegenerateMeshStillGivesFiniteOperators) {
  // Every vertex at the same point: no angle, no area, no length.
  MeshSequence grid = testing::PlanarGrid(4);
  grid.frame(0).setZero();
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  for (const auto& builder : AllBuilders()) {
    const auto op = builder.build(topo, grid.frame_d(0));
    ASSERT_TRUE(op.ok()) << builder.name;
    testing::ExpectOperatorIdentities(*op, topo);
  }
  const auto cotan = BuildCotan(topo, grid.frame_d(0));
  EXPECT_EQ(cotan->stats.fallback_rows, topo.vertex_count);  // all rows fell back to Tutte
}

TEST(GeometricOperators, RejectFramesOfTheWrongSize) {
  const MeshSequence grid = testing::PlanarGrid(4);
  const MeshTopology topo = BuildTopology(grid.triangles(), grid.vertex_count());
  const FramePositionsD small = FramePositionsD::Zero(3, 3);
  EXPECT_EQ(BuildCotan(topo, small).status().code(), ErrorCode::kMismatch);
  EXPECT_EQ(BuildMeanValue(topo, small).status().code(), ErrorCode::kMismatch);
  FramePositionsD nan = grid.frame_d(0);
  nan(3, 1) = NAN;
  EXPECT_EQ(BuildCotanSym(topo, nan).status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc
