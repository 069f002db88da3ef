// STED on tiny meshes, every expected value worked out by hand in the comments (the code only
// evaluates the final closed forms).
#include <gtest/gtest.h>

#include <cmath>

#include "dmc/metrics.h"
#include "metrics_test_util.h"

namespace dmc {
namespace {

using testing::Frame;
using testing::MakeSequence;
using testing::RelativeTolerance;
using testing::Translated;

// Two triangles (0,1,2), (0,2,3) over the 4×3 rectangle. Edges, in MeshTopology order, with
// their lengths: 01 = 4, 02 = 5 (diagonal), 03 = 3, 12 = 3, 23 = 4.
const std::vector<std::array<int32_t, 3>> kQuadTriangles = {{0, 1, 2}, {0, 2, 3}};
const Frame kRectangle = {{0, 0, 0}, {4, 0, 0}, {4, 3, 0}, {0, 3, 0}};
// Vertex 3 pulled up to (0, 6, 0): l′(03) = 6, l′(23) = |(4,3) − (0,6)| = 5, the rest unchanged.
const Frame kRectanglePulled = {{0, 0, 0}, {4, 0, 0}, {4, 3, 0}, {0, 6, 0}};

StedOptions Width(int width) {
  StedOptions options;
  options.width = width;
  return options;
}

TEST(Sted, TwoTrianglesWidthOneEveryVertexSeesEveryEdge) {
  // ed = (l − l′)/l: ed(03) = (3 − 6)/3 = −1, ed(23) = (4 − 5)/4 = −1/4, others 0.
  // w = 1: every vertex's one-ring reaches 0 or 2, and both touch all five edges, so N(v) is
  // all five edges for every v and dev is the same for all four vertices.
  //   Σl = 19, Σ l·ed = −3 − 1 = −4, avg = −4/19.
  //   Σ l·ed² = 3·1 + 4·(1/16) = 3.25, so dev² = Σ l·ed²/Σl − avg² = 3.25/19 − 16/361
  //   = (61.75 − 16)/361 = 45.75/361.
  // F = 1: STED_s = dev, STED_t = 0, STED = STED_s.
  const MeshSequence a = MakeSequence(kQuadTriangles, {kRectangle});
  const MeshSequence b = MakeSequence(kQuadTriangles, {kRectanglePulled});
  const auto result = Sted(a, b);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const double expected = std::sqrt(45.75 / 361.0);
  EXPECT_NEAR(result->sted_s, expected, RelativeTolerance(expected));
  EXPECT_EQ(result->sted_t, 0.0);
  EXPECT_NEAR(result->sted, expected, RelativeTolerance(expected));
}

TEST(Sted, TwoTrianglesWidthZeroUsesIncidentEdgesOnly) {
  // w = 0: N(v) = edges incident to v.
  //  v0: 01 (l 4, ed 0), 02 (5, 0), 03 (3, −1): Σl = 12, avg = −3/12 = −1/4,
  //      dev² = [9·(1/4)² + 3·(3/4)²]/12 = (9/16 + 27/16)/12 = 3/16.
  //  v1: 01, 12, both ed 0: dev = 0.
  //  v2: 02 (5, 0), 12 (3, 0), 23 (4, −1/4): Σl = 12, avg = −1/12,
  //      dev² = [8·(1/12)² + 4·(−1/4 + 1/12)²]/12 = (8/144 + 16/144)/12 = 1/72.
  //  v3: 03 (3, −1), 23 (4, −1/4): Σl = 7, avg = −4/7,
  //      dev² = [3·(3/7)² + 4·(9/28)²]/7 = (108/196 + 81/196)/7 = 27/196.
  const MeshSequence a = MakeSequence(kQuadTriangles, {kRectangle});
  const MeshSequence b = MakeSequence(kQuadTriangles, {kRectanglePulled});
  const auto result = Sted(a, b, Width(0));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const double expected =
      (std::sqrt(3.0) / 4.0 + 0.0 + 1.0 / std::sqrt(72.0) + std::sqrt(27.0) / 14.0) / 4.0;
  EXPECT_NEAR(result->sted_s, expected, RelativeTolerance(expected));
}

TEST(Sted, OriginalDefinesTheLengthsSoStedIsNotSymmetric) {
  // Swapped: the pulled rectangle is now the original. Lengths 01 = 4, 02 = 5, 03 = 6, 12 = 3,
  // 23 = 5; the distorted has 03 = 3, 23 = 4, so ed(03) = (6 − 3)/6 = 1/2, ed(23) = 1/5. w = 0:
  //  v0: 01 (4, 0), 02 (5, 0), 03 (6, 1/2): Σl = 15, avg = 3/15 = 1/5,
  //      dev² = [9·(1/5)² + 6·(3/10)²]/15 = (0.36 + 0.54)/15 = 0.06.
  //  v1: 0.
  //  v2: 02 (5, 0), 12 (3, 0), 23 (5, 1/5): Σl = 13, avg = 1/13,
  //      dev² = [8·(1/13)² + 5·(1.6/13)²]/13 = (8 + 12.8)/169/13 = 20.8/2197.
  //  v3: 03 (6, 1/2), 23 (5, 1/5): Σl = 11, avg = 4/11,
  //      dev² = [6·(1.5/11)² + 5·(1.8/11)²]/11 = (13.5 + 16.2)/1331 = 29.7/1331.
  const MeshSequence a = MakeSequence(kQuadTriangles, {kRectangle});
  const MeshSequence b = MakeSequence(kQuadTriangles, {kRectanglePulled});
  const auto forward = Sted(a, b, Width(0));
  const auto backward = Sted(b, a, Width(0));
  ASSERT_TRUE(forward.ok() && backward.ok());
  const double expected_backward =
      (std::sqrt(0.06) + 0.0 + std::sqrt(20.8 / 2197.0) + std::sqrt(29.7 / 1331.0)) / 4.0;
  EXPECT_NEAR(backward->sted_s, expected_backward, RelativeTolerance(expected_backward));
  // 0.2305 forward against 0.1229 backward.
  EXPECT_GT(forward->sted_s - backward->sted_s, 0.1);
}

TEST(Sted, ZeroLengthEdgeInOriginalZeroesEveryNeighbourhoodHoldingIt) {
  // Vertex 3 sits on vertex 0 in the original: l(03) = 0. Lengths 01 = 4, 02 = 5, 03 = 0,
  // 12 = 3, 23 = 5. The distorted moves vertex 1 to (8, 0, 0): l′(01) = 8,
  // l′(12) = |(4,3) − (8,0)| = 5, so ed(01) = −1, ed(12) = (3 − 5)/3 = −2/3, others 0.
  // w = 0: v0 and v3 hold edge 03, so avg = NaN and they contribute 0 (still counted in V·F).
  //  v1: 01 (4, −1), 12 (3, −2/3): Σl = 7, avg = −6/7,
  //      dev² = [4·(1/7)² + 3·(4/21)²]/7 = (36/441 + 48/441)/7 = 12/441.
  //  v2: 02 (5, 0), 12 (3, −2/3), 23 (5, 0): Σl = 13, avg = −2/13,
  //      dev² = [10·(2/13)² + 3·(20/39)²]/13 = (120/507 + 400/507)/13 = 40/507.
  // w = 1: every one-ring contains vertex 0 or 3, so every N(v) holds edge 03: STED_s = 0.
  const Frame collapsed = {{0, 0, 0}, {4, 0, 0}, {4, 3, 0}, {0, 0, 0}};
  const Frame stretched = {{0, 0, 0}, {8, 0, 0}, {4, 3, 0}, {0, 0, 0}};
  const MeshSequence a = MakeSequence(kQuadTriangles, {collapsed});
  const MeshSequence b = MakeSequence(kQuadTriangles, {stretched});
  const auto narrow = Sted(a, b, Width(0));
  ASSERT_TRUE(narrow.ok()) << narrow.status().ToString();
  const double expected = (std::sqrt(12.0) / 21.0 + std::sqrt(40.0 / 507.0)) / 4.0;
  EXPECT_NEAR(narrow->sted_s, expected, RelativeTolerance(expected));
  const auto wide = Sted(a, b, Width(1));
  ASSERT_TRUE(wide.ok());
  EXPECT_EQ(wide->sted_s, 0.0);
  EXPECT_FALSE(std::isnan(wide->sted));
}

TEST(Sted, ZeroLengthEdgeInDistortedOnlyIsAnOrdinaryDifference) {
  // The distorted collapses vertex 3 onto vertex 0: l′(03) = 0, so ed(03) = (3 − 0)/3 = 1, and
  // l′(23) = 5, ed(23) = −1/4. w = 0:
  //  v0: 01 (4, 0), 02 (5, 0), 03 (3, 1): Σl = 12, avg = 1/4, dev² = (9/16 + 27/16)/12 = 3/16.
  //  v1: 0.   v2: as in the width-zero test, 1/72.
  //  v3: 03 (3, 1), 23 (4, −1/4): Σl = 7, avg = 2/7,
  //      dev² = [3·(5/7)² + 4·(15/28)²]/7 = (300/196 + 225/196)/7 = 75/196.
  const Frame collapsed = {{0, 0, 0}, {4, 0, 0}, {4, 3, 0}, {0, 0, 0}};
  const MeshSequence a = MakeSequence(kQuadTriangles, {kRectangle});
  const MeshSequence b = MakeSequence(kQuadTriangles, {collapsed});
  const auto result = Sted(a, b, Width(0));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const double expected =
      (std::sqrt(3.0) / 4.0 + 1.0 / std::sqrt(72.0) + std::sqrt(75.0) / 14.0) / 4.0;
  EXPECT_NEAR(result->sted_s, expected, RelativeTolerance(expected));
}

// The temporal fixture: a 30-40-50 right triangle (frame-0 diameter D = 50) translated rigidly,
// so every edge keeps its length (STED_s = 0) and every vertex has the same te. With dt = 0.3
// the displacements 0, 8, 20, 36 give |d|/D = 0, 0.16, 0.4, 0.72 and
// te = sqrt((|d|/D)² + 0.09) = 0.3, 0.34, 0.5, 0.78 exactly.
const std::vector<std::array<int32_t, 3>> kTriangle = {{0, 1, 2}};
const Frame kRightTriangle = {{0, 0, 0}, {40, 0, 0}, {0, 30, 0}};

// Original: frame steps of length 20, 0, 36, so te(1..3) = 0.5, 0.3, 0.78.
MeshSequence TemporalOriginal() {
  return MakeSequence(
      kTriangle, {kRightTriangle, Translated(kRightTriangle, {20, 0, 0}),
                  Translated(kRightTriangle, {20, 0, 0}), Translated(kRightTriangle, {20, 36, 0})});
}
// Distorted: frame steps of length 8, 20, 36, so te′(1..3) = 0.34, 0.5, 0.78.
MeshSequence TemporalDistorted() {
  return MakeSequence(
      kTriangle, {kRightTriangle, Translated(kRightTriangle, {8, 0, 0}),
                  Translated(kRightTriangle, {8, 20, 0}), Translated(kRightTriangle, {8, 20, 36})});
}

StedOptions Temporal(int window) {
  StedOptions options;
  options.dt = 0.3;
  options.window = window;
  options.c = 1.0;  // STED = sqrt(0 + STED_t²) = STED_t
  return options;
}

TEST(Sted, TemporalWindowClippedAtTheEnd) {
  // s = 1, F = 4: windows [max(1, f), min(3, f+1)] = [1,2], [2,3], [3,3] (clipped at F−1).
  //  s̄ = (0.5 + 0.3)/2 = 0.4, (0.3 + 0.78)/2 = 0.54, 0.78.
  //  terms |te′ − te|/s̄ = 0.16/0.4, 0.2/0.54, 0/0.78; STED_t = their sum / (V·(F−1)) with V
  //  identical vertices, i.e. their mean over the 3 frames.
  // (A symmetric window [f−1, f+1] would give s̄(2) = 1.58/3 instead and a different value.)
  const auto result = Sted(TemporalOriginal(), TemporalDistorted(), Temporal(1));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const double expected = (0.16 / 0.4 + 0.2 / 0.54 + 0.0) / 3.0;
  EXPECT_EQ(result->sted_s, 0.0);
  EXPECT_NEAR(result->sted_t, expected, RelativeTolerance(expected));
  EXPECT_NEAR(result->sted, expected, RelativeTolerance(expected));
}

TEST(Sted, TemporalWindowClippedAtBothEnds) {
  // s = 2: windows [max(1, f−1), min(3, f+2)] = [1,3] (f−1 = 0 clipped to 1), [1,3], [2,3].
  //  s̄ = 1.58/3, 1.58/3, 0.54; terms 0.16·3/1.58, 0.2·3/1.58, 0.
  //  STED_t = (0.48 + 0.6)/1.58/3 = 0.36/1.58.
  // s = 5 (the default): every window is [1,3] and the last term is 0 again: same value.
  const double expected = 0.36 / 1.58;
  for (int window : {2, 5}) {
    const auto result = Sted(TemporalOriginal(), TemporalDistorted(), Temporal(window));
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    EXPECT_NEAR(result->sted_t, expected, RelativeTolerance(expected)) << "s = " << window;
  }
}

TEST(Sted, OriginalDefinesTheLocalSpeed) {
  // Swapped, s = 1: te of the (new) original is 0.34, 0.5, 0.78 and te′ is 0.5, 0.3, 0.78.
  //  s̄ = (0.34 + 0.5)/2 = 0.42, (0.5 + 0.78)/2 = 0.64, 0.78; terms 0.16/0.42, 0.2/0.64, 0.
  const auto result = Sted(TemporalDistorted(), TemporalOriginal(), Temporal(1));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const double expected = (0.16 / 0.42 + 0.2 / 0.64) / 3.0;
  EXPECT_NEAR(result->sted_t, expected, RelativeTolerance(expected));
}

TEST(Sted, DiameterComesFromFrameZeroOfTheOriginal) {
  // Original: the right triangle (D = 50), then the same triangle three times larger (diameter
  // 150). Distorted: frame 0 twice as large (diameter 100), frame 1 as the original's.
  // F = 2, so the only window is [1, 1] and s̄ = te. With D = 50 and dt = 0.3:
  //   v0 stays at the origin in both: te = te′ = 0.3, term 0.
  //   v1: original (40,0,0) → (120,0,0): |d|/D = 1.6, te = sqrt(2.56 + 0.09) = sqrt(2.65);
  //       distorted (80,0,0) → (120,0,0): 0.8, te′ = sqrt(0.64 + 0.09) = sqrt(0.73).
  //   v2: original (0,30,0) → (0,90,0): 1.2, te = sqrt(1.53);
  //       distorted (0,60,0) → (0,90,0): 0.6, te′ = sqrt(0.45).
  // Taking D from the distorted (100) or from all frames (150) would give other values.
  Frame large = kRightTriangle, larger = kRightTriangle;
  for (auto& p : large) p = {2 * p[0], 2 * p[1], 2 * p[2]};
  for (auto& p : larger) p = {3 * p[0], 3 * p[1], 3 * p[2]};
  const MeshSequence a = MakeSequence(kTriangle, {kRightTriangle, larger});
  const MeshSequence b = MakeSequence(kTriangle, {large, larger});
  const auto result = Sted(a, b, Temporal(5));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const double term1 = (std::sqrt(2.65) - std::sqrt(0.73)) / std::sqrt(2.65);
  const double term2 = (std::sqrt(1.53) - std::sqrt(0.45)) / std::sqrt(1.53);
  const double expected = (0.0 + term1 + term2) / 3.0;
  EXPECT_NEAR(result->sted_t, expected, RelativeTolerance(expected));
}

TEST(Sted, SingleFrameHasNoTemporalPart) {
  const MeshSequence a = MakeSequence(kTriangle, {kRightTriangle});
  const MeshSequence b = MakeSequence(kTriangle, {Translated(kRightTriangle, {5, 5, 5})});
  const auto result = Sted(a, b);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->sted_t, 0.0);
  EXPECT_EQ(result->sted_s, 0.0);  // a translation keeps every length
  EXPECT_EQ(result->sted, 0.0);
}

// The tetrahedron of every term: T = (0,0,0), (4,0,0), (0,4,0), (0,0,4) translated by (2f, 0, 0)
// in frame f = 0, 1, 2; the distorted differs only in frame 0, where vertex 0 sits at (0, 0, −1).
MeshSequence MovingTetrahedron(bool distort_first_frame) {
  const std::vector<std::array<int32_t, 3>> faces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const Frame tetrahedron = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0, 0, 4}};
  Frame first = tetrahedron;
  if (distort_first_frame) first[0] = {0, 0, -1};
  return MakeSequence(
      faces, {first, Translated(tetrahedron, {2, 0, 0}), Translated(tetrahedron, {4, 0, 0})});
}

TEST(Sted, TetrahedronThreeFramesEveryTermWithDefaults) {
  const MeshSequence a = MovingTetrahedron(false);
  const MeshSequence b = MovingTetrahedron(true);
  const auto result = Sted(a, b);  // w = 1, dt = 0.0003, s = 5, c = 9.144e-5
  ASSERT_TRUE(result.ok()) << result.status().ToString();

  // Spatial. Frames 1 and 2 are exact: dev = 0. In frame 0 each one-ring is the other three
  // vertices, so N(v) is all 6 edges for every v. Edges 01, 02, 03, 12, 13, 23 have
  // l = 4, 4, 4, 4√2, 4√2, 4√2 and, with vertex 0 at (0,0,−1), l′ = √17, √17, 5, 4√2, 4√2, 4√2:
  // ed = (4−√17)/4, (4−√17)/4, −1/4, 0, 0, 0.
  //   Σl = 12 + 12√2, Σ l·ed = 2(4 − √17) − 1 = 7 − 2√17, avg = (7 − 2√17)/(12 + 12√2),
  //   dev² = [8·((4−√17)/4 − avg)² + 4·(−1/4 − avg)² + 12√2·avg²] / (12 + 12√2).
  // STED_s = 4·dev / (V·F) = dev / 3.
  const double root2 = std::sqrt(2.0), root17 = std::sqrt(17.0);
  const double length_sum = 12.0 + 12.0 * root2;
  const double avg = (7.0 - 2.0 * root17) / length_sum;
  const double ed_side = (4.0 - root17) / 4.0;
  const double dev = std::sqrt((8.0 * (ed_side - avg) * (ed_side - avg) +
                                4.0 * (-0.25 - avg) * (-0.25 - avg) + 12.0 * root2 * avg * avg) /
                               length_sum);
  const double expected_s = dev / 3.0;
  EXPECT_NEAR(result->sted_s, expected_s, RelativeTolerance(expected_s));

  // Temporal. D = 4√2 (frame 0 of the original). Every vertex of A moves by 2 per frame:
  // te = sqrt((2/(4√2))² + dt²) = sqrt(1/8 + dt²) =: T everywhere, so s̄ = T. In A′ only vertex
  // 0 of frame 1 differs: it moves from (0,0,−1) to (2,0,0), |d|² = 5, te′ = sqrt(5/32 + dt²).
  // STED_t = |sqrt(5/32 + dt²) − T| / T / (V·(F−1)) = ... / 8.
  const double dt = 0.0003;
  const double te = std::sqrt(0.125 + dt * dt);
  const double te_moved = std::sqrt(5.0 / 32.0 + dt * dt);
  const double expected_t = (te_moved - te) / te / 8.0;
  EXPECT_NEAR(result->sted_t, expected_t, RelativeTolerance(expected_t));

  const double c = 9.144e-5;
  const double expected = std::sqrt(expected_s * expected_s + c * c * expected_t * expected_t);
  EXPECT_NEAR(result->sted, expected, RelativeTolerance(expected));
}

TEST(Sted, IdenticalSequencesGiveZero) {
  const MeshSequence a = MovingTetrahedron(true);
  const auto result = Sted(a, a);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->sted, 0.0);
  EXPECT_EQ(result->sted_s, 0.0);
  EXPECT_EQ(result->sted_t, 0.0);
}

TEST(Sted, DtZeroRestingVertexWithoutDifferenceContributesNothing) {
  // dt = 0 and nothing moves in either sequence: te = te′ = 0 and s̄ = 0, every term is 0/0,
  // documented as contributing 0.
  const MeshSequence still =
      MakeSequence(kTriangle, {kRightTriangle, kRightTriangle, kRightTriangle});
  StedOptions options;
  options.dt = 0.0;
  const auto result = Sted(still, still, options);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->sted_t, 0.0);
  // A static original against a moving distorted: x/0 is infinite, as documented.
  const MeshSequence moving = MakeSequence(
      kTriangle, {kRightTriangle, Translated(kRightTriangle, {1, 0, 0}), kRightTriangle});
  const auto infinite = Sted(still, moving, options);
  ASSERT_TRUE(infinite.ok());
  EXPECT_TRUE(std::isinf(infinite->sted_t));
}

}  // namespace
}  // namespace dmc
