#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>

#include "bitstream/syntax.h"
#include "decoder/range_decoder.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/io.h"
#include "dmc/metrics.h"
#include "dmc/topology.h"
#include "encoder/syntax_writer.h"
#include "test_support.h"

namespace dmc {
namespace {

// A UV sphere (closed: poles are single vertices) whose surface bends and breathes smoothly over
// time: a small, realistic stand-in for a deforming character.
MeshSequence WobblingSphere(int rings, int segments, int frames) {
  const int v_count = 2 + (rings - 1) * segments;
  std::vector<std::array<int32_t, 3>> tris;
  auto ring_vertex = [&](int ring, int s) { return 1 + (ring - 1) * segments + (s % segments); };
  const int south = v_count - 1;
  for (int s = 0; s < segments; ++s) {
    tris.push_back({0, ring_vertex(1, s), ring_vertex(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      tris.push_back({ring_vertex(r, s), ring_vertex(r + 1, s), ring_vertex(r + 1, s + 1)});
      tris.push_back({ring_vertex(r, s), ring_vertex(r + 1, s + 1), ring_vertex(r, s + 1)});
    }
    tris.push_back({ring_vertex(rings - 1, s), south, ring_vertex(rings - 1, s + 1)});
  }
  Triangles triangles(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t) {
    triangles.row(static_cast<Eigen::Index>(t)) << tris[t][0], tris[t][1], tris[t][2];
  }
  MeshSequence seq(v_count, triangles, frames);
  for (int f = 0; f < frames; ++f) {
    const double time = 0.1 * f;
    auto frame = seq.frame(f);
    for (int v = 0; v < v_count; ++v) {
      double theta, phi;
      if (v == 0) {
        theta = 0.0, phi = 0.0;
      } else if (v == south) {
        theta = std::numbers::pi, phi = 0.0;
      } else {
        theta = std::numbers::pi * ((v - 1) / segments + 1) / rings;
        phi = 2.0 * std::numbers::pi * ((v - 1) % segments) / segments;
      }
      const double radius = 1.0 + 0.2 * std::sin(2.0 * theta + time) * std::cos(phi - 0.5 * time);
      const double bend = 0.3 * std::sin(time) * std::cos(theta);
      const double x = radius * std::sin(theta) * std::cos(phi) + bend;
      const double y = radius * std::sin(theta) * std::sin(phi);
      const double z = radius * std::cos(theta) * (1.0 + 0.1 * std::sin(1.3 * time));
      frame.row(v) << static_cast<float>(x + 0.05 * f), static_cast<float>(y),
          static_cast<float>(z);
    }
  }
  seq.name = "wobbling-sphere";
  seq.frame_rate = 25.0;
  return seq;
}

EncoderOptions Quick(const std::string& op) {
  EncoderOptions options;
  options.operator_name = op;
  options.residual_bits = 11;
  return options;
}

class CodecRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(CodecRoundTrip, DecodesWhatTheEncoderMeasured) {
  const MeshSequence original = WobblingSphere(16, 24, 20);
  EncodeReport report;
  auto bytes = Encode(original, Quick(GetParam()), &report);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_EQ(report.bytes, bytes->size());
  EXPECT_NEAR(report.bpfv, 8.0 * bytes->size() / (20.0 * original.vertex_count()), 1e-12);
  ASSERT_TRUE(report.measured);

  auto decoded = Decode(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_EQ(decoded->vertex_count(), original.vertex_count());
  EXPECT_EQ(decoded->frame_count(), original.frame_count());
  EXPECT_TRUE(CheckComparable(original, *decoded).ok());  // same oriented triangle set
  EXPECT_EQ(decoded->name, original.name);
  EXPECT_EQ(decoded->frame_rate, original.frame_rate);
  auto distortion = MeasureDistortion(original, *decoded);
  ASSERT_TRUE(distortion.ok());
  EXPECT_EQ(distortion->kg, report.distortion.kg);
  EXPECT_EQ(distortion->sted, report.distortion.sted);
  EXPECT_LT(report.distortion.kg, 1.0);
  EXPECT_GT(report.rank, 0);

  // Identical bytes on a repeated run.
  auto again = Encode(original, Quick(GetParam()));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, *bytes);
}

INSTANTIATE_TEST_SUITE_P(Operators, CodecRoundTrip,
                         ::testing::Values("ddl", "tutte", "kirchhoff", "cotan", "cotan-area",
                                           "cotan-sym", "mean-value"));

TEST(Codec, RateFallsAndDistortionRisesWithTheStep) {
  const MeshSequence original = WobblingSphere(14, 20, 16);
  double previous_bpfv = 1e9, previous_kg = -1.0;
  for (int bits : {13, 11, 9, 7}) {
    EncoderOptions options = Quick("ddl");
    options.residual_bits = bits;
    options.rank = 12;
    EncodeReport report;
    ASSERT_TRUE(Encode(original, options, &report).ok());
    EXPECT_LT(report.bpfv, previous_bpfv) << "bits " << bits;
    EXPECT_GT(report.distortion.kg, previous_kg) << "bits " << bits;
    previous_bpfv = report.bpfv;
    previous_kg = report.distortion.kg;
  }
}

TEST(Codec, SegmentsDecodeIndependently) {
  const MeshSequence original = WobblingSphere(10, 16, 25);
  EncoderOptions options = Quick("ddl");
  options.segment_frames = 10;
  EncodeReport report;
  auto bytes = Encode(original, options, &report);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_EQ(report.segments, 3);
  Decoder decoder;
  ASSERT_TRUE(decoder.Open(*bytes).ok());
  ASSERT_EQ(decoder.segment_count(), 3);
  auto whole = Decode(*bytes);
  ASSERT_TRUE(whole.ok());
  int first = 0;
  for (int s = 0; s < 3; ++s) {
    auto part = decoder.DecodeSegment(s);
    ASSERT_TRUE(part.ok());
    EXPECT_EQ(decoder.info().segments[s].first_frame, first);
    for (int f = 0; f < part->frame_count(); ++f) {
      EXPECT_EQ(part->frame(f), whole->frame(first + f));
    }
    first += part->frame_count();
  }
  EXPECT_EQ(first, 25);
}

TEST(Codec, BytesDoNotDependOnTheThreadCount) {
  const MeshSequence original = WobblingSphere(12, 16, 24);
  EncoderOptions options = Quick("ddl");
  options.segment_frames = 8;
  options.measure = false;
  auto parallel = Encode(original, options);
  ASSERT_TRUE(parallel.ok());
  std::vector<uint8_t> serial;
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    auto bytes = Encode(original, options);
    ASSERT_TRUE(bytes.ok());
    serial = *bytes;
    auto decoded_serial = Decode(serial);
    auto decoded_parallel = Decode(*parallel);
    ASSERT_TRUE(decoded_serial.ok() && decoded_parallel.ok());
  }
  EXPECT_EQ(serial, *parallel);
  auto a = Decode(serial);
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  auto b = Decode(serial);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(std::equal(a->data(), a->data() + a->position_value_count(), b->data()));
}

TEST(Codec, SingleFrameSequence) {
  const MeshSequence original = WobblingSphere(10, 16, 1);
  EncodeReport report;
  auto bytes = Encode(original, Quick("ddl"), &report);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  auto decoded = Decode(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_EQ(decoded->frame_count(), 1);
  EXPECT_LT(report.distortion.kg, 1.0);
}

TEST(Codec, RejectsImpossibleOptions) {
  const MeshSequence original = WobblingSphere(6, 8, 3);
  EncoderOptions options;
  options.operator_name = "no-such-operator";
  EXPECT_EQ(Encode(original, options).status().code(), ErrorCode::kNotFound);
  options = EncoderOptions();
  options.basis_bits = 1;
  EXPECT_EQ(Encode(original, options).status().code(), ErrorCode::kInvalidArgument);
  options = EncoderOptions();
  options.target_bpfv = 1.0;
  options.target_sted = 0.01;
  EXPECT_EQ(Encode(original, options).status().code(), ErrorCode::kInvalidArgument);
  MeshSequence bad = original;
  bad.frame(1)(2, 0) = std::nanf("");
  EXPECT_EQ(Encode(bad, EncoderOptions()).status().code(), ErrorCode::kInvalidSequence);
}

TEST(Codec, EveryTruncationAndEveryByteFlipIsAnError) {
  const MeshSequence original = WobblingSphere(6, 8, 4);
  EncoderOptions options = Quick("ddl");
  options.measure = false;
  auto bytes = Encode(original, options);
  ASSERT_TRUE(bytes.ok());
  for (size_t length = 0; length < bytes->size(); ++length) {
    auto result = Decode(std::span<const uint8_t>(bytes->data(), length));
    ASSERT_FALSE(result.ok()) << "length " << length;
    const ErrorCode code = result.status().code();
    EXPECT_TRUE(code == ErrorCode::kTruncatedStream || code == ErrorCode::kCorruptStream)
        << "length " << length << ": " << result.status().ToString();
  }
  for (size_t i = 0; i < bytes->size(); ++i) {
    std::vector<uint8_t> damaged = *bytes;
    damaged[i] ^= 0x5a;
    auto result = Decode(damaged);
    EXPECT_FALSE(result.ok()) << "flip at " << i;
  }
}

TEST(Codec, DdlWeightCoderRoundTripsAndKeepsRowsTranslationInvariant) {
  const MeshSequence mesh = WobblingSphere(8, 12, 1);
  const MeshTopology topology = BuildTopology(mesh.triangles(), mesh.vertex_count());
  std::vector<double> weights(topology.edges.size());
  for (size_t e = 0; e < weights.size(); ++e) weights[e] = 0.15 + 0.01 * std::sin(0.7 * e);
  std::vector<int64_t> encoded;
  const std::vector<uint8_t> payload = syntax::WriteDdlWeights(
      weights, topology, 8, format::WeightPrediction::kReferenceProportional, &encoded);
  SegmentSyntax syntax;
  syntax.header.operator_id = static_cast<uint8_t>(OperatorId::kDdl);
  syntax.header.weight_bits = 8;
  syntax.header.weight_prediction = 1;
  ASSERT_TRUE(syntax::ReadOperator(payload, topology, syntax).ok());
  EXPECT_EQ(syntax.edge_weights, encoded);
  // Explicit weights are the rounded fit; the schedule sends about 2|V| of the 3|V| weights.
  const auto schedule = format::BuildWeightSchedule(topology);
  size_t explicit_weights = 0;
  for (const auto& visit : schedule) explicit_weights += visit.unknown_edges.size() - 1;
  EXPECT_LT(explicit_weights, topology.edges.size());
  EXPECT_GT(explicit_weights, topology.edges.size() / 2);
  auto laplace = RebuildSegmentOperator(topology, syntax);
  ASSERT_TRUE(laplace.ok());
  const Eigen::VectorXd row_sums = laplace->matrix * Eigen::VectorXd::Ones(mesh.vertex_count());
  EXPECT_LT(row_sums.cwiseAbs().maxCoeff(), 1e-12);
}

// The DDL fallback keeps no dequantised deltas: it measures each candidate with the deltas the
// decoder reads back from the residual payload. That is only the encoder's closed loop if the
// reader returns exactly (bit for bit) what the writer dequantised, and the payload must not depend
// on whether the writer stores them.
TEST(Codec, ResidualReaderReturnsTheWritersDequantisedDeltasExactly) {
  const MeshSequence mesh = WobblingSphere(8, 12, 1);
  const MeshTopology topology = BuildTopology(mesh.triangles(), mesh.vertex_count());
  const std::vector<int32_t> vertex_order = format::BreadthFirstOrder(topology);
  constexpr int kRank = 4;
  format::SegmentHeader header;
  header.rank = kRank;
  header.residual_step = 0.01;
  Eigen::MatrixXd delta(mesh.vertex_count(), kRank);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < kRank; ++k) {
      // Residuals from -11 to +11 steps, off the grid by up to 0.3 steps in either direction.
      delta(v, k) = 0.01 * ((v * 7 + k * 3) % 23 - 11) + 0.001 * ((v + k) % 7 - 3);
    }
  }
  Eigen::MatrixXd written;
  const auto payload = syntax::WriteResiduals(delta, topology, vertex_order, header, &written);
  ASSERT_TRUE(payload.ok()) << payload.status().ToString();
  const auto without_output =
      syntax::WriteResiduals(delta, topology, vertex_order, header, nullptr);
  ASSERT_TRUE(without_output.ok());
  EXPECT_EQ(*without_output, *payload);
  // Hand-computed: vertex 0, component 0 is -11 steps - 0.3 steps -> -11 · 0.01; vertex 5,
  // component 1 is (38 % 23 - 11) = 4 steps + 0.3 steps (6 % 7 - 3 = 3 thousandths) -> 4 · 0.01.
  EXPECT_EQ(written(0, 0), -11 * 0.01);
  EXPECT_EQ(written(5, 1), 4 * 0.01);
  SegmentSyntax syntax;
  syntax.header = header;
  ASSERT_TRUE(syntax::ReadResiduals(*payload, topology, vertex_order, syntax).ok());
  ASSERT_EQ(syntax.delta.rows(), written.rows());
  ASSERT_EQ(syntax.delta.cols(), written.cols());
  EXPECT_TRUE((syntax.delta.array() == written.array()).all());
}

// Rate–distortion optimised rounding: the payload still decodes to exactly the writer's
// dequantised deltas; every level is the nearest or one toward zero; larger λ never costs more
// bytes; λ = 0 is plain rounding.
TEST(Codec, RdoRoundingDecodesToTheWritersDeltasAndOnlyMovesTowardZero) {
  const MeshSequence mesh = WobblingSphere(8, 12, 1);
  const MeshTopology topology = BuildTopology(mesh.triangles(), mesh.vertex_count());
  const std::vector<int32_t> vertex_order = format::BreadthFirstOrder(topology);
  constexpr int kRank = 6;
  format::SegmentHeader header;
  header.rank = kRank;
  header.residual_step = 0.01;
  Eigen::MatrixXd delta(mesh.vertex_count(), kRank);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < kRank; ++k) {
      delta(v, k) = 0.01 * (0.15 * ((v * 13 + k * 5) % 29) - 1.6) / (1 + k);
    }
  }
  Eigen::MatrixXd plain;
  const auto plain_payload = syntax::WriteResiduals(delta, topology, vertex_order, header, &plain);
  ASSERT_TRUE(plain_payload.ok());
  Eigen::MatrixXd zero_lambda;
  EXPECT_EQ(*syntax::WriteResiduals(delta, topology, vertex_order, header, &zero_lambda, 0.0),
            *plain_payload);
  size_t previous_size = plain_payload->size();
  for (const double lambda : {0.05, 0.2, 1.0}) {
    SCOPED_TRACE(lambda);
    Eigen::MatrixXd written;
    const auto payload =
        syntax::WriteResiduals(delta, topology, vertex_order, header, &written, lambda);
    ASSERT_TRUE(payload.ok());
    EXPECT_LE(payload->size(), previous_size);
    previous_size = payload->size();
    int moved = 0;
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      for (int k = 0; k < kRank; ++k) {
        const double nearest = plain(v, k), chosen = written(v, k);
        if (chosen == nearest) continue;
        ++moved;
        EXPECT_NEAR(std::abs(nearest) - std::abs(chosen), header.residual_step, 1e-12);
        EXPECT_EQ(std::signbit(nearest) || chosen == 0.0, std::signbit(chosen) || chosen == 0.0);
      }
    }
    EXPECT_GT(moved, 0);
    SegmentSyntax syntax;
    syntax.header = header;
    ASSERT_TRUE(syntax::ReadResiduals(*payload, topology, vertex_order, syntax).ok());
    EXPECT_TRUE((syntax.delta.array() == written.array()).all());
  }
  EXPECT_LT(previous_size, plain_payload->size());
}

// The encoder's comparison of codings (encoder.cpp, kStedSlopeBits): bits + 0.5 · V · F · ln STED.
double RateDistortionCost(const EncodeReport& report) {
  return 8.0 * static_cast<double>(report.bytes) +
         0.5 * report.vertices * report.frames * std::log(report.distortion.sted);
}

// With one segment, the fallback's choice is made on exactly the stream's rate and STED: it keeps
// the fitted DDL unless kirchhoff, tutte or mean-value costs less, so it never costs more.
TEST(Codec, DdlFallbackNeverCostsMoreThanTheFittedWeights) {
  const MeshSequence original = WobblingSphere(16, 24, 12);
  for (int bits : {8, 10, 12}) {
    EncoderOptions options = Quick("ddl");
    options.residual_bits = bits;
    options.rank_search = false;  // one rank: this compares operators (rank_search_test.cpp)
    EncodeReport fallback, fitted;
    ASSERT_TRUE(Encode(original, options, &fallback).ok());
    options.ddl_fallback = false;
    ASSERT_TRUE(Encode(original, options, &fitted).ok());
    EXPECT_EQ(fitted.segment_operators, std::vector<std::string>{"ddl"});
    ASSERT_EQ(fallback.segment_operators.size(), 1u);
    const std::string& chosen = fallback.segment_operators[0];
    EXPECT_TRUE(chosen == "ddl" || chosen == "kirchhoff" || chosen == "tutte" ||
                chosen == "mean-value")
        << chosen;
    if (chosen == "ddl") {
      EXPECT_EQ(fallback.bytes, fitted.bytes) << "bits " << bits;
    }
    EXPECT_LE(RateDistortionCost(fallback), RateDistortionCost(fitted) + 1e-6) << "bits " << bits;
  }
}

// Two-frame segments cannot pay for fitted weights (about 10 bits per vertex each): the stream
// names the operator of every segment, decodes, and the decoder's segment information agrees.
TEST(Codec, DdlFallbackNamesEverySegmentsOperator) {
  const MeshSequence original = WobblingSphere(12, 16, 8);
  EncoderOptions options = Quick("ddl");
  options.segment_frames = 2;
  EncodeReport report;
  auto bytes = Encode(original, options, &report);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  ASSERT_EQ(report.segment_operators.size(), 4u);
  Decoder decoder;
  ASSERT_TRUE(decoder.Open(*bytes).ok());
  int fallbacks = 0;
  for (int s = 0; s < 4; ++s) {
    EXPECT_EQ(decoder.info().segments[s].operator_name, report.segment_operators[s]);
    fallbacks += report.segment_operators[s] != "ddl";
  }
  EXPECT_GT(fallbacks, 0);
  auto decoded = Decode(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  auto distortion = MeasureDistortion(original, *decoded);
  ASSERT_TRUE(distortion.ok());
  EXPECT_EQ(distortion->sted, report.distortion.sted);
}

TEST(Syntax, RoundDivRoundsHalvesUp) {
  EXPECT_EQ(format::RoundDiv(7, 2), 4);
  EXPECT_EQ(format::RoundDiv(-7, 2), -3);
  EXPECT_EQ(format::RoundDiv(256, 6), 43);
  EXPECT_EQ(format::RoundDiv(-1, 3), 0);
  EXPECT_EQ(format::RoundDiv(-2, 3), -1);
}

}  // namespace
}  // namespace dmc

namespace dmc {
namespace {

// Real data: chicken-crossing has 41 components and 31 boundary loops; every codec operator must
// keep the input's vertex order and triangle set and decode what the encoder measured.
class RealDataRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(RealDataRoundTrip, ChickenCrossingWithManyComponents) {
  DMC_REQUIRE_SHARED_DATA(path, "chicken-crossing");
  ReadOptions read_options;
  read_options.max_frames = 6;
  auto original = ReadSequence(path, read_options);
  ASSERT_TRUE(original.ok()) << original.status().ToString();
  EncoderOptions options;
  options.operator_name = GetParam();
  options.residual_bits = 11;
  EncodeReport report;
  auto bytes = Encode(*original, options, &report);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  auto decoded = Decode(*bytes);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  ASSERT_TRUE(CheckComparable(*original, *decoded).ok());
  auto distortion = MeasureDistortion(*original, *decoded);
  ASSERT_TRUE(distortion.ok());
  EXPECT_EQ(distortion->kg, report.distortion.kg);
  EXPECT_EQ(distortion->sted, report.distortion.sted);
  // Vertex order kept: each decoded vertex is close to the same-index input vertex.
  EXPECT_LT(distortion->max_error, 0.05 * ComputeBoundingBox(*original).diagonal());
  EXPECT_LT(report.distortion.kg, 2.0);
}

INSTANTIATE_TEST_SUITE_P(Operators, RealDataRoundTrip,
                         ::testing::Values("ddl", "tutte", "kirchhoff", "mean-value"));

}  // namespace
}  // namespace dmc
