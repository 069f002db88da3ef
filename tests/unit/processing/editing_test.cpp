// laplacian-edit and ls-mesh: identities of the constrained least-squares solves.
#include <gtest/gtest.h>

#include <cmath>

#include "processing_test_util.h"

namespace dmc {
namespace {

using testing::MustApply;
using testing::MustPrepare;

struct Case {
  std::string name;
  MeshSequence mesh;
};

std::vector<Case> Meshes() {
  return {{"icosphere", testing::Icosphere(2)},
          {"jittered-grid", testing::JitteredPlanarGrid(9, 0.3)},
          {"animated-sphere", testing::Animate(testing::Icosphere(2), 3)}};
}

// Handles: a patch of low indices; fixed: a patch of high indices; the rest free.
Selection PatchSelection(int vertex_count) {
  Selection selection;
  for (int v = 0; v < 4; ++v) selection.handles.push_back(v);
  for (int v = vertex_count - 6; v < vertex_count; ++v) selection.fixed.push_back(v);
  return selection;
}

TEST(LaplacianEdit, UnmovedHandlesReturnTheInput) {
  for (const Case& c : Meshes()) {
    for (const char* op : {"cotan", "tutte", "mean-value", "kirchhoff", "cotan-sym"}) {
      for (const char* mode : {"hard", "soft"}) {
        RunOptions options;
        options.operator_name = op;
        options.selection = PatchSelection(c.mesh.vertex_count());
        options.parameters = {{"constraints", mode}};
        const PreparedRun run = MustPrepare("laplacian-edit", c.mesh, options);
        for (int f = 0; f < c.mesh.frame_count(); ++f) {
          const FramePositionsD input = c.mesh.frame_d(f);
          const FrameOutput output = MustApply(run, input);
          EXPECT_LT((output.positions - input).cwiseAbs().maxCoeff(), 1e-9)
              << c.name << " " << op << " " << mode << " frame " << f;
        }
      }
    }
  }
}

TEST(LaplacianEdit, TranslatingEverythingTranslatesTheResult) {
  const Eigen::RowVector3d shift(0.3, -1.2, 2.5);
  for (const Case& c : Meshes()) {
    for (const char* mode : {"hard", "soft"}) {
      RunOptions options;
      options.operator_name = "cotan";
      options.selection = PatchSelection(c.mesh.vertex_count());
      options.selection.transform.topRightCorner<3, 1>() << 0.1, 0.2, -0.05;
      options.parameters = {{"constraints", mode}};
      const PreparedRun run = MustPrepare("laplacian-edit", c.mesh, options);
      const FramePositionsD input = c.mesh.frame_d(0);
      const FramePositionsD moved = input.rowwise() + shift;
      const FrameOutput a = MustApply(run, input);
      const FrameOutput b = MustApply(run, moved);
      EXPECT_LT(((b.positions.rowwise() - shift) - a.positions).cwiseAbs().maxCoeff(), 1e-9)
          << c.name << " " << mode;
      // The edit really moved something.
      EXPECT_GT((a.positions - input).cwiseAbs().maxCoeff(), 0.01) << c.name << " " << mode;
    }
  }
}

TEST(LaplacianEdit, HardConstraintsAreMetExactly) {
  const MeshSequence sphere = testing::Icosphere(3);
  RunOptions options;
  options.operator_name = "cotan";
  options.selection = PatchSelection(sphere.vertex_count());
  options.selection.transform.topRightCorner<3, 1>() << 0.0, 0.0, 0.4;
  const PreparedRun run = MustPrepare("laplacian-edit", sphere, options);
  const FramePositionsD input = sphere.frame_d(0);
  const FrameOutput output = MustApply(run, input);
  for (int32_t h : options.selection.handles) {
    EXPECT_DOUBLE_EQ(output.positions(h, 2), input(h, 2) + 0.4);
  }
  for (int32_t v : options.selection.fixed) {
    EXPECT_EQ(output.positions.row(v), input.row(v));
  }
  EXPECT_EQ(testing::MeasurementValue(output.measurements, "constraint_error"), 0.0);
}

TEST(LaplacianEdit, SoftConstraintsConvergeToHardAsTheWeightGrows) {
  for (const Case& c : Meshes()) {
    RunOptions options;
    options.operator_name = "mean-value";
    options.selection = PatchSelection(c.mesh.vertex_count());
    options.selection.transform.topRightCorner<3, 1>() << 0.2, 0.1, 0.3;
    const FramePositionsD input = c.mesh.frame_d(0);
    options.parameters = {{"constraints", "hard"}};
    const FramePositionsD hard =
        MustApply(MustPrepare("laplacian-edit", c.mesh, options), input).positions;
    double previous = std::numeric_limits<double>::infinity();
    double first = 0.0;
    for (double weight : {1.0, 10.0, 100.0, 1000.0}) {
      options.parameters = {{"constraints", "soft"}, {"weight", std::to_string(weight)}};
      const FramePositionsD soft =
          MustApply(MustPrepare("laplacian-edit", c.mesh, options), input).positions;
      const double difference = (soft - hard).cwiseAbs().maxCoeff();
      if (weight == 1.0) first = difference;
      EXPECT_LT(difference, previous) << c.name << " weight " << weight;
      previous = difference;
    }
    EXPECT_LT(previous, 1e-3 * first) << c.name;
    EXPECT_LT(previous, 1e-4) << c.name;
  }
}

TEST(LaplacianEdit, NewHandleTargetsReuseTheFactorisation) {
  const MeshSequence grid = testing::JitteredPlanarGrid(10, 0.2);
  RunOptions options;
  options.operator_name = "cotan";
  options.selection = PatchSelection(grid.vertex_count());
  options.selection.transform.topRightCorner<3, 1>() << 0.0, 0.0, 0.25;
  const PreparedRun run = MustPrepare("laplacian-edit", grid, options);
  const FramePositionsD input = grid.frame_d(0);
  // Targets given at apply time equal to the transform's produce the same result...
  FrameConstraints constraints;
  constraints.handle_positions = TransformedHandlePositions(run.selection, input);
  const FrameOutput via_transform = MustApply(run, input);
  const FrameOutput via_targets = MustApply(run, input, &constraints);
  EXPECT_LT((via_transform.positions - via_targets.positions).cwiseAbs().maxCoeff(), 1e-12);
  // ...and the solution is linear in the targets: halfway targets give the halfway result.
  constraints.handle_positions.col(2).array() -= 0.125;
  const FrameOutput halfway = MustApply(run, input, &constraints);
  const FramePositionsD expected = 0.5 * (input + via_transform.positions);
  EXPECT_LT((halfway.positions - expected).cwiseAbs().maxCoeff(), 1e-9);
  // Wrong target count: kMismatch.
  constraints.handle_positions.resize(2, 3);
  EXPECT_EQ(run.prepared->Apply(input, 0, &constraints).status().code(), ErrorCode::kMismatch);
}

TEST(LaplacianEdit, AnchorsPullFreeVerticesTowardTheirInput) {
  const MeshSequence grid = testing::JitteredPlanarGrid(10, 0.2);
  const FramePositionsD input = grid.frame_d(0);
  RunOptions options;
  options.operator_name = "tutte";
  options.selection.handles = {0, 1, 2};
  options.selection.transform.topRightCorner<3, 1>() << 0.0, 0.0, 1.0;
  const double free_motion =
      MustApply(MustPrepare("laplacian-edit", grid, options), input).positions.col(2).norm();
  for (int v = 40; v < 60; ++v) options.selection.anchors.push_back(v);
  options.parameters = {{"anchor-weight", "10"}};
  const double anchored_motion =
      MustApply(MustPrepare("laplacian-edit", grid, options), input).positions.col(2).norm();
  EXPECT_LT(anchored_motion, free_motion);
}

TEST(LaplacianEdit, EveryComponentNeedsAConstraint) {
  const MeshSequence mesh = testing::TwoTetrahedraAndIsolatedVertex();
  RunOptions options;
  options.operator_name = "kirchhoff";
  options.selection.handles = {0};
  const auto missing = Prepare("laplacian-edit", mesh, options);
  EXPECT_EQ(missing.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(missing.status().message().find("vertex 4"), std::string::npos)
      << missing.status().message();
  // One constraint per tetrahedron suffices; the isolated vertex stays where it is.
  options.selection.fixed = {4};
  const PreparedRun run = MustPrepare("laplacian-edit", mesh, options);
  const FramePositionsD input = mesh.frame_d(0);
  const FrameOutput output = MustApply(run, input);
  EXPECT_LT((output.positions - input).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(LeastSquaresMesh, ControlPointsAtTheirPositionsOnAPlaneKeepThePlane) {
  const MeshSequence grid = testing::JitteredPlanarGrid(9, 0.3);
  RunOptions options;
  options.operator_name = "tutte";
  for (int v = 0; v < grid.vertex_count(); v += 7) options.selection.handles.push_back(v);
  const PreparedRun run = MustPrepare("ls-mesh", grid, options);
  const FrameOutput output = MustApply(run, grid.frame_d(0));
  // z-targets are all 0 and L·0 = 0: the least-squares z is exactly 0.
  EXPECT_LT(output.positions.col(2).cwiseAbs().maxCoeff(), 1e-12);
  // Lifting every control point by h lifts the whole surface by h (L·1 = 0 for unit sum).
  options.selection.transform(2, 3) = 0.7;
  const FrameOutput lifted = MustApply(MustPrepare("ls-mesh", grid, options), grid.frame_d(0));
  EXPECT_LT((lifted.positions.col(2).array() - 0.7).abs().maxCoeff(), 1e-9);
  EXPECT_LT((lifted.positions.leftCols(2) - output.positions.leftCols(2)).cwiseAbs().maxCoeff(),
            1e-9);
}

TEST(LeastSquaresMesh, HeavierControlPointsAreApproximatedCloser) {
  const MeshSequence sphere = testing::Icosphere(2);
  RunOptions options;
  options.operator_name = "kirchhoff";
  for (int v = 0; v < sphere.vertex_count(); v += 5) options.selection.handles.push_back(v);
  double previous = std::numeric_limits<double>::infinity();
  for (const char* weight : {"0.1", "1", "10", "100"}) {
    options.parameters = {{"weight", weight}};
    const FrameOutput output =
        MustApply(MustPrepare("ls-mesh", sphere, options), sphere.frame_d(0));
    const double error = testing::MeasurementValue(output.measurements, "control_point_error");
    EXPECT_LT(error, previous) << "weight " << weight;
    previous = error;
  }
  EXPECT_LT(previous, 1e-3);
}

TEST(LeastSquaresMesh, TwoComponentsNeedTwoControlPoints) {
  const MeshSequence mesh = testing::TwoTetrahedraAndIsolatedVertex();
  RunOptions options;
  options.operator_name = "tutte";
  options.selection.handles = {1};
  EXPECT_EQ(Prepare("ls-mesh", mesh, options).status().code(), ErrorCode::kInvalidArgument);
  options.selection.handles = {1, 5};
  const FrameOutput output = MustApply(MustPrepare("ls-mesh", mesh, options), mesh.frame_d(0));
  EXPECT_LT((output.positions.row(8) - mesh.frame_d(0).row(8)).norm(), 1e-12);  // isolated: kept
}

}  // namespace
}  // namespace dmc
