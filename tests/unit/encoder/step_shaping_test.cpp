// Format 1.2 step shaping (spec §8.5.1): the step factors, the anchor regions (nearest anchor in
// hops, ties to the first listed, whatever the ring order), the exponents in the anchor chunk,
// residuals coded with per-vertex steps, the encoder's choice of exponents and the option.
#include "encoder/step_shaping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/encoder_options.h"
#include "dmc/metrics.h"
#include "dmc/topology.h"
#include "encoder/range_encoder.h"
#include "encoder/syntax_writer.h"
#include "test_support.h"

namespace dmc {
namespace {

MeshTopology GridTopology(int n) {
  const MeshSequence grid = testing::PlanarGrid(n);
  return BuildTopology(grid.triangles(), grid.vertex_count());
}

// Hop distances from `source` (breadth-first search), -1 where unreachable.
std::vector<int> HopDistances(const MeshTopology& topology, int source) {
  std::vector<int> distance(topology.vertex_count, -1);
  std::vector<int> queue = {source};
  distance[source] = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head];
    for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
      const int u = topology.ring_neighbors[k];
      if (distance[u] < 0) {
        distance[u] = distance[v] + 1;
        queue.push_back(u);
      }
    }
  }
  return distance;
}

// The rule of §8.5.1 by brute force: the anchor at the fewest hops, the first listed on ties.
std::vector<int32_t> NearestAnchors(const MeshTopology& topology,
                                    const std::vector<int32_t>& anchors) {
  std::vector<int32_t> owner(topology.vertex_count, -1);
  std::vector<int> best(topology.vertex_count, std::numeric_limits<int>::max());
  for (size_t a = 0; a < anchors.size(); ++a) {
    const std::vector<int> distance = HopDistances(topology, anchors[a]);
    for (int v = 0; v < topology.vertex_count; ++v) {
      if (distance[v] >= 0 && distance[v] < best[v]) {
        best[v] = distance[v];
        owner[v] = static_cast<int32_t>(a);
      }
    }
  }
  return owner;
}

TEST(StepFactor, IsTwoToTheQuarterExponent) {
  for (int e = -format::kMaxStepExponent; e <= format::kMaxStepExponent; ++e) {
    EXPECT_DOUBLE_EQ(format::StepFactor(e), std::exp2(e / 4.0)) << e;
    if (e % 4 == 0) {
      EXPECT_EQ(format::StepFactor(e), std::ldexp(1.0, e / 4)) << e;
    }
    if (e + 4 <= format::kMaxStepExponent) {
      // Exactly a power of two apart: the table is scaled, never recomputed.
      EXPECT_EQ(format::StepFactor(e + 4), 2.0 * format::StepFactor(e)) << e;
    }
    if (e > -format::kMaxStepExponent) {
      EXPECT_LT(format::StepFactor(e - 1), format::StepFactor(e)) << e;
    }
  }
}

TEST(AnchorRegions, AreTheNearestAnchorWithTiesToTheFirstListed) {
  const MeshTopology topology = GridTopology(13);
  // Symmetric anchors on a grid make many vertices equidistant from two or more of them.
  for (const std::vector<int32_t>& anchors :
       {std::vector<int32_t>{0}, std::vector<int32_t>{0, 168}, std::vector<int32_t>{6, 78, 162},
        std::vector<int32_t>{0, 12, 84, 156, 168}, std::vector<int32_t>{40, 41, 42, 43}}) {
    EXPECT_EQ(format::AnchorRegions(topology, anchors), NearestAnchors(topology, anchors));
  }
}

TEST(AnchorRegions, DoNotDependOnTheRingOrder) {
  const MeshTopology topology = GridTopology(13);
  const std::vector<int32_t> anchors = {0, 12, 84, 156, 168};
  const std::vector<int32_t> expected = format::AnchorRegions(topology, anchors);
  std::mt19937 random(7);
  for (int trial = 0; trial < 5; ++trial) {
    MeshTopology shuffled = topology;
    for (int v = 0; v < shuffled.vertex_count; ++v) {
      std::shuffle(shuffled.ring_neighbors.begin() + shuffled.ring_offsets[v],
                   shuffled.ring_neighbors.begin() + shuffled.ring_offsets[v + 1], random);
    }
    EXPECT_EQ(format::AnchorRegions(shuffled, anchors), expected) << "trial " << trial;
  }
}

TEST(AnchorRegions, LeaveAComponentWithoutAnAnchorUnowned) {
  // Two triangles that share no vertex; the only anchor is in the first.
  Triangles triangles(2, 3);
  triangles << 0, 1, 2, 3, 4, 5;
  const MeshTopology topology = BuildTopology(triangles, 6);
  EXPECT_EQ(format::AnchorRegions(topology, std::vector<int32_t>{1}),
            (std::vector<int32_t>{0, 0, 0, -1, -1, -1}));
  const std::vector<int8_t> exponents = {-4};
  EXPECT_EQ(format::VertexStepFactors(topology, std::vector<int32_t>{1}, exponents),
            (std::vector<double>{0.5, 0.5, 0.5, 1.0, 1.0, 1.0}));
}

TEST(VertexStepFactors, AreEmptyWhenEveryExponentIsZero) {
  const MeshTopology topology = GridTopology(5);
  const std::vector<int32_t> anchors = {0, 24};
  EXPECT_TRUE(format::VertexStepFactors(topology, anchors, std::vector<int8_t>{0, 0}).empty());
  EXPECT_TRUE(format::VertexStepFactors(topology, anchors, std::vector<int8_t>{}).empty());
  const std::vector<double> factors =
      format::VertexStepFactors(topology, anchors, std::vector<int8_t>{3, -5});
  const std::vector<int32_t> owner = format::AnchorRegions(topology, anchors);
  ASSERT_EQ(factors.size(), 25u);
  for (int v = 0; v < 25; ++v) {
    EXPECT_EQ(factors[v], format::StepFactor(owner[v] == 0 ? 3 : -5)) << v;
  }
}

format::SegmentHeader Header(int rank, double step, uint8_t minor) {
  format::SegmentHeader header;
  header.rank = static_cast<uint32_t>(rank);
  header.residual_step = step;
  header.anchor_step = step;
  header.version_minor = minor;
  return header;
}

TEST(StepShapedResiduals, RoundTripWithEachVertexsOwnStep) {
  const MeshTopology topology = GridTopology(12);
  const std::vector<int32_t> order = format::BreadthFirstOrder(topology);
  const std::vector<int32_t> anchors = {0, 77, 143};
  const std::vector<int8_t> exponents = {-6, 0, 7};
  const std::vector<double> factors = format::VertexStepFactors(topology, anchors, exponents);
  const int rank = 4;
  const double step = 0.01;
  Eigen::MatrixXd delta(topology.vertex_count, rank);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> value(-0.2, 0.2);
  for (Eigen::Index i = 0; i < delta.size(); ++i) delta.data()[i] = value(random);
  const format::SegmentHeader header = Header(rank, step, 2);
  Eigen::MatrixXd written;
  const auto payload = syntax::WriteResiduals(delta, topology, order, header, &written,
                                              /*rdo_lambda=*/0.0, factors);
  ASSERT_TRUE(payload.ok()) << payload.status().ToString();
  SegmentSyntax syntax;
  syntax.header = header;
  syntax.anchors = anchors;
  syntax.anchor_step_exponents = exponents;
  ASSERT_TRUE(syntax::ReadResiduals(*payload, topology, order, syntax).ok());
  EXPECT_EQ(syntax.delta, written);  // bit for bit: the decoder rebuilds what the encoder kept
  for (int v = 0; v < topology.vertex_count; ++v) {
    for (int k = 0; k < rank; ++k) {
      // Plain rounding: within half of the vertex's own step.
      EXPECT_LE(std::abs(delta(v, k) - written(v, k)), 0.5 * step * factors[v] * (1 + 1e-12));
    }
  }
  // Without the exponents the same payload decodes to other values: the factors are applied.
  syntax.anchor_step_exponents.clear();
  ASSERT_TRUE(syntax::ReadResiduals(*payload, topology, order, syntax).ok());
  EXPECT_NE(syntax.delta, written);
}

TEST(StepShapedAnchors, ExponentsRoundTripIn12AndAreAbsentBefore) {
  const std::vector<int32_t> anchors = {2, 9, 30};
  const std::vector<int8_t> exponents = {-16, 5, 16};
  Eigen::MatrixXd coefficients = Eigen::MatrixXd::Zero(40, 2);
  coefficients(9, 1) = 0.5;
  for (const uint8_t minor : {uint8_t{1}, uint8_t{2}}) {
    const format::SegmentHeader header = Header(2, 0.1, minor);
    Eigen::MatrixXd written;
    const std::vector<uint8_t> payload =
        syntax::WriteAnchors(anchors, coefficients, header, &written, exponents);
    SegmentSyntax syntax;
    syntax.header = header;
    syntax.header.anchor_count = 3;
    ASSERT_TRUE(syntax::ReadAnchors(payload, 40, syntax).ok()) << int{minor};
    EXPECT_EQ(syntax.anchors, anchors);
    EXPECT_EQ(syntax.anchor_values, written);
    EXPECT_EQ(syntax.anchor_step_exponents, minor >= 2 ? exponents : std::vector<int8_t>())
        << int{minor};
  }
}

TEST(StepShapedAnchors, AnExponentBeyondSixteenIsCorrupt) {
  for (const int64_t bad : {int64_t{17}, int64_t{-17}, int64_t{1} << 40}) {
    RangeEncoder encoder;
    format::AnchorContexts contexts;
    encoder.EncodeUnsigned(contexts.index_gap, 0);  // anchor 0
    encoder.EncodeSigned(contexts.step_exponent, bad);
    encoder.EncodeSigned(contexts.value[0], 0);
    const std::vector<uint8_t> payload = encoder.Finish();
    SegmentSyntax syntax;
    syntax.header = Header(1, 0.1, 2);
    syntax.header.anchor_count = 1;
    const Status status = syntax::ReadAnchors(payload, 10, syntax);
    EXPECT_EQ(status.code(), ErrorCode::kCorruptStream) << bad << ": " << status.ToString();
    EXPECT_NE(status.message().find("step exponent"), std::string::npos) << status.ToString();
  }
}

// A 17 × 17 grid whose columns are spaced 16 times closer on the left than on the right
// (spacing growing geometrically), so the mean edge length varies over the mesh.
Eigen::MatrixXd GradedGrid(int n) {
  Eigen::MatrixXd shape(n * n, 3);
  for (int v = 0; v < n * n; ++v) {
    const double u = static_cast<double>(v % n) / (n - 1);
    shape.row(v) << (std::exp2(4.0 * u) - 1.0) / 15.0, static_cast<double>(v / n) / (n - 1), 0.0;
  }
  return shape;
}

TEST(ChooseStepExponents, FollowTheEdgeLengths) {
  const int n = 17;
  const MeshTopology topology = GridTopology(n);
  const std::vector<int32_t> anchors = {8 * n, 8 * n + 8, 8 * n + 16};  // left, middle, right
  const Eigen::MatrixXd graded = GradedGrid(n);
  const std::vector<int8_t> exponents = ChooseStepExponents(graded, topology, anchors, 1.0);
  ASSERT_EQ(exponents.size(), 3u);
  EXPECT_LT(exponents[0], 0);  // short edges: a finer step
  EXPECT_GT(exponents[2], 0);  // long edges: a coarser one
  EXPECT_LT(exponents[0], exponents[1]);
  EXPECT_LT(exponents[1], exponents[2]);
  for (const int8_t e : exponents) EXPECT_LE(std::abs(e), 8);
  // Half the strength, about half the exponents.
  const std::vector<int8_t> half = ChooseStepExponents(graded, topology, anchors, 0.5);
  EXPECT_NEAR(half[0], exponents[0] / 2.0, 1.0);
  EXPECT_NEAR(half[2], exponents[2] / 2.0, 1.0);
  // Strength 0: every exponent 0.
  EXPECT_EQ(ChooseStepExponents(graded, topology, anchors, 0.0), std::vector<int8_t>(3, 0));
  // Automatic on a uniform grid (no spread of edge lengths): off.
  Eigen::MatrixXd uniform = graded;
  for (int v = 0; v < n * n; ++v) uniform(v, 0) = static_cast<double>(v % n) / (n - 1);
  EXPECT_EQ(ChooseStepExponents(uniform, topology, anchors, -1.0), std::vector<int8_t>(3, 0));
  // Automatic on the graded grid: on.
  EXPECT_NE(ChooseStepExponents(graded, topology, anchors, -1.0), std::vector<int8_t>(3, 0));
}

TEST(ChooseStepExponents, AutomaticStrengthRisesWithTheSpread) {
  EXPECT_EQ(AutomaticStepShapingStrength(0.0), 0.0);
  EXPECT_EQ(AutomaticStepShapingStrength(0.25), 0.0);
  EXPECT_NEAR(AutomaticStepShapingStrength(0.425), 0.5, 1e-12);
  EXPECT_EQ(AutomaticStepShapingStrength(0.6), 1.0);
  EXPECT_EQ(AutomaticStepShapingStrength(3.0), 1.0);
}

TEST(ChooseStepExponents, IgnoreVerticesWithoutEdgeLength) {
  const int n = 5;
  const MeshTopology topology = GridTopology(n);
  const Eigen::MatrixXd collapsed = Eigen::MatrixXd::Zero(n * n, 3);  // every edge of length 0
  EXPECT_EQ(ChooseStepExponents(collapsed, topology, std::vector<int32_t>{0, 24}, 1.0),
            std::vector<int8_t>(2, 0));
}

// A graded grid animated by a travelling wave: a mesh of uneven triangles.
MeshSequence GradedWave(int n, int frames) {
  const Eigen::MatrixXd shape = GradedGrid(n);
  MeshSequence sequence(n * n, synth::GridTriangles(n, n, synth::GridDiagonals::kUniform), frames);
  for (int f = 0; f < frames; ++f) {
    for (int v = 0; v < n * n; ++v) {
      const double x = shape(v, 0), y = shape(v, 1);
      sequence.frame(f).row(v) << static_cast<float>(x), static_cast<float>(y),
          static_cast<float>(0.1 * std::sin(6.0 * x + 0.4 * f) * std::cos(3.0 * y - 0.2 * f));
    }
  }
  return sequence;
}

TEST(StepShapingEncode, DecodesToWhatTheEncoderMeasured) {
  const MeshSequence original = GradedWave(33, 12);
  std::vector<uint8_t> previous;
  for (const double strength : {0.0, 1.0, -1.0}) {
    EncoderOptions options;
    options.step_shaping = strength;
    EncodeReport report;
    const auto stream = Encode(original, options, &report);
    ASSERT_TRUE(stream.ok()) << stream.status().ToString();
    const auto decoded = Decode(*stream);
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    const auto distortion = MeasureDistortion(original, *decoded);
    ASSERT_TRUE(distortion.ok());
    EXPECT_EQ(distortion->kg, report.distortion.kg) << strength;
    EXPECT_EQ(distortion->sted, report.distortion.sted) << strength;
    if (strength == 1.0) {
      EXPECT_NE(*stream, previous) << "the exponents change the stream";
    }
    previous = *stream;
  }
}

TEST(StepShapingOption, IsValidated) {
  for (const double bad : {-2.0, -0.5, 2.5, std::nan("")}) {
    EncoderOptions options;
    options.step_shaping = bad;
    const Status status = ValidateOptions(options);
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument) << bad;
    EXPECT_NE(status.message().find("step"), std::string::npos) << status.ToString();
  }
  for (const double good : {-1.0, 0.0, 0.5, 2.0}) {
    EncoderOptions options;
    options.step_shaping = good;
    EXPECT_TRUE(ValidateOptions(options).ok()) << good;
  }
}

}  // namespace
}  // namespace dmc
