// The decoder on hostile input (bitstream-spec/dmc-format.md §11, §12.1): every prefix, every
// byte flip (with and without a repaired checksum) and a set of crafted streams must give a
// result or one of the error codes the spec allows for stream content — never a crash, another
// code, non-finite output, or memory out of proportion with the stream's declared sizes.
//
// The overflow cases (huge steps and weights, large fans) were found while writing the spec; the
// decoder now bounds steps by 2^64 and anchor weights by [2^-32, 2^32] and predicts DDL weights
// in 128-bit integers (spec §8.1, §8.4, §9.4).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <functional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/syntax_reader.h"
#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/synth.h"
#include "dmc/topology.h"
#include "encoder/range_encoder.h"
#include "encoder/syntax_writer.h"
#include "entropy/byte_io.h"
#include "test_support.h"
#include "unit/conformance/stream_chunks.h"

namespace dmc {

// Failure messages name codes ("corrupt-stream") instead of dumping their bytes.
inline void PrintTo(ErrorCode code, std::ostream* out) { *out << ErrorCodeName(code); }

namespace {

__extension__ typedef __int128 Int128;  // exact reference arithmetic (GCC/Clang extension)

using testing::Chunk;
using testing::JoinChunks;
using testing::SplitChunks;

// A small valid one-segment DDL stream (twist, ~100 vertices, 3 frames) shared by the tests.
const std::vector<uint8_t>& SmallStream() {
  static const std::vector<uint8_t> stream = [] {
    SynthOptions synth;
    synth.resolution = 100;
    synth.frames = 3;
    const StatusOr<MeshSequence> sequence = Synthesize("twist", synth);
    EXPECT_TRUE(sequence.ok());
    EncoderOptions options;
    options.measure = false;
    const StatusOr<std::vector<uint8_t>> bytes = Encode(*sequence, options);
    EXPECT_TRUE(bytes.ok()) << bytes.status().ToString();
    return bytes.ok() ? *bytes : std::vector<uint8_t>();
  }();
  return stream;
}

constexpr size_t kSegmentHeader = 2, kMean = 3, kAnchors = 6, kResiduals = 7;

// The codes spec §11 allows a decoder to report for stream content.
bool IsStreamError(ErrorCode code) {
  return code == ErrorCode::kCorruptStream || code == ErrorCode::kTruncatedStream ||
         code == ErrorCode::kUnsupported || code == ErrorCode::kNumericalFailure;
}

bool AllFinite(const MeshSequence& sequence) {
  for (size_t i = 0; i < sequence.position_value_count(); ++i) {
    if (!std::isfinite(sequence.data()[i])) return false;
  }
  return true;
}

long PeakRssKilobytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

// Rewrites segment 0's header of the small stream.
std::vector<uint8_t> WithSegmentHeader(const std::function<void(format::SegmentHeader&)>& edit) {
  std::vector<uint8_t> preamble;
  std::vector<Chunk> chunks = SplitChunks(SmallStream(), &preamble);
  const StreamInfo info = *ReadStreamInfo(SmallStream());
  auto header = syntax::ReadSegmentHeader(chunks[kSegmentHeader].payload, 0,
                                          static_cast<uint32_t>(info.frame_count),
                                          static_cast<uint32_t>(info.vertex_count));
  EXPECT_TRUE(header.ok());
  edit(*header);
  chunks[kSegmentHeader].payload = syntax::WriteSegmentHeader(*header);
  return JoinChunks(preamble, chunks);
}

TEST(HostileStreams, EveryProperPrefixIsTruncatedStream) {
  const std::vector<uint8_t>& stream = SmallStream();
  ASSERT_FALSE(stream.empty());
  for (size_t length = 0; length < stream.size(); ++length) {
    const std::span<const uint8_t> prefix(stream.data(), length);
    EXPECT_EQ(Decode(prefix).status().code(), ErrorCode::kTruncatedStream) << "length " << length;
    EXPECT_EQ(ReadStreamInfo(prefix).status().code(), ErrorCode::kTruncatedStream)
        << "length " << length;
  }
  EXPECT_TRUE(Decode(stream).ok());
}

TEST(HostileStreams, EveryByteFlipIsRejectedByTheContainer) {
  // Without repairing checksums a flipped byte hits the preamble checks, the framing or a
  // checksum: never a decoded sequence, and only container-level codes.
  const std::vector<uint8_t>& stream = SmallStream();
  std::set<ErrorCode> seen;
  for (size_t i = 0; i < stream.size(); ++i) {
    for (const uint8_t mask : {uint8_t{0x01}, uint8_t{0x80}, uint8_t{0xFF}}) {
      std::vector<uint8_t> damaged = stream;
      damaged[i] ^= mask;
      const StatusOr<MeshSequence> result = Decode(damaged);
      ASSERT_FALSE(result.ok()) << "byte " << i << " ^ " << int(mask) << " decoded";
      const ErrorCode code = result.status().code();
      EXPECT_TRUE(code == ErrorCode::kCorruptStream || code == ErrorCode::kTruncatedStream ||
                  code == ErrorCode::kUnsupported)
          << "byte " << i << ": " << result.status().ToString();
      seen.insert(code);
    }
  }
  // The version byte gives unsupported, checksums corrupt-stream, a grown size varint truncation.
  EXPECT_EQ(seen, (std::set<ErrorCode>{ErrorCode::kUnsupported, ErrorCode::kCorruptStream,
                                       ErrorCode::kTruncatedStream}));
}

TEST(HostileStreams, EveryPayloadByteFlipWithARepairedChecksumIsHandled) {
  // With the checksum recomputed, the flip reaches the syntax readers, the connectivity decoder,
  // the operator rebuild and the solver. The result is a finite sequence or a stream error.
  const std::vector<uint8_t>& stream = SmallStream();
  std::vector<uint8_t> preamble;
  const std::vector<Chunk> chunks = SplitChunks(stream, &preamble);
  const StreamInfo info = *ReadStreamInfo(stream);
  const long rss_before = PeakRssKilobytes();
  int decoded = 0, rejected = 0;
  for (size_t c = 0; c < chunks.size(); ++c) {
    for (size_t i = 0; i < chunks[c].payload.size(); ++i) {
      std::vector<Chunk> damaged = chunks;
      damaged[c].payload[i] ^= 0xFF;
      const StatusOr<MeshSequence> result = Decode(JoinChunks(preamble, damaged));
      if (result.ok()) {
        ++decoded;
        EXPECT_EQ(result->frame_count(), info.frame_count) << "chunk " << c << " byte " << i;
        EXPECT_TRUE(AllFinite(*result))
            << "chunk " << c << " byte " << i << ": decoded non-finite positions";
      } else {
        ++rejected;
        EXPECT_TRUE(IsStreamError(result.status().code()))
            << "chunk " << c << " byte " << i << ": " << result.status().ToString();
      }
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(decoded, 0);  // flips in residuals, for example, decode to another sequence
  // The stream declares ~100 vertices × 3 frames: nothing should need more than a few MB. (Under
  // ASan freed memory stays in its quarantine, up to 256 MB, so RSS says nothing there.)
  if (!DMC_SANITIZER_OWNS_ALLOCATOR) {
    EXPECT_LT(PeakRssKilobytes() - rss_before, 256 * 1024) << "peak RSS grew by more than 256 MB";
  }
}

TEST(HostileStreams, ComponentWithoutAnchorIsNumericalFailure) {
  // Anchors all in one component of a two-component mesh: the normal matrix is singular there.
  // Two disjoint tetrahedra, decoded with a hand-made stream would be long; use the encoder on a
  // two-component mesh and drop the second component's anchor.
  Triangles triangles(8, 3);
  triangles << 0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2, 4, 6, 5, 4, 5, 7, 5, 6, 7, 4, 7, 6;
  MeshSequence sequence(8, triangles, 3);
  for (int f = 0; f < 3; ++f) {
    sequence.frame(f) << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 3, 0, 0, 4, 0, 0, 3, 1, 0, 3, 0, 1;
    sequence.frame(f).col(0).array() += 0.1f * static_cast<float>(f * f);
    sequence.frame(f)(5, 1) += 0.2f * static_cast<float>(f);
  }
  EncoderOptions options;
  options.measure = false;
  options.operator_name = "kirchhoff";
  options.rank = 2;
  const StatusOr<std::vector<uint8_t>> stream = Encode(sequence, options);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();
  ASSERT_TRUE(Decode(*stream).ok());

  std::vector<uint8_t> preamble;
  std::vector<Chunk> chunks = SplitChunks(*stream, &preamble);
  auto header = syntax::ReadSegmentHeader(chunks[kSegmentHeader].payload, 0, 3, 8);
  ASSERT_TRUE(header.ok());
  ASSERT_EQ(header->anchor_count, 2u);  // one per component
  header->anchor_count = 1;
  chunks[kSegmentHeader].payload = syntax::WriteSegmentHeader(*header);
  // Anchor 0 only (index gap 0, values 0): vertices 4..7 have none.
  RangeEncoder encoder;
  format::AnchorContexts contexts;
  encoder.EncodeUnsigned(contexts.index_gap, 0);
  for (uint32_t k = 0; k < header->rank; ++k) encoder.EncodeSigned(contexts.value[k], 0);
  chunks[kAnchors].payload = encoder.Finish();
  const std::vector<uint8_t> damaged = JoinChunks(preamble, chunks);
  EXPECT_TRUE(ReadStreamInfo(damaged).ok());
  EXPECT_EQ(Decode(damaged).status().code(), ErrorCode::kNumericalFailure);
}

TEST(HostileStreams, ResidualsTruncatedAfterTheContainerAreTruncatedStream) {
  std::vector<uint8_t> preamble;
  std::vector<Chunk> chunks = SplitChunks(SmallStream(), &preamble);
  ASSERT_GT(chunks[kResiduals].payload.size(), 8u);
  for (size_t keep = 0; keep < chunks[kResiduals].payload.size(); ++keep) {
    std::vector<Chunk> cut = chunks;
    cut[kResiduals].payload.resize(keep);
    const ErrorCode code = Decode(JoinChunks(preamble, cut)).status().code();
    // Values decoded from the virtual zero bytes past the end are small (+1), so every cut is
    // reported as a truncation (spec §5.5).
    EXPECT_EQ(code, ErrorCode::kTruncatedStream) << "kept " << keep << " bytes";
  }
}

TEST(HostileStreams, HugeAnchorWeightIsHandled) {
  // anchor_weight = 1e300 is finite and positive but its square overflows, which would put
  // infinite entries in the normal matrix: §8.1 bounds it to [2^-32, 2^32] (corrupt-stream).
  const std::vector<uint8_t> stream =
      WithSegmentHeader([](format::SegmentHeader& h) { h.anchor_weight = 1e300; });
  const StatusOr<MeshSequence> result = Decode(stream);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), ErrorCode::kCorruptStream) << result.status().ToString();
}

TEST(HostileStreams, OverflowingResidualStepIsHandled) {
  // Every non-zero residual index times DBL_MAX / 2 is infinite: §8.1 bounds steps by 2^64.
  const std::vector<uint8_t> stream =
      WithSegmentHeader([](format::SegmentHeader& h) { h.residual_step = DBL_MAX / 2; });
  const StatusOr<MeshSequence> result = Decode(stream);
  ASSERT_FALSE(result.ok()) << "decoded a sequence from infinite differential coordinates";
  EXPECT_EQ(result.status().code(), ErrorCode::kCorruptStream) << result.status().ToString();
}

TEST(HostileStreams, OverflowingMeanStepIsHandled) {
  // The mean trajectory's indices times DBL_MAX / 2 would overflow to infinite positions.
  const std::vector<uint8_t> stream =
      WithSegmentHeader([](format::SegmentHeader& h) { h.mean_step = DBL_MAX / 2; });
  const StatusOr<MeshSequence> result = Decode(stream);
  if (result.ok()) {
    EXPECT_TRUE(AllFinite(*result)) << "decoded non-finite positions instead of corrupt-stream";
  } else {
    EXPECT_EQ(result.status().code(), ErrorCode::kCorruptStream) << result.status().ToString();
  }
}

TEST(HostileStreams, OverflowingReferenceFrameStepIsHandled) {
  // A geometric operator's reference frame (spec §8.4) with step DBL_MAX / 2: every coordinate
  // index of magnitude >= 2 would overflow to infinity; the step is bounded by 2^64.
  SynthOptions synth;
  synth.resolution = 100;
  synth.frames = 3;
  const StatusOr<MeshSequence> sequence = Synthesize("twist", synth);
  ASSERT_TRUE(sequence.ok());
  EncoderOptions options;
  options.measure = false;
  options.operator_name = "cotan";
  const StatusOr<std::vector<uint8_t>> stream = Encode(*sequence, options);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();
  std::vector<uint8_t> preamble;
  std::vector<Chunk> chunks = SplitChunks(*stream, &preamble);
  constexpr size_t kOperator = 5;
  ASSERT_GE(chunks[kOperator].payload.size(), 8u);
  ByteWriter step;
  step.PutF64(DBL_MAX / 2);
  std::copy(step.bytes().begin(), step.bytes().end(), chunks[kOperator].payload.begin());
  const StatusOr<MeshSequence> result = Decode(JoinChunks(preamble, chunks));
  ASSERT_FALSE(result.ok()) << "decoded a sequence from an infinite reference frame";
  EXPECT_EQ(result.status().code(), ErrorCode::kCorruptStream) << result.status().ToString();
}

TEST(HostileStreams, DdlPredictionIsExactForLargeFans) {
  // §9.4 defines the prediction in exact integers. A fan of 2^17 triangles around vertex 0 with
  // DDL weights at their limit (256 · 2^20 each, reachable with weight_bits = 20) makes the known
  // sum R about -2^45 (all but two of vertex 0's edges known); R · RW(e) then exceeds 2^63 in
  // 64-bit arithmetic.
  constexpr int kFan = 1 << 17;
  Triangles triangles(kFan, 3);
  for (int t = 0; t < kFan; ++t) triangles.row(t) << 0, t + 1, t + 2;
  const MeshTopology topology = BuildTopology(triangles, kFan + 2);
  const int64_t limit = int64_t{256} << 20;
  // All but the last two of vertex 0's kFan + 1 edges known, each at +limit.
  const int64_t remaining = (int64_t{1} << 20) - int64_t{kFan - 1} * limit;
  std::vector<int32_t> unknown;
  for (int k = topology.ring_offsets[1] - 2; k < topology.ring_offsets[1]; ++k) {
    unknown.push_back(topology.ring_edges[k]);
  }
  Int128 total = 0;
  for (const int32_t e : unknown) total += format::ReferenceWeight(topology, e);
  const Int128 numerator =
      static_cast<Int128>(remaining) * format::ReferenceWeight(topology, unknown.front());
  // RoundDiv in exact arithmetic: floor((2a + b) / (2b)), b > 0.
  Int128 a = 2 * numerator + total, b = 2 * total;
  Int128 exact = a / b;
  if (a % b != 0 && a < 0) --exact;
  EXPECT_EQ(static_cast<Int128>(format::PredictWeight(
                format::WeightPrediction::kReferenceProportional, remaining, topology, unknown)),
            exact);
}

TEST(HostileStreams, DdlPredictionFallsBackToUniformWhenEveryReferenceWeightIsZero) {
  // §9.4: RW(e) = ((d_i + d_j) · 2^20) div (2 · d_i · d_j) is 0 once both ends have degree above
  // 2^21. Two hubs joined by one edge, each adjacent to 2^21 + 1 vertices: the prediction of that
  // edge alone divided by Σ RW = 0 (a crash on a crafted stream); it is now the uniform one.
  constexpr int kLeaves = (1 << 21) + 1;
  Triangles triangles(kLeaves, 3);
  for (int t = 0; t < kLeaves; ++t) triangles.row(t) << 0, 1, t + 2;
  const MeshTopology topology = BuildTopology(triangles, kLeaves + 2);
  const int32_t hub_edge = topology.ring_edges[topology.ring_offsets[0]];  // edge (0, 1)
  ASSERT_EQ(topology.edges[hub_edge], (std::array<int32_t, 2>{0, 1}));
  ASSERT_EQ(format::ReferenceWeight(topology, hub_edge), 0);
  for (const int64_t remaining : {int64_t{1} << 20, int64_t{-12345}, int64_t{0}}) {
    EXPECT_EQ(format::PredictWeight(format::WeightPrediction::kReferenceProportional, remaining,
                                    topology, std::vector<int32_t>{hub_edge}),
              format::RoundDiv(remaining, 1));
  }
}

}  // namespace
}  // namespace dmc
