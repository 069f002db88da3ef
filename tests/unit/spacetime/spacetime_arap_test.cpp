// Spacetime ARAP editing: no edit is the identity, a rigid edit of everything is that rigid
// motion, α large confines the edit to the key frame, α small spreads it over the window, the
// energy never increases, and both solvers agree.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "dmc/spacetime.h"
#include "test_support.h"
#include "unit/operators/operator_test_meshes.h"

namespace dmc {
namespace {

constexpr int kGrid = 8;

// A waving jittered grid: 9 frames of 64 vertices.
MeshSequence WavingGrid(int frames = 9) {
  const MeshSequence base = testing::JitteredPlanarGrid(kGrid, 0.3);
  MeshSequence seq(base.vertex_count(), base.triangles(), frames);
  for (int f = 0; f < frames; ++f) {
    seq.frame(f) = base.frame(0);
    for (int v = 0; v < base.vertex_count(); ++v) {
      const float x = base.frame(0)(v, 0);
      seq.frame(f)(v, 2) = 0.05f * std::sin(3.0f * x + 0.4f * static_cast<float>(f));
    }
  }
  return seq;
}

// Handles: the 2×2 centre vertices; fixed: the grid's border (the ROI's spatial boundary).
SpacetimeArapConstraints CentreHandlesBorderFixed() {
  SpacetimeArapConstraints c;
  for (int y = 0; y < kGrid; ++y) {
    for (int x = 0; x < kGrid; ++x) {
      const int v = y * kGrid + x;
      if (x == 0 || y == 0 || x == kGrid - 1 || y == kGrid - 1) c.fixed.push_back(v);
      if ((x == 3 || x == 4) && (y == 3 || y == 4)) c.handles.push_back(v);
    }
  }
  return c;
}

Eigen::MatrixXd HandlePositions(const MeshSequence& seq, int frame,
                                const std::vector<int32_t>& handles) {
  Eigen::MatrixXd positions(handles.size(), 3);
  for (size_t h = 0; h < handles.size(); ++h) {
    positions.row(static_cast<Eigen::Index>(h)) = seq.frame_d(frame).row(handles[h]);
  }
  return positions;
}

// Largest vertex displacement of frame f between two sequences.
double FrameChange(const MeshSequence& a, const MeshSequence& b, int f) {
  return (a.frame_d(f) - b.frame_d(f)).rowwise().norm().maxCoeff();
}

TEST(SpacetimeArap, NoEditReturnsTheInput) {
  const MeshSequence seq = WavingGrid();
  const SpacetimeArapConstraints constraints = CentreHandlesBorderFixed();
  SpacetimeArapOptions options;
  options.key_frame = 4;
  options.window = 2;
  const auto editor = SpacetimeArapEditor::Create(seq, constraints, options);
  ASSERT_TRUE(editor.ok()) << editor.status().ToString();
  const auto result = editor->Solve(HandlePositions(seq, 4, constraints.handles));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->first_frame, 2);
  EXPECT_EQ(result->last_frame, 6);
  for (int f = 0; f < seq.frame_count(); ++f)
    EXPECT_LE(FrameChange(seq, result->sequence, f), 1e-6);
  EXPECT_TRUE(result->converged);
  EXPECT_LE(result->energies.back(), 1e-20);
}

TEST(SpacetimeArap, RigidEditOfEverythingMovesEveryFrameRigidly) {
  // A closed surface: on a flat one, out-of-plane rotations are barely determined by the cells
  // and ARAP converges slowly.
  const MeshSequence seq = testing::Animate(testing::Icosphere(2), 5, 0.2);
  SpacetimeArapConstraints constraints;
  for (int v = 0; v < seq.vertex_count(); ++v) constraints.handles.push_back(v);
  SpacetimeArapOptions options;
  options.key_frame = 2;
  options.window = 2;  // the whole sequence: no temporal boundary
  options.tolerance = 1e-7;
  options.max_iterations = 400;
  const auto editor = SpacetimeArapEditor::Create(seq, constraints, options);
  ASSERT_TRUE(editor.ok()) << editor.status().ToString();
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.5, Eigen::Vector3d(0.3, 0.2, 1.0).normalized()).toRotationMatrix();
  const Eigen::RowVector3d shift(0.3, -0.2, 0.1);
  const auto rigid = [&](const FramePositionsD& p) {
    FramePositionsD moved = p * rotation.transpose();
    moved.rowwise() += shift;
    return moved;
  };
  const auto result = editor->Solve(rigid(seq.frame_d(2)));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_TRUE(result->converged) << result->iterations << " iterations, last move "
                                 << result->last_move;
  for (int f = 0; f < seq.frame_count(); ++f) {
    const double error =
        (result->sequence.frame_d(f) - rigid(seq.frame_d(f))).cwiseAbs().maxCoeff();
    EXPECT_LE(error, 1e-4) << "frame " << f;
  }
}

// Moves the centre handles 0.2 up in the key frame and reports each frame's largest change.
std::vector<double> ChangesPerFrame(double alpha, int window, const MeshSequence& seq) {
  const SpacetimeArapConstraints constraints = CentreHandlesBorderFixed();
  SpacetimeArapOptions options;
  options.alpha = alpha;
  options.key_frame = 4;
  options.window = window;
  const auto editor = SpacetimeArapEditor::Create(seq, constraints, options);
  EXPECT_TRUE(editor.ok()) << editor.status().ToString();
  Eigen::MatrixXd targets = HandlePositions(seq, 4, constraints.handles);
  targets.col(2).array() += 0.2;
  const auto result = editor->Solve(targets);
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_LE(result->max_handle_error, 0.01);
  std::vector<double> changes;
  for (int f = 0; f < seq.frame_count(); ++f) {
    changes.push_back(FrameChange(seq, result->sequence, f));
  }
  return changes;
}

TEST(SpacetimeArap, LargeAlphaChangesOnlyTheKeyFrame) {
  const MeshSequence seq = WavingGrid();
  const std::vector<double> changes = ChangesPerFrame(1e6, 3, seq);
  EXPECT_GT(changes[4], 0.19);
  for (int f = 0; f < seq.frame_count(); ++f) {
    if (f != 4) {
      EXPECT_LT(changes[f], 0.02 * changes[4]) << "frame " << f;
    }
  }
}

TEST(SpacetimeArap, SmallAlphaSpreadsTheEditSmoothlyOverTheWindow) {
  const MeshSequence seq = WavingGrid();
  const std::vector<double> changes = ChangesPerFrame(1e-3, 3, seq);
  // Frames 1 and 7 are the anchored temporal boundary; 0 and 8 lie outside the window.
  EXPECT_EQ(changes[0], 0.0);
  EXPECT_EQ(changes[8], 0.0);
  EXPECT_LT(changes[1], 0.01 * changes[4]);
  EXPECT_LT(changes[7], 0.01 * changes[4]);
  EXPECT_GT(changes[3], 0.4 * changes[4]);
  EXPECT_GT(changes[5], 0.4 * changes[4]);
  // Decreasing away from the key frame on both sides.
  EXPECT_GT(changes[3], changes[2]);
  EXPECT_GT(changes[2], changes[1]);
  EXPECT_GT(changes[5], changes[6]);
  EXPECT_GT(changes[6], changes[7]);
  // And far more spread than with a large α.
  const std::vector<double> stiff = ChangesPerFrame(1e6, 3, seq);
  EXPECT_GT(changes[3], 10.0 * stiff[3]);
}

TEST(SpacetimeArap, EnergyNeverIncreases) {
  const MeshSequence seq = WavingGrid();
  const SpacetimeArapConstraints constraints = CentreHandlesBorderFixed();
  for (double alpha : {0.01, 1.0, 100.0}) {
    SpacetimeArapOptions options;
    options.alpha = alpha;
    options.key_frame = 4;
    options.window = 3;
    options.max_iterations = 30;
    const auto editor = SpacetimeArapEditor::Create(seq, constraints, options);
    ASSERT_TRUE(editor.ok());
    // A large edit: the handles turn 90° about the grid's centre and rise.
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).matrix();
    Eigen::MatrixXd targets = HandlePositions(seq, 4, constraints.handles);
    const Eigen::RowVector3d centre = targets.colwise().mean();
    targets = ((targets.rowwise() - centre) * turn.transpose()).rowwise() + centre;
    targets.col(2).array() += 0.3;
    const auto result = editor->Solve(targets);
    ASSERT_TRUE(result.ok());
    ASSERT_GE(result->energies.size(), 3u) << alpha;
    for (size_t i = 1; i < result->energies.size(); ++i) {
      EXPECT_LE(result->energies[i], result->energies[i - 1] * (1.0 + 1e-12))
          << "alpha " << alpha << " iteration " << i;
    }
    EXPECT_LT(result->energies.back(), result->energies.front());
  }
}

TEST(SpacetimeArap, BlockLdltAndSparseCholeskyAgree) {
  const MeshSequence seq = WavingGrid();
  const SpacetimeArapConstraints constraints = CentreHandlesBorderFixed();
  SpacetimeArapOptions options;
  options.key_frame = 4;
  options.window = 2;
  options.max_iterations = 5;
  Eigen::MatrixXd targets = HandlePositions(seq, 4, constraints.handles);
  targets.col(0).array() += 0.1;
  const auto cholesky = SpacetimeArapEditor::Create(seq, constraints, options);
  options.solver = SpacetimeSolverKind::kBlockLdlt;
  const auto block = SpacetimeArapEditor::Create(seq, constraints, options);
  ASSERT_TRUE(cholesky.ok() && block.ok());
  const auto a = cholesky->Solve(targets);
  const auto b = block->Solve(targets);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->iterations, b->iterations);
  for (int f = 0; f < seq.frame_count(); ++f) {
    EXPECT_LE(FrameChange(a->sequence, b->sequence, f), 1e-6);
  }
}

// Create's status: kInvalidArgument with a message that contains `message`.
void ExpectRejected(const MeshSequence& seq, const SpacetimeArapConstraints& constraints,
                    const SpacetimeArapOptions& options, const std::string& message) {
  const Status status = SpacetimeArapEditor::Create(seq, constraints, options).status();
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument) << message;
  EXPECT_NE(status.message().find(message), std::string::npos) << status.message();
}

TEST(SpacetimeArap, RejectsBadOptionsAndConstraintsNamingTheProblem) {
  const MeshSequence seq = WavingGrid(3);
  const SpacetimeArapConstraints constraints = CentreHandlesBorderFixed();
  SpacetimeArapOptions options;
  options.window = 0;
  ExpectRejected(seq, constraints, options, "spacetime-arap: window must be >= 1");
  options.window = 1;
  options.key_frame = 3;
  ExpectRejected(seq, constraints, options,
                 "spacetime-arap: key frame 3 outside the sequence's 3 frames");
  options.key_frame = 1;
  options.alpha = -1.0;
  ExpectRejected(seq, constraints, options, "spacetime-arap: alpha must be a finite value > 0");
  options.alpha = 1.0;
  options.tolerance = 0.0;
  ExpectRejected(
      seq, constraints, options,
      "spacetime-arap: tolerance and constraint weight must be > 0, max iterations >= 0");
  options.tolerance = 1e-5;
  options.key_frame = 0;
  ExpectRejected(WavingGrid(1), constraints, options,
                 "spacetime-arap: the window holds one frame; the sequence needs at least two");
  options.key_frame = 1;
  SpacetimeArapConstraints overlapping = constraints;
  overlapping.fixed.push_back(constraints.handles[0]);
  ExpectRejected(seq, overlapping, options,
                 "spacetime-arap: vertex " + std::to_string(constraints.handles[0]) +
                     " is both a handle and fixed");
  ExpectRejected(seq, {}, options, "spacetime-arap: no handle vertex to edit");
  SpacetimeArapConstraints outside = constraints;
  outside.handles.push_back(64);
  ExpectRejected(seq, outside, options, "spacetime-arap: handle 64 outside [0, 64)");
  outside = constraints;
  outside.fixed.push_back(-1);
  ExpectRejected(seq, outside, options, "spacetime-arap: fixed vertex -1 outside [0, 64)");
  options.frame_times = {0.0, 1.0};
  ExpectRejected(seq, constraints, options,
                 "spacetime-arap: frame_times holds 2 times for 3 frames");
  options.frame_times.clear();
  const auto editor = SpacetimeArapEditor::Create(seq, constraints, options);
  ASSERT_TRUE(editor.ok());
  EXPECT_EQ(editor->Solve(Eigen::MatrixXd::Zero(1, 3)).status().code(), ErrorCode::kMismatch);
}

}  // namespace
}  // namespace dmc
