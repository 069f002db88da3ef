// EncoderOptions::effort: every level encodes a stream the decoder reads, the levels' search plans
// grow as they rise, the exhaustive level searches every operator at every rank,
// the bytes do not depend on the thread count at any level, and an effort out of range or a
// switch the effort would not honour is refused with a message naming the option.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <string>
#include <vector>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/encoder_options.h"
#include "dmc/synth.h"
#include "dmc/wire_ids.h"
#include "encoder/search_plan.h"

namespace dmc {
namespace {

// Two segments of 12 frames, so segments are encoded concurrently as well as searched.
MeshSequence Walker() {
  SynthOptions options;
  options.frames = 24;
  options.resolution = 1200;
  return *Synthesize("walker", options);
}

EncoderOptions AtEffort(int effort) {
  EncoderOptions options;
  options.effort = effort;
  options.segment_frames = 12;
  return options;
}

TEST(Effort, EveryLevelEncodesAStreamTheDecoderReads) {
  const MeshSequence original = Walker();
  for (int effort = 0; effort <= kMaxEffort; ++effort) {
    EncodeReport report;
    auto bytes = Encode(original, AtEffort(effort), &report);
    ASSERT_TRUE(bytes.ok()) << "effort " << effort << ": " << bytes.status().ToString();
    ASSERT_TRUE(report.measured);
    auto decoded = Decode(*bytes);
    ASSERT_TRUE(decoded.ok()) << "effort " << effort << ": " << decoded.status().ToString();
    EXPECT_EQ(decoded->frame_count(), original.frame_count());
    EXPECT_EQ(decoded->vertex_count(), original.vertex_count());
    auto measured = MeasureDistortion(original, *decoded);
    ASSERT_TRUE(measured.ok());
    // The report is the decoder's output measured: the same at every level.
    EXPECT_DOUBLE_EQ(measured->sted, report.distortion.sted) << "effort " << effort;
    EXPECT_LT(report.distortion.sted, 0.2) << "effort " << effort;
  }
}

// The default rank and operator switches leave the search to the effort; turning them off gives
// the one-pass encode at every level.
TEST(Effort, SwitchesOffGiveTheOnePassAtEveryLevel) {
  const MeshSequence original = Walker();
  auto one_pass = Encode(original, AtEffort(0));
  ASSERT_TRUE(one_pass.ok());
  for (const int effort : {1, 5, kMaxEffort}) {
    EncoderOptions options = AtEffort(effort);
    options.ddl_fallback = false;
    auto bytes = Encode(original, options);
    ASSERT_TRUE(bytes.ok());
    EXPECT_EQ(*bytes, *one_pass) << "effort " << effort;
  }
  // Effort 0 with the switches' defaults is the one pass with them off.
  EncoderOptions off = AtEffort(0);
  off.rank_search = false;
  off.ddl_fallback = false;
  auto explicit_off = Encode(original, off);
  ASSERT_TRUE(explicit_off.ok());
  EXPECT_EQ(*explicit_off, *one_pass);
}

// Below kRankSearchEffort the rank is the threshold's; rank_search = false gives the same bytes
// there, and at every level for a fixed rank.
TEST(Effort, NoRankSearchBelowItsLevelNorForAFixedRank) {
  const MeshSequence original = Walker();
  for (int effort = 0; effort < kRankSearchEffort; ++effort) {
    EncoderOptions options = AtEffort(effort);
    auto searched = Encode(original, options);
    options.rank_search = false;
    auto plain = Encode(original, options);
    ASSERT_TRUE(searched.ok() && plain.ok());
    EXPECT_EQ(*searched, *plain) << "effort " << effort;
  }
  for (const int effort : {kRankSearchEffort, 5, kMaxEffort}) {
    EncoderOptions options = AtEffort(effort);
    options.rank = 4;
    auto searched = Encode(original, options);
    options.rank_search = false;
    auto plain = Encode(original, options);
    ASSERT_TRUE(searched.ok() && plain.ok());
    EXPECT_EQ(*searched, *plain) << "effort " << effort;
  }
}

TEST(Effort, BytesDoNotDependOnTheThreadCount) {
  const MeshSequence original = Walker();
  for (const int effort : {0, 2, 5, 8, 9}) {
    EncoderOptions options = AtEffort(effort);
    options.measure = false;
    std::vector<uint8_t> bytes[2];
    for (const int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      auto encoded = Encode(original, options);
      ASSERT_TRUE(encoded.ok()) << encoded.status().ToString();
      bytes[threads - 1] = std::move(encoded).value();
    }
    EXPECT_EQ(bytes[0], bytes[1]) << "effort " << effort;
  }
}

// The levels search more as they rise, as RD.md's table says: nothing at 0, the fallback from 1,
// the rank search from 2 (and at every level above), the exhaustive search at 8 (every operator at
// every rank, refitted, 32 frames, nothing pruned; no level below measures more frames) and every
// frame at 9. (What each level costs in time is a benchmark's: BM_EncodeEffort in
// tests/bench/bench_codec.cpp.)
TEST(Effort, SearchGrowsWithTheLevel) {
  std::vector<SearchPlan> plans;
  for (int effort = 0; effort <= kMaxEffort; ++effort) {
    plans.push_back(PlanSearch(AtEffort(effort), OperatorId::kDdl));
  }
  EXPECT_EQ(plans[0].rank_scales.size(), 1u);
  EXPECT_FALSE(plans[0].fallback);
  EXPECT_TRUE(plans[kFallbackEffort].fallback);
  EXPECT_EQ(plans[kFallbackEffort].rank_scales.size(), 1u);
  // One rank above the threshold's (a quarter of it) and two below, the highest rank first.
  EXPECT_EQ(plans[kRankSearchEffort].rank_scales, (std::vector<double>{0.25, 1.0, 2.0, 4.0}));
  const SearchPlan& exhaustive = plans[8];
  EXPECT_TRUE(exhaustive.fallback && exhaustive.operators_at_every_rank &&
              exhaustive.refit_at_every_rank);
  EXPECT_EQ(exhaustive.measured_frames, 32);
  EXPECT_EQ(exhaustive.prune_sted_ratio, 0.0);
  EXPECT_GT(plans[kMaxEffort].measured_frames, exhaustive.measured_frames);
  for (int effort = 1; effort <= kMaxEffort; ++effort) {
    EXPECT_GE(plans[effort].rank_scales.size(), plans[effort - 1].rank_scales.size()) << effort;
    if (effort < 8) {
      EXPECT_LE(plans[effort].measured_frames, exhaustive.measured_frames) << effort;
    }
  }
  // The switches restrict every level: no fallback and no rank search without the fallback.
  EncoderOptions no_fallback = AtEffort(8);
  no_fallback.ddl_fallback = false;
  EXPECT_FALSE(PlanSearch(no_fallback, OperatorId::kDdl).fallback);
  EXPECT_EQ(PlanSearch(no_fallback, OperatorId::kDdl).rank_scales.size(), 1u);
}

TEST(Effort, OutOfRangeIsRefusedNamingTheOption) {
  const MeshSequence original = Walker();
  for (const int effort : {-1, kMaxEffort + 1}) {
    EncoderOptions options;
    options.effort = effort;
    const Status status = ValidateOptions(options);
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(status.message(), "effort must be in [0, 9], got " + std::to_string(effort));
    EXPECT_EQ(ValidateOptions(options, OptionSpelling::kCliFlag).message(),
              "--effort must be in [0, 9], got " + std::to_string(effort));
    EXPECT_EQ(Encode(original, options).status().code(), ErrorCode::kInvalidArgument);
  }
}

// A switch the caller named true asks for a search; below its level that is an error, not a
// silently ignored request. Named false, or not named, it is never an error.
TEST(Effort, NamedSwitchesTheLevelWouldIgnoreAreRefused) {
  EncoderOptions options;
  options.effort = 0;
  const std::vector<std::string> both = {"rank_search", "ddl_fallback"};
  const Status fallback = CheckGivenSwitches(options, both);
  EXPECT_EQ(fallback.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(fallback.message(),
            "ddl_fallback asks for a search that effort 0 does not do (it does from 1 up)");
  options.effort = kRankSearchEffort - 1;
  const Status rank = CheckGivenSwitches(options, both, OptionSpelling::kCliFlag);
  EXPECT_EQ(rank.message(), "--rank-search asks for a search that --effort " +
                                std::to_string(kRankSearchEffort - 1) +
                                " does not do (it does from " + std::to_string(kRankSearchEffort) +
                                " up)");
  options.effort = kRankSearchEffort;
  EXPECT_TRUE(CheckGivenSwitches(options, both).ok());
  options.effort = 0;
  EXPECT_TRUE(CheckGivenSwitches(options, {}).ok());
  options.rank_search = false;
  options.ddl_fallback = false;
  EXPECT_TRUE(CheckGivenSwitches(options, both).ok());
}

}  // namespace
}  // namespace dmc
