// Declared sizes against what a stream can hold and what a caller accepts (spec §5.5, §8.7,
// §11.4): a payload too short for the values its headers declare is corrupt-stream before
// anything is sized by them, and a declared output above DecoderOptions::max_output_bytes is
// resource-limit before the connectivity is decoded. (Their memory is measured in
// allocation_bound_test, which counts every heap byte.)
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "bitstream/format.h"
#include "decoder/range_decoder.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/sparse_solvers.h"
#include "dmc/synth.h"
#include "dmc/wire_ids.h"
#include "encoder/range_encoder.h"
#include "encoder/syntax_writer.h"
#include "test_support.h"
#include "unit/conformance/stream_chunks.h"

namespace dmc {
namespace {

using testing::Chunk;

std::vector<uint8_t> EncodeSynthetic(const char* generator, int resolution, int frames,
                                     const char* operator_name) {
  SynthOptions synth;
  synth.resolution = resolution;
  synth.frames = frames;
  const StatusOr<MeshSequence> sequence = Synthesize(generator, synth);
  EXPECT_TRUE(sequence.ok()) << sequence.status().ToString();
  EncoderOptions options;
  options.measure = false;
  options.operator_name = operator_name;
  const StatusOr<std::vector<uint8_t>> stream = Encode(*sequence, options);
  EXPECT_TRUE(stream.ok()) << stream.status().ToString();
  return stream.ok() ? *stream : std::vector<uint8_t>();
}

constexpr size_t kSegmentHeader = 2, kOperator = 5;

TEST(DeclaredSizes, TheDecisionBoundHoldsForTheMostCompressibleInput) {
  // The bound is a property of the range coder: decisions of a saturated model are the cheapest
  // there are, so a long run of them comes closest to it, and must stay within it. The bound
  // takes the probability alone; the coder's truncation of the range makes real decisions
  // several times dearer, so a run reaches a fifth of it, not less than an eighth.
  for (const int bit : {0, 1}) {
    RangeEncoder encoder;
    AdaptiveBit model;
    constexpr uint64_t kDecisions = 4'000'000;
    for (uint64_t i = 0; i < kDecisions; ++i) encoder.EncodeBit(model, bit);
    const std::vector<uint8_t> payload = encoder.Finish();
    EXPECT_LE(kDecisions, format::MaxDecisions(payload.size())) << "bit " << bit;
    EXPECT_GT(kDecisions, format::MaxDecisions(payload.size()) / 8) << "bit " << bit;
    // And the decoder reads them all back without overrunning.
    RangeDecoder decoder;
    ASSERT_TRUE(decoder.Init(payload).ok());
    AdaptiveBit mirror;
    for (uint64_t i = 0; i < kDecisions; ++i) ASSERT_EQ(decoder.DecodeBit(mirror), bit);
    EXPECT_TRUE(decoder.CheckNotOverrun("run").ok());
  }
}

TEST(DeclaredSizes, OutputAboveTheCallersLimitIsResourceLimit) {
  const std::vector<uint8_t> stream = EncodeSynthetic("twist", 100, 3, "ddl");
  const StatusOr<StreamInfo> info = ReadStreamInfo(stream);
  ASSERT_TRUE(info.ok()) << info.status().ToString();
  const uint64_t output = DeclaredOutputBytes(*info);
  EXPECT_EQ(output, 12 * (uint64_t(info->vertex_count) * info->frame_count +
                          uint64_t(info->triangle_count)));

  DecoderOptions tight;
  tight.max_output_bytes = output - 1;
  const StatusOr<MeshSequence> refused = Decode(stream, tight);
  ASSERT_EQ(refused.status().code(), ErrorCode::kResourceLimit);
  EXPECT_NE(refused.status().message().find(std::to_string(output) + " bytes of output"),
            std::string::npos)
      << refused.status().message();
  Decoder decoder;
  EXPECT_EQ(decoder.Open(stream, tight).code(), ErrorCode::kResourceLimit);

  DecoderOptions exact;
  exact.max_output_bytes = output;
  EXPECT_TRUE(Decode(stream, exact).ok());
  DecoderOptions none;
  none.max_output_bytes = 0;
  EXPECT_TRUE(Decode(stream, none).ok());
  EXPECT_TRUE(Decode(stream).ok());  // the default, 4 GiB
}

TEST(DeclaredSizes, TheCallersLimitComesBeforeTheStreamsOwnChecks) {
  // Spec §4.4: the limit is checked right after the format's own output limit, so a caller
  // never pays for the rest of a stream it would refuse anyway.
  const std::filesystem::path vector = std::filesystem::path(DMC_SOURCE_DIR) /
                                       "conformance/vectors/invalid" /
                                       "residuals_cannot_hold_declared_vertices.dmc";
  const StatusOr<std::vector<uint8_t>> stream = ReadFileBytes(vector);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();
  EXPECT_EQ(Decode(*stream).status().code(), ErrorCode::kResourceLimit);  // 16.9 GB > 4 GiB
  DecoderOptions none;
  none.max_output_bytes = 0;
  EXPECT_EQ(Decode(*stream, none).status().code(), ErrorCode::kCorruptStream);
  EXPECT_EQ(ReadStreamInfo(*stream).status().code(), ErrorCode::kCorruptStream);
}

TEST(DeclaredSizes, PayloadsThatCannotHoldTheirDeclaredValuesAreCorrupt) {
  // The generated vectors declare 2^26 vertices (or 2^25 anchors) in a few hundred bytes; each
  // message names the payload that is too short.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"residuals_cannot_hold_declared_vertices", "residual payload of"},
      {"residuals_cannot_hold_declared_vertices_tutte", "residual payload of"},
      {"reference_frame_cannot_hold_declared_vertices", "reference frame payload of"},
      {"anchors_cannot_hold_declared_count", "anchor payload of"},
  };
  DecoderOptions none;
  none.max_output_bytes = 0;
  for (const auto& [name, message] : cases) {
    const StatusOr<std::vector<uint8_t>> stream = ReadFileBytes(
        std::filesystem::path(DMC_SOURCE_DIR) / "conformance/vectors/invalid" / (name + ".dmc"));
    ASSERT_TRUE(stream.ok()) << stream.status().ToString();
    for (const Status& status :
         {Decode(*stream, none).status(), ReadStreamInfo(*stream).status()}) {
      EXPECT_EQ(status.code(), ErrorCode::kCorruptStream) << name << ": " << status.ToString();
      EXPECT_NE(status.message().find(message), std::string::npos) << status.message();
    }
  }
}

TEST(DeclaredSizes, DdlWeightsBeyondTheOperatorPayloadAreCorrupt) {
  // A DDL segment codes at least E - (non-isolated vertices) weights; a 5-byte payload holds at
  // most 121 640 decisions, so a mesh of about 60k vertices (120k more edges than vertices)
  // cannot have its weights in it. The Tutte stream is relabelled DDL: no fit is needed.
  const std::vector<uint8_t> stream = EncodeSynthetic("cloth", 65000, 1, "tutte");
  ASSERT_FALSE(stream.empty());
  std::vector<uint8_t> preamble;
  std::vector<Chunk> chunks = testing::SplitChunks(stream, &preamble);
  StatusOr<format::SegmentHeader> header = [&] {
    std::span<const uint8_t> payload(chunks[kSegmentHeader].payload);
    return syntax::ReadSegmentHeader(payload, 0, 1, ReadStreamInfo(stream)->vertex_count);
  }();
  ASSERT_TRUE(header.ok()) << header.status().ToString();
  header->operator_id = static_cast<uint8_t>(OperatorId::kDdl);
  chunks[kSegmentHeader].payload = syntax::WriteSegmentHeader(*header);
  chunks[kOperator].payload = {0, 0, 0, 0, 0};
  const Status status = Decode(testing::JoinChunks(preamble, chunks)).status();
  EXPECT_EQ(status.code(), ErrorCode::kCorruptStream) << status.ToString();
  EXPECT_NE(status.message().find("DDL weight payload of 5 bytes"), std::string::npos)
      << status.message();
}

// A disc triangulated as a fan: vertex 0 joined to a ring of `ring` vertices, moving over frames.
MeshSequence Fan(int ring, int frames) {
  Triangles triangles(ring, 3);
  for (int i = 0; i < ring; ++i) triangles.row(i) << 0, 1 + i, 1 + (i + 1) % ring;
  MeshSequence sequence(ring + 1, triangles, frames);
  for (int f = 0; f < frames; ++f) {
    sequence.frame(f).row(0) << 0.0f, 0.0f, 0.1f * static_cast<float>(f);
    for (int i = 0; i < ring; ++i) {
      const double angle = 2.0 * 3.141592653589793 * i / ring;
      sequence.frame(f).row(1 + i) << static_cast<float>(std::cos(angle)),
          static_cast<float>(std::sin(angle)), 0.0f;
    }
  }
  return sequence;
}

TEST(DeclaredSizes, NormalMatrixAboveTheLimitIsResourceLimit) {
  // A fan of 1000 triangles in 3 frames declares 48 KB of output, but its centre's row of L meets
  // every other row in LᵀL: about 1000² entries, over 8 MB. The limit bounds that too. (Its dense
  // factor costs seconds with the SimplicialLDLT backend at 3000 triangles.)
  const MeshSequence fan = Fan(1000, 3);
  EncoderOptions options;
  options.measure = false;
  options.operator_name = "tutte";
  const StatusOr<std::vector<uint8_t>> stream = Encode(fan, options);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();
  const StatusOr<StreamInfo> info = ReadStreamInfo(*stream);
  ASSERT_TRUE(info.ok());
  ASSERT_GT(info->segments[0].rank, 0);
  DecoderOptions limit;
  limit.max_matrix_bytes = uint64_t{1} << 20;
  ASSERT_LT(DeclaredOutputBytes(*info), limit.max_matrix_bytes);
  const Status refused = Decode(*stream, limit).status();
  EXPECT_EQ(refused.code(), ErrorCode::kResourceLimit) << refused.ToString();
  EXPECT_NE(refused.message().find("normal matrix"), std::string::npos) << refused.message();
  EXPECT_TRUE(Decode(*stream).ok());  // 4 GiB
  // The factor's own check, made after the ordering: a 100×100 identity has a factor of 100
  // values (800 bytes), refused under a 64-byte bound.
  SolverOptions solver_options;
  solver_options.max_matrix_bytes = 64;
  SparseMatrixD identity(100, 100);
  identity.setIdentity();
  const Status factor = SparseSpdSolver::Factor(identity, solver_options).status();
  EXPECT_EQ(factor.code(), ErrorCode::kResourceLimit) << factor.ToString();
  EXPECT_NE(factor.message().find("its factor would take"), std::string::npos);
  solver_options.max_matrix_bytes = 0;
  EXPECT_TRUE(SparseSpdSolver::Factor(identity, solver_options).ok());
}

}  // namespace
}  // namespace dmc
