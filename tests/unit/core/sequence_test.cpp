#include "dmc/sequence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test_support.h"

namespace dmc {
namespace {

TEST(MeshSequence, StoresFramesContiguously) {
  MeshSequence seq = testing::Tetrahedron(3);
  EXPECT_EQ(seq.vertex_count(), 4);
  EXPECT_EQ(seq.frame_count(), 3);
  EXPECT_EQ(seq.position_value_count(), 3u * 4u * 3u);
  EXPECT_FLOAT_EQ(seq.data()[(2 * 4 + 1) * 3 + 0], 1.2f);  // frame 2, vertex 1, x
  EXPECT_TRUE(ValidateSequence(seq).ok());
}

TEST(MeshSequence, AppendFrameRejectsVertexCountChange) {
  MeshSequence seq = testing::Tetrahedron(1);
  FramePositions five(5, 3);
  five.setZero();
  const Status status = seq.AppendFrame(five);
  EXPECT_EQ(status.code(), ErrorCode::kMismatch);
  EXPECT_EQ(status.message(), "frame 1 has 5 vertices, expected 4");
  EXPECT_EQ(seq.frame_count(), 1);
}

TEST(Validate, RejectsEmptyInput) {
  EXPECT_EQ(ValidateSequence(MeshSequence()).message(), "the sequence has no vertices");
  MeshSequence no_frames(4, testing::Tetrahedron().triangles(), 0);
  EXPECT_EQ(ValidateSequence(no_frames).message(), "the sequence has no frames");
  MeshSequence no_triangles(4, Triangles(0, 3), 1);
  EXPECT_EQ(ValidateSequence(no_triangles).message(), "the sequence has no triangles");
}

TEST(Validate, NamesOutOfRangeIndex) {
  MeshSequence seq = testing::Tetrahedron(1);
  seq.mutable_triangles()(2, 1) = 7;
  const Status status = ValidateSequence(seq);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(status.message(), "triangle 2 refers to vertex 7, outside [0, 4)");
  seq.mutable_triangles()(2, 1) = -1;
  EXPECT_EQ(ValidateSequence(seq).message(), "triangle 2 refers to vertex -1, outside [0, 4)");
}

TEST(Validate, NamesNonFiniteCoordinate) {
  MeshSequence seq = testing::Tetrahedron(3);
  seq.frame(2)(3, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(ValidateSequence(seq).message(), "frame 2, vertex 3: coordinate y is not finite");
  seq.frame(2)(3, 1) = 0.0f;
  seq.frame(1)(0, 2) = std::numeric_limits<float>::infinity();
  EXPECT_EQ(ValidateSequence(seq).message(), "frame 1, vertex 0: coordinate z is not finite");
}

TEST(Validate, DegenerateTrianglesAreWarningsNotErrors) {
  MeshSequence seq = testing::Tetrahedron(1);
  seq.mutable_triangles()(0, 1) = 0;  // repeated index
  ValidationReport report;
  EXPECT_TRUE(ValidateSequence(seq, &report).ok());
  EXPECT_EQ(report.degenerate_triangles, 1);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("first is triangle 0"), std::string::npos);
}

TEST(CheckComparable, NamesTheDifference) {
  const MeshSequence a = testing::Tetrahedron(3);
  EXPECT_TRUE(CheckComparable(a, a).ok());
  EXPECT_EQ(CheckComparable(a, testing::Tetrahedron(2)).message(), "frame counts differ: 3 vs 2");
  MeshSequence b = a;
  b.mutable_triangles()(3, 0) = 1;
  EXPECT_EQ(CheckComparable(a, b).message(),
            "triangle lists differ: oriented triangle (0, 3, 2) has no counterpart");
  MeshSequence reordered = a;  // same oriented triangles, other order and rotations
  reordered.mutable_triangles().row(0) = a.triangles().row(3);
  reordered.mutable_triangles().row(3) << a.triangles()(0, 1), a.triangles()(0, 2),
      a.triangles()(0, 0);
  EXPECT_TRUE(CheckComparable(a, reordered).ok());
  MeshSequence flipped = a;  // orientation differs
  std::swap(flipped.mutable_triangles()(1, 0), flipped.mutable_triangles()(1, 1));
  EXPECT_EQ(CheckComparable(a, flipped).code(), ErrorCode::kMismatch);
  EXPECT_EQ(CheckComparable(a, testing::PlanarGrid(3, 3)).code(), ErrorCode::kMismatch);
  // A degenerate triangle with a repeated index, rotated (as meshopt's triangle codec may).
  MeshSequence repeated = a, rotated = a;
  repeated.mutable_triangles().row(2) << 2, 3, 2;
  rotated.mutable_triangles().row(2) << 2, 2, 3;
  EXPECT_TRUE(CheckComparable(repeated, rotated).ok());
}

TEST(BoundingBox, CoversAllFrames) {
  const BoundingBox box = ComputeBoundingBox(testing::Tetrahedron(3));
  EXPECT_NEAR(box.min.x(), 0.0, 1e-7);
  EXPECT_NEAR(box.max.x(), 1.2, 1e-6);
  EXPECT_NEAR(box.diagonal(), std::sqrt(1.2 * 1.2 + 1 + 1), 1e-6);
}

}  // namespace
}  // namespace dmc
