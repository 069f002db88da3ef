// Long segments (kLongSegmentFrames frames or more) pay for more side information by default:
// EncoderOptions::weight_bits 0 chooses the DDL weight step per segment, 2^-8 for long segments
// and 2^-7 below, and the automatic anchor count is 2 % of the vertices instead of 1 %. Values set
// are used for every segment. The segment header carries both, and every choice decodes.
#include <gtest/gtest.h>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/encoder_options.h"
#include "dmc/synth.h"
#include "encoder/anchors.h"

namespace dmc {
namespace {

TEST(WeightBits, AutomaticFollowsTheSegmentLength) {
  EncoderOptions options;
  ASSERT_EQ(options.weight_bits, 0);
  EXPECT_EQ(SegmentWeightBits(options, kLongSegmentFrames - 1), 7);
  EXPECT_EQ(SegmentWeightBits(options, kLongSegmentFrames), 8);
  EXPECT_EQ(SegmentWeightBits(options, 4096), 8);
  options.weight_bits = 5;
  EXPECT_EQ(SegmentWeightBits(options, 4096), 5);
  EXPECT_EQ(SegmentWeightBits(options, 1), 5);
}

TEST(AnchorCount, AutomaticDoublesInLongSegments) {
  EncoderOptions options;
  ASSERT_EQ(options.anchors, -1);
  EXPECT_EQ(RequestedAnchorCount(options, 10000, kLongSegmentFrames - 1), 100);
  EXPECT_EQ(RequestedAnchorCount(options, 10000, kLongSegmentFrames), 200);
  EXPECT_EQ(RequestedAnchorCount(options, 30, kLongSegmentFrames), 1);          // at least one
  EXPECT_EQ(RequestedAnchorCount(options, 1000000, kLongSegmentFrames), 1000);  // the cap
  options.anchors = 7;
  EXPECT_EQ(RequestedAnchorCount(options, 10000, kLongSegmentFrames), 7);
}

TEST(WeightBits, TheStreamCarriesEachSegmentsStep) {
  SynthOptions synth;
  synth.frames = kLongSegmentFrames + 4;
  synth.resolution = 300;
  const MeshSequence original = *Synthesize("twist", synth);
  struct Case {
    int weight_bits, segment_frames, expected;
  };
  for (const Case c : {Case{0, 0, 8}, Case{0, 66, 7}, Case{6, 0, 6}}) {
    EncoderOptions options;
    options.ddl_fallback = false;  // every segment keeps the DDL and its weights
    options.weight_bits = c.weight_bits;
    options.segment_frames = c.segment_frames;
    const auto stream = Encode(original, options);
    ASSERT_TRUE(stream.ok()) << stream.status().ToString();
    const auto info = ReadStreamInfo(*stream);
    ASSERT_TRUE(info.ok()) << info.status().ToString();
    for (const SegmentInfo& segment : info->segments) {
      EXPECT_EQ(segment.operator_name, "ddl");
      EXPECT_EQ(segment.weight_bits, c.expected)
          << "weight_bits " << c.weight_bits << ", segment of " << segment.frame_count;
      // 1 % of the vertices, 2 % in a long segment (the twist is one component: no extra anchor).
      const bool long_segment = segment.frame_count >= kLongSegmentFrames;
      EXPECT_GE(
          segment.anchor_count,
          RequestedAnchorCount(EncoderOptions(), original.vertex_count(), segment.frame_count))
          << "segment of " << segment.frame_count;
      EXPECT_EQ(long_segment, c.segment_frames == 0);
    }
    EXPECT_TRUE(Decode(*stream).ok());
  }
}

TEST(WeightBits, OutOfRangeIsRefused) {
  for (const int bad : {-1, 1, 21}) {
    EncoderOptions options;
    options.weight_bits = bad;
    const Status status = ValidateOptions(options);
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument) << bad;
    EXPECT_NE(status.message().find("weight_bits"), std::string::npos) << status.ToString();
  }
}

}  // namespace
}  // namespace dmc
