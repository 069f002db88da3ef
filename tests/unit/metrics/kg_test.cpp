// KG, the vertex-error statistics, MeasureDistortion and DistortionMeter, with hand-computed
// values, plus the error paths.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "dmc/metrics.h"
#include "metrics_test_util.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::Frame;
using testing::MakeSequence;
using testing::RelativeTolerance;
using testing::Translated;

// T = (0,0,0), (4,0,0), (0,4,0), (0,0,4) translated by (2f, 0, 0) in frames f = 0, 1, 2; the
// distorted differs only in frame 0, where vertex 0 sits at (0, 0, −1) (error 1).
MeshSequence MovingTetrahedron(bool distort_first_frame) {
  const std::vector<std::array<int32_t, 3>> faces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const Frame tetrahedron = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0, 0, 4}};
  Frame first = tetrahedron;
  if (distort_first_frame) first[0] = {0, 0, -1};
  return MakeSequence(
      faces, {first, Translated(tetrahedron, {2, 0, 0}), Translated(tetrahedron, {4, 0, 0})});
}

TEST(Kg, TetrahedronByHand) {
  // Centroid of each frame: (1 + 2f, 1, 1). Squared deviations: vertex 0 → 3, the others
  // → 9 + 1 + 1 = 11, so 36 per frame and ‖A − E(A)‖² = 108. ‖A − A′‖² = 1.
  // KG = 100 · 1 / sqrt(108).
  const auto kg = KgError(MovingTetrahedron(false), MovingTetrahedron(true));
  ASSERT_TRUE(kg.ok()) << kg.status().ToString();
  const double expected = 100.0 / std::sqrt(108.0);
  EXPECT_NEAR(*kg, expected, RelativeTolerance(expected));
}

TEST(Kg, IdenticalSequencesGiveZero) {
  const MeshSequence a = MovingTetrahedron(true);
  const auto kg = KgError(a, a);
  ASSERT_TRUE(kg.ok());
  EXPECT_EQ(*kg, 0.0);
}

TEST(Kg, OriginalDefinesTheNormalisation) {
  // Swapping the arguments keeps ‖A − A′‖ but normalises by the other sequence's spread.
  // Distorted = the original scaled by 2 about the origin: ‖A′ − E(A′)‖ = 2·‖A − E(A)‖, so
  // KG(A′, A) = KG(A, A′) / 2.
  const MeshSequence a = MovingTetrahedron(false);
  MeshSequence doubled = a;
  for (int f = 0; f < doubled.frame_count(); ++f) doubled.frame(f) *= 2.0f;
  const auto forward = KgError(a, doubled);
  const auto backward = KgError(doubled, a);
  ASSERT_TRUE(forward.ok() && backward.ok());
  EXPECT_NEAR(*backward, *forward / 2.0, RelativeTolerance(*forward));
}

TEST(MeasureDistortion, TetrahedronEveryField) {
  const auto report = MeasureDistortion(MovingTetrahedron(false), MovingTetrahedron(true));
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_NEAR(report->kg, 100.0 / std::sqrt(108.0), 1e-12);
  // Bounding box of A over all frames: x ∈ [0, 8], y, z ∈ [0, 4]: diagonal sqrt(96).
  // RMSE over the 12 vertex positions: sqrt(1/12).
  EXPECT_NEAR(report->rmse_rel, std::sqrt(1.0 / 12.0) / std::sqrt(96.0), 1e-15);
  EXPECT_EQ(report->max_error, 1.0);
  EXPECT_EQ(report->frames, 3);
  EXPECT_EQ(report->vertices, 4);
  const auto sted = Sted(MovingTetrahedron(false), MovingTetrahedron(true));
  ASSERT_TRUE(sted.ok());
  EXPECT_EQ(report->sted, sted->sted);
  EXPECT_EQ(report->sted_s, sted->sted_s);
  EXPECT_EQ(report->sted_t, sted->sted_t);
}

TEST(DistortionMeter, ReusedMeterMatchesOneShotCalls) {
  const MeshSequence original = testing::PlanarGrid(6, 4);
  MeshSequence first = original, second = original;
  for (int f = 0; f < original.frame_count(); ++f) {
    first.frame(f).col(2).array() += 0.01f * static_cast<float>(f + 1);
    second.frame(f)(7, 0) += 0.05f;
  }
  StedOptions options;
  options.width = 2;
  const auto meter = DistortionMeter::Create(original, options);
  ASSERT_TRUE(meter.ok()) << meter.status().ToString();
  EXPECT_NEAR(meter->diameter(), std::sqrt(2.0), 1e-7);  // the unit square's diagonal
  EXPECT_EQ(meter->options().width, 2);
  const DistortionMeter copy = *meter;
  for (const MeshSequence* distorted : {&first, &second}) {
    const auto reused = copy.Measure(*distorted);
    const auto direct = MeasureDistortion(original, *distorted, options);
    ASSERT_TRUE(reused.ok() && direct.ok());
    EXPECT_EQ(reused->kg, direct->kg);
    EXPECT_EQ(reused->sted, direct->sted);
    EXPECT_EQ(reused->rmse_rel, direct->rmse_rel);
    EXPECT_EQ(reused->max_error, direct->max_error);
    EXPECT_GT(reused->sted, 0.0);
  }
}

TEST(MetricsErrors, MismatchedInputsAreRejected) {
  const MeshSequence a = MovingTetrahedron(false);
  // Frame count.
  MeshSequence fewer_frames = a;
  fewer_frames.ResizeFrames(2);
  // Vertex count: the same triangles over one extra (isolated) vertex.
  MeshSequence more_vertices(5, a.triangles(), 3);
  // Triangle list: same counts, one face reoriented.
  MeshSequence other_faces = a;
  other_faces.mutable_triangles().row(0) << 0, 1, 2;
  for (const MeshSequence* b : {&fewer_frames, &more_vertices, &other_faces}) {
    EXPECT_EQ(KgError(a, *b).status().code(), ErrorCode::kMismatch);
    EXPECT_EQ(Sted(a, *b).status().code(), ErrorCode::kMismatch);
    EXPECT_EQ(MeasureDistortion(a, *b).status().code(), ErrorCode::kMismatch);
    const auto meter = DistortionMeter::Create(a);
    ASSERT_TRUE(meter.ok());
    EXPECT_EQ(meter->Measure(*b).status().code(), ErrorCode::kMismatch);
  }
}

TEST(MetricsErrors, BadOptionsAreRejected) {
  const MeshSequence a = MovingTetrahedron(false);
  StedOptions negative_width, zero_window, negative_dt, nan_dt, negative_c;
  negative_width.width = -1;
  zero_window.window = 0;
  negative_dt.dt = -1e-3;
  nan_dt.dt = std::numeric_limits<double>::quiet_NaN();
  negative_c.c = -1.0;
  for (const StedOptions& options :
       {negative_width, zero_window, negative_dt, nan_dt, negative_c}) {
    EXPECT_EQ(ValidateStedOptions(options).code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(Sted(a, a, options).status().code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(MeasureDistortion(a, a, options).status().code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(DistortionMeter::Create(a, options).status().code(), ErrorCode::kInvalidArgument);
  }
  StedOptions edge_values;
  edge_values.width = 0;
  edge_values.window = 1;
  edge_values.dt = 0.0;
  edge_values.c = 0.0;
  EXPECT_TRUE(ValidateStedOptions(edge_values).ok());
}

TEST(MetricsErrors, InvalidOrDegenerateSequencesAreRejected) {
  const MeshSequence a = MovingTetrahedron(false);
  MeshSequence not_finite = a;
  not_finite.frame(1)(2, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(KgError(a, not_finite).status().code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(Sted(a, not_finite).status().code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(Sted(not_finite, a).status().code(), ErrorCode::kInvalidSequence);
  // Every vertex at one point: KG's denominator and D are 0, neither metric is defined.
  MeshSequence collapsed = a;
  for (int f = 0; f < collapsed.frame_count(); ++f) collapsed.frame(f).setConstant(1.0f);
  EXPECT_EQ(KgError(collapsed, a).status().code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(Sted(collapsed, a).status().code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(MeasureDistortion(collapsed, a).status().code(), ErrorCode::kInvalidSequence);
  // A single frame needs no D: a collapsed single frame is still measurable by STED.
  MeshSequence single = collapsed;
  single.ResizeFrames(1);
  MeshSequence single_other = a;
  single_other.ResizeFrames(1);
  EXPECT_TRUE(Sted(single, single_other).ok());
  // No frames at all.
  MeshSequence empty = a;
  empty.ResizeFrames(0);
  EXPECT_EQ(Sted(empty, empty).status().code(), ErrorCode::kInvalidSequence);
}

}  // namespace
}  // namespace dmc
