// Parameterisation, morphing, curvature, spectral filtering and the scalar PLY output.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include "dmc/io.h"
#include "processing_test_util.h"

namespace dmc {
namespace {

using testing::MeasurementValue;
using testing::MustApply;
using testing::MustPrepare;

// ---- param-barycentric

TEST(ParamBarycentric, MeanValueWeightsReproduceAPlanarDiskUpToASimilarity) {
  // A planar disk, tilted and moved out of the xy plane: with its own boundary, mean-value
  // weights (linear precision) give back its shape.
  const MeshSequence grid = testing::JitteredPlanarGrid(10, 0.35);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  FramePositionsD tilted =
      (grid.frame_d(0) * rotation.transpose()).rowwise() + Eigen::RowVector3d(1.0, -2.0, 0.5);
  MeshSequence disk(grid.vertex_count(), grid.triangles(), 0);
  ASSERT_TRUE(disk.AppendFrame(tilted.cast<float>()).ok());
  RunOptions options;
  options.operator_name = "mean-value";
  options.parameters = {{"boundary", "input"}};
  const FrameOutput output =
      MustApply(MustPrepare("param-barycentric", disk, options), disk.frame_d(0));
  EXPECT_EQ(output.positions.col(2).cwiseAbs().maxCoeff(), 0.0);
  // Dynamic sizes: GCC 12 reports a false -Wstringop-overread inside umeyama's fixed 2-D path.
  const Eigen::MatrixXd uv = output.positions.leftCols(2).transpose();
  const Eigen::MatrixXd xy = grid.frame_d(0).leftCols(2).transpose();
  const Eigen::MatrixXd similarity = Eigen::umeyama(uv, xy, /*with_scaling=*/true);
  const Eigen::MatrixXd mapped =
      (similarity.topLeftCorner(2, 2) * uv).colwise() + similarity.topRightCorner(2, 1).col(0);
  EXPECT_LT((mapped - xy).cwiseAbs().maxCoeff(), 1e-5);  // float input positions
  EXPECT_EQ(MeasurementValue(output.measurements, "flipped_triangles"), 0.0);
  EXPECT_LT(MeasurementValue(output.measurements, "angle_distortion_max_deg"), 1e-3);
  // Tutte weights lack linear precision: the same disk comes out distorted.
  options.operator_name = "tutte";
  const FrameOutput tutte =
      MustApply(MustPrepare("param-barycentric", disk, options), disk.frame_d(0));
  EXPECT_GT(MeasurementValue(tutte.measurements, "angle_distortion_mean_deg"), 0.5);
}

TEST(ParamBarycentric, PositiveWeightsOnAConvexBoundaryFlipNothing) {
  // A bumpy, non-planar disk: the grid lifted onto a paraboloid with noise.
  MeshSequence disk = testing::JitteredPlanarGrid(12, 0.4, 11);
  for (int v = 0; v < disk.vertex_count(); ++v) {
    const float x = disk.frame(0)(v, 0) - 0.5f, y = disk.frame(0)(v, 1) - 0.5f;
    disk.frame(0)(v, 2) = 2.0f * (x * x + y * y) + 0.05f * std::sin(17.0f * static_cast<float>(v));
  }
  for (const char* op : {"tutte", "mean-value", "kirchhoff"}) {
    for (const char* boundary : {"circle", "polygon"}) {
      RunOptions options;
      options.operator_name = op;
      options.parameters = {{"boundary", boundary}, {"sides", "5"}};
      const FrameOutput output =
          MustApply(MustPrepare("param-barycentric", disk, options), disk.frame_d(0));
      EXPECT_EQ(MeasurementValue(output.measurements, "flipped_triangles"), 0.0)
          << op << " " << boundary;
      EXPECT_LE(output.positions.leftCols(2).rowwise().norm().maxCoeff(), 1.0 + 1e-12);
    }
  }
}

TEST(ParamBarycentric, RejectsMeshesThatAreNoDisk) {
  RunOptions options;
  options.operator_name = "tutte";
  EXPECT_EQ(Prepare("param-barycentric", testing::Icosphere(1), options).status().code(),
            ErrorCode::kUnsupported);
  options.parameters = {{"boundary", "square"}};
  EXPECT_EQ(Prepare("param-barycentric", testing::PlanarGrid(4), options).status().code(),
            ErrorCode::kInvalidArgument);
}

// ---- morph

TEST(InterpolateDeltas, EndpointsAndRotationLengthsBetweenTheInputs) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd from(200, 3), to(200, 3);
  for (Eigen::Index i = 0; i < from.size(); ++i) {
    from(i) = normal(rng);
    to(i) = normal(rng);
  }
  to.row(0) = -from.row(0);       // antiparallel
  to.row(1) = 3.0 * from.row(1);  // parallel
  to.row(2).setZero();            // a zero vector
  for (DeltaInterpolation mode : {DeltaInterpolation::kLinear, DeltaInterpolation::kRotation}) {
    EXPECT_LT((InterpolateDeltas(from, to, 0.0, mode) - from).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((InterpolateDeltas(from, to, 1.0, mode) - to).cwiseAbs().maxCoeff(), 1e-12);
  }
  for (double t : {0.1, 0.25, 0.5, 0.9}) {
    const Eigen::MatrixXd d = InterpolateDeltas(from, to, t, DeltaInterpolation::kRotation);
    for (Eigen::Index i = 0; i < d.rows(); ++i) {
      const double a = from.row(i).norm(), b = to.row(i).norm(), length = d.row(i).norm();
      EXPECT_GE(length, std::min(a, b) - 1e-12) << i << " t " << t;
      EXPECT_LE(length, std::max(a, b) + 1e-12) << i << " t " << t;
      EXPECT_NEAR(length, (1.0 - t) * a + t * b, 1e-12) << i;
      if (i >= 3) {
        // The direction turns by t·α in the plane of the two vectors.
        const double alpha = std::acos(std::clamp(from.row(i).dot(to.row(i)) / (a * b), -1.0, 1.0));
        const double turned =
            std::acos(std::clamp(from.row(i).dot(d.row(i)) / (a * length), -1.0, 1.0));
        EXPECT_NEAR(turned, t * alpha, 1e-9) << i;
        const Eigen::Vector3d normal =
            Eigen::Vector3d(from.row(i).transpose()).cross(Eigen::Vector3d(to.row(i).transpose()));
        EXPECT_NEAR(normal.dot(d.row(i).transpose()), 0.0, 1e-9) << i;
      }
    }
    // Antiparallel vectors keep their length instead of collapsing through zero.
    EXPECT_NEAR(d.row(0).norm(), from.row(0).norm(), 1e-12);
    const Eigen::MatrixXd linear = InterpolateDeltas(from, to, 0.5, DeltaInterpolation::kLinear);
    EXPECT_LT(linear.row(0).norm(), 1e-12);
  }
}

// Two frames of a sphere: the second with a bulge on one side.
MeshSequence BulgingSphere() {
  const MeshSequence sphere = testing::Icosphere(2);
  MeshSequence sequence(sphere.vertex_count(), sphere.triangles(), 0);
  EXPECT_TRUE(sequence.AppendFrame(sphere.frame(0)).ok());
  FramePositions bulged = sphere.frame(0);
  for (int v = 0; v < sphere.vertex_count(); ++v) {
    const float x = bulged(v, 0);
    if (x > 0.3f) bulged.row(v) *= 1.0f + 0.6f * (x - 0.3f);
  }
  EXPECT_TRUE(sequence.AppendFrame(bulged).ok());
  return sequence;
}

TEST(Morph, EndpointsReturnTheInputs) {
  const MeshSequence pair = BulgingSphere();
  for (const char* mode : {"linear", "rotation"}) {
    for (const char* op : {"tutte", "cotan", "kirchhoff"}) {
      RunOptions options;
      options.operator_name = op;
      options.parameters = {{"interpolation", mode}, {"frames", "5"}};
      const auto result = RunMethod("morph", pair, options);
      ASSERT_TRUE(result.ok()) << result.status().ToString();
      ASSERT_EQ(result->sequence.frame_count(), 5);
      EXPECT_LT((result->sequence.frame_d(0) - pair.frame_d(0)).cwiseAbs().maxCoeff(), 1e-5)
          << mode << " " << op;
      EXPECT_LT((result->sequence.frame_d(4) - pair.frame_d(1)).cwiseAbs().maxCoeff(), 1e-5)
          << mode << " " << op;
    }
  }
}

TEST(Morph, LinearWholeMeshMorphIsPositionInterpolation) {
  // δ is linear in x, so interpolating δ linearly is interpolating positions (thesis 3.5).
  const MeshSequence pair = BulgingSphere();
  RunOptions options;
  options.operator_name = "cotan";
  options.parameters = {{"interpolation", "linear"}, {"frames", "5"}};
  const auto result = RunMethod("morph", pair, options);
  ASSERT_TRUE(result.ok());
  for (int k = 0; k < 5; ++k) {
    const double t = k / 4.0;
    const FramePositionsD expected = (1.0 - t) * pair.frame_d(0) + t * pair.frame_d(1);
    EXPECT_LT((result->sequence.frame_d(k) - expected).cwiseAbs().maxCoeff(), 1e-5) << k;
  }
}

TEST(Morph, PartialMorphMovesHandlesAndKeepsFixedVertices) {
  const MeshSequence pair = BulgingSphere();
  RunOptions options;
  options.operator_name = "tutte";
  options.parameters = {{"frames", "3"}};
  // Handles: the bulging cap; fixed: the far side.
  for (int v = 0; v < pair.vertex_count(); ++v) {
    const float x = pair.frame(0)(v, 0);
    if (x > 0.6f) options.selection.handles.push_back(v);
    if (x < -0.2f) options.selection.fixed.push_back(v);
  }
  const auto result = RunMethod("morph", pair, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const FramePositionsD middle = result->sequence.frame_d(1);
  const FramePositionsD halfway = 0.5 * (pair.frame_d(0) + pair.frame_d(1));
  for (int32_t h : options.selection.handles) {
    EXPECT_LT((middle.row(h) - halfway.row(h)).norm(), 1e-5);
  }
  for (int32_t f : options.selection.fixed) {
    EXPECT_LT((middle.row(f) - pair.frame_d(0).row(f)).norm(), 1e-6);
  }
  // Fixed vertices do not move in either input, so t = 1 gives the second input.
  EXPECT_LT((result->sequence.frame_d(2) - pair.frame_d(1)).cwiseAbs().maxCoeff(), 1e-5);
}

// ---- curvature

TEST(Curvature, CotanAreaOnASphereIsOneOverTheRadius) {
  const double radius = 2.0;
  const MeshSequence sphere = testing::Icosphere(4, radius);
  RunOptions options;
  options.operator_name = "cotan-area";
  const auto output = RunMethodOnMesh("curvature", sphere.triangles(), sphere.frame_d(0), options);
  ASSERT_TRUE(output.ok()) << output.status().ToString();
  ASSERT_EQ(output->vertex_scalar.size(), sphere.vertex_count());
  EXPECT_NEAR(output->vertex_scalar.mean(), 1.0 / radius, 0.01 / radius);
  EXPECT_GT(output->vertex_scalar.minCoeff(), 0.95 / radius);
  EXPECT_LT(output->vertex_scalar.maxCoeff(), 1.05 / radius);
  EXPECT_EQ(output->positions, sphere.frame_d(0));
  // Reversed orientation: the normals point inward and the sign flips.
  Triangles reversed = sphere.triangles();
  reversed.col(1).swap(reversed.col(2));
  const auto inward = RunMethodOnMesh("curvature", reversed, sphere.frame_d(0), options);
  ASSERT_TRUE(inward.ok());
  EXPECT_LT((inward->vertex_scalar + output->vertex_scalar).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Curvature, PlanarInteriorHasZeroCurvatureWithLinearPrecision) {
  const MeshSequence grid = testing::JitteredPlanarGrid(9, 0.3);
  const MeshTopology topology = BuildTopology(grid.triangles(), grid.vertex_count());
  for (const char* op : {"cotan", "mean-value", "cotan-area"}) {
    RunOptions options;
    options.operator_name = op;
    const auto output = RunMethodOnMesh("curvature", grid.triangles(), grid.frame_d(0), options);
    ASSERT_TRUE(output.ok());
    for (int v = 0; v < grid.vertex_count(); ++v) {
      if (!topology.is_boundary_vertex(v)) {
        EXPECT_NEAR(output->vertex_scalar[v], 0.0, 1e-5) << op;
      }
    }
  }
}

TEST(Curvature, SequencesGetOneScalarPerFrame) {
  const MeshSequence animation = testing::Animate(testing::Icosphere(2), 3);
  RunOptions options;
  options.operator_name = "cotan-area";
  for (bool frame_operator : {false, true}) {
    options.parameters = {{"frame-operator", frame_operator ? "true" : "false"}};
    const auto result = RunMethod("curvature", animation, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    EXPECT_EQ(result->scalar_name, "mean_curvature");
    ASSERT_EQ(result->vertex_scalars.size(), 3u);
    // With the frame's own operator, frame f's estimate equals the single-mesh estimate.
    if (frame_operator) {
      const auto single =
          RunMethodOnMesh("curvature", animation.triangles(), animation.frame_d(2), options);
      ASSERT_TRUE(single.ok());
      EXPECT_LT((result->vertex_scalars[2] - single->vertex_scalar).cwiseAbs().maxCoeff(), 1e-9);
    }
  }
}

// ---- spectral-filter

TEST(SpectralFilter, LowPassRemovesNoiseFromASphere) {
  const MeshSequence noisy = testing::NoisySphere(3, 1.0, 0.03);
  const double before = testing::RadialRoughness(noisy.frame_d(0));
  for (const char* op : {"kirchhoff", "cotan-sym"}) {
    RunOptions options;
    options.operator_name = op;
    options.parameters = {{"k", "36"}};
    const PreparedRun run = MustPrepare("spectral-filter", noisy, options);
    const FrameOutput output = MustApply(run, noisy.frame_d(0));
    EXPECT_LT(testing::RadialRoughness(output.positions), 0.5 * before) << op;
    // The constant vector is in the basis: the centroid (in the mass metric) is kept.
    EXPECT_LT(MeasurementValue(output.measurements, "eigenvalue_min"), 1e-6) << op;
    // Enhancement amplifies the same noise instead.
    options.parameters = {{"k", "36"}, {"filter", "enhance"}, {"gain", "2"}};
    const FrameOutput enhanced =
        MustApply(MustPrepare("spectral-filter", noisy, options), noisy.frame_d(0));
    EXPECT_GT(testing::RadialRoughness(enhanced.positions), 1.5 * before) << op;
  }
}

TEST(SpectralFilter, AllEigenvectorsOfATinyMeshReproduceIt) {
  // With k = V − 1 of V eigenvectors only the highest frequency is dropped; with a basis that
  // spans the coordinates (an octahedron's x, y, z are eigenvectors of its Kirchhoff matrix),
  // the low-pass reproduces the mesh.
  Triangles octahedron(8, 3);
  octahedron << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  MeshSequence mesh(6, octahedron, 1);
  mesh.frame(0) << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  RunOptions options;
  options.operator_name = "kirchhoff";
  options.parameters = {{"k", "4"}};
  const FrameOutput output =
      MustApply(MustPrepare("spectral-filter", mesh, options), mesh.frame_d(0));
  EXPECT_LT((output.positions - mesh.frame_d(0)).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(SpectralFilter, NeedsASymmetricOperator) {
  RunOptions options;
  options.operator_name = "cotan";
  EXPECT_EQ(Prepare("spectral-filter", testing::Icosphere(2), options).status().code(),
            ErrorCode::kInvalidArgument);
}

// ---- scalar PLY

TEST(ScalarPly, WritesThePropertyAndColoursAndReadsBackAsAMesh) {
  const MeshSequence tetra = testing::Tetrahedron();
  Eigen::VectorXd values(4);
  values << -2.0, 0.0, 1.0, 2.0;
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "dmc_processing_scalar_test.ply";
  ASSERT_TRUE(
      WriteScalarPly(path, tetra.triangles(), tetra.frame_d(0), values, "mean_curvature").ok());
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_NE(text.str().find("property float mean_curvature"), std::string::npos);
  EXPECT_NE(text.str().find("property uchar red"), std::string::npos);
  const auto read = ReadSequence(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->frame_d(0), tetra.frame_d(0));
  EXPECT_EQ(read->triangles(), tetra.triangles());
  std::filesystem::remove(path);
  EXPECT_EQ(WriteScalarPly(path, tetra.triangles(), tetra.frame_d(0), values, "bad name").code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(WriteScalarPly(path, tetra.triangles(), tetra.frame_d(0), values.head(3), "h").code(),
            ErrorCode::kInvalidArgument);
}

TEST(ScalarPly, DivergingColourMap) {
  EXPECT_EQ(DivergingColour(0.0, 1.0), (std::array<uint8_t, 3>{255, 255, 255}));
  EXPECT_EQ(DivergingColour(1.0, 1.0), (std::array<uint8_t, 3>{255, 0, 0}));
  EXPECT_EQ(DivergingColour(5.0, 1.0), (std::array<uint8_t, 3>{255, 0, 0}));  // saturates
  EXPECT_EQ(DivergingColour(-1.0, 1.0), (std::array<uint8_t, 3>{0, 0, 255}));
  EXPECT_EQ(DivergingColour(0.5, 1.0), (std::array<uint8_t, 3>{255, 128, 128}));
  EXPECT_EQ(DivergingColour(std::nan(""), 1.0), (std::array<uint8_t, 3>{255, 255, 255}));
}

}  // namespace
}  // namespace dmc
