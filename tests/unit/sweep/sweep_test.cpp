// RunSweep: ladders, points measured exactly as a separate encode/decode/measure would, rates
// consistent with the bytes, progress reported, unusable codecs skipped with a warning.
#include "sweep/sweep.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/synth.h"

namespace dmc::sweep {
namespace {

using ::testing::HasSubstr;

const MeshSequence& Walker() {
  static const MeshSequence sequence = [] {
    SynthOptions options;
    options.frames = 6;
    options.resolution = 300;
    return *Synthesize("walker", options);
  }();
  return sequence;
}

TEST(Ladders, SpreadTheRungsEvenly) {
  SweepOptions options;
  const std::vector<double> bits = ResidualBitsLadder(options);
  ASSERT_EQ(bits.size(), 8u);
  EXPECT_EQ(bits.front(), 5.0);
  EXPECT_NEAR(bits[1], 5.0 + 11.0 / 7.0, 1e-12);
  EXPECT_EQ(bits.back(), 16.0);
  // 8 + k · 8/7 rounded: 9.14 → 9, 12.57 → 13 (12 is skipped), …
  EXPECT_EQ(BaselineBitsLadder(options), (std::vector<int>{8, 9, 10, 11, 13, 14, 15, 16}));
  options.points = 20;  // more rungs than distinct integers: duplicates go
  EXPECT_EQ(BaselineBitsLadder(options).size(), 9u);
}

TEST(Ladders, AnExplicitLadderReplacesTheEvenOneForDmcOnly) {
  SweepOptions options;
  options.ladder = {12.0, 7.5, 12.0, 9.0};
  EXPECT_EQ(ResidualBitsLadder(options), (std::vector<double>{7.5, 9.0, 12.0}));
  EXPECT_EQ(BaselineBitsLadder(options).size(), 8u);  // still spaced by points
  EXPECT_TRUE(ValidateSweepOptions(options).ok());
  options.ladder = {10.0, 0.5};
  const Status status = ValidateSweepOptions(options);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("--ladder rungs must be in [1, 30], got 0.5"));
}

TEST(Ladders, BasisBitsFollowTheRungUnlessFixed) {
  EXPECT_EQ(BasisBitsFor(5.0, 0), 10);
  EXPECT_EQ(BasisBitsFor(13.4, 0), 13);
  EXPECT_EQ(BasisBitsFor(13.6, 0), 14);
  EXPECT_EQ(BasisBitsFor(24.0, 0), 16);
  EXPECT_EQ(BasisBitsFor(24.0, 7), 7);
}

TEST(ValidateSweepOptions, NamesTheBadField) {
  const auto message = [](SweepOptions options) {
    const Status status = ValidateSweepOptions(options);
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
    return status.message();
  };
  SweepOptions options;
  EXPECT_TRUE(ValidateSweepOptions(options).ok());
  options.points = 1;
  EXPECT_THAT(message(options), HasSubstr("--points"));
  options = SweepOptions();
  options.min_residual_bits = 12;
  options.max_residual_bits = 10;
  EXPECT_THAT(message(options), HasSubstr("residual bits"));
  options = SweepOptions();
  options.basis_bits = 1;
  EXPECT_THAT(message(options), HasSubstr("--basis-bits"));
  options = SweepOptions();
  options.effort = 10;
  EXPECT_THAT(message(options), HasSubstr("--effort"));
  options = SweepOptions();
  options.max_baseline_bits = 17;
  EXPECT_THAT(message(options), HasSubstr("baseline bits"));
  options = SweepOptions();
  options.operators.clear();
  options.baselines.clear();
  EXPECT_THAT(message(options), HasSubstr("nothing to sweep"));
  options = SweepOptions();
  options.sted.window = 0;
  EXPECT_FALSE(ValidateSweepOptions(options).ok());
}

TEST(SetEncoderOption, SetsTableOptionsByNameAndRefusesTheRest) {
  EncoderOptions options;
  EXPECT_TRUE(SetEncoderOption(&options, "rank_threshold=100").ok());
  EXPECT_EQ(options.rank_threshold, 100.0);
  EXPECT_TRUE(SetEncoderOption(&options, "anchors=25").ok());
  EXPECT_EQ(options.anchors, 25);
  EXPECT_TRUE(SetEncoderOption(&options, "residual_rdo_lambda=0.125").ok());
  EXPECT_EQ(options.residual_rdo_lambda, 0.125);
  EXPECT_TRUE(SetEncoderOption(&options, "rank_search=off").ok());
  EXPECT_FALSE(options.rank_search);
  const auto message = [&](std::string_view setting) {
    const Status status = SetEncoderOption(&options, setting);
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument) << setting;
    return status.message();
  };
  EXPECT_THAT(message("anchors"), HasSubstr("NAME=VALUE"));
  EXPECT_THAT(message("anchors=2.5"), HasSubstr("an integer"));
  EXPECT_THAT(message("anchor_step_ratio=x"), HasSubstr("a number"));
  EXPECT_THAT(message("rank_search=maybe"), HasSubstr("true or false"));
  EXPECT_THAT(message("no_such_option=1"), HasSubstr("no encoder option"));
  EXPECT_THAT(message("effort=3"), HasSubstr("sets effort itself"));
  EXPECT_THAT(message("residual_step=0.1"), HasSubstr("sets residual_step itself"));
  EXPECT_EQ(options.anchors, 25);  // refused settings change nothing
  SweepOptions sweep;
  ASSERT_TRUE(SetEncoderOption(&sweep.encoder, "weight_bits=40").ok());
  EXPECT_THAT(ValidateSweepOptions(sweep).message(), HasSubstr("weight_bits"));
}

TEST(RunSweep, PointsAreWhatASeparateEncodeDecodeAndMeasureGives) {
  SweepOptions options;
  options.operators = {"tutte"};
  options.baselines = {BaselineKind::kZstd};
  options.points = 3;
  std::vector<int> done_counts;
  int last_total = 0;
  const StatusOr<SweepResult> result = RunSweep(
      Walker(), options, [&](const RdPoint* point, const std::string&, int done, int total) {
        EXPECT_NE(point, nullptr);
        done_counts.push_back(done);
        last_total = total;
      });
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_TRUE(result->warnings.empty());
  ASSERT_EQ(result->points.size(), 6u);
  EXPECT_EQ(done_counts, (std::vector<int>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(last_total, 6);

  const double vertex_frames =
      static_cast<double>(Walker().vertex_count()) * Walker().frame_count();
  for (size_t i = 0; i < result->points.size(); ++i) {
    const RdPoint& point = result->points[i];
    EXPECT_EQ(point.Curve(), i < 3 ? "dmc/tutte" : "zstd");
    EXPECT_DOUBLE_EQ(point.bpfv, 8.0 * static_cast<double>(point.bytes) / vertex_frames);
    if (i % 3 > 0) {
      EXPECT_GT(point.bpfv, result->points[i - 1].bpfv);  // finer rung, more bits
      EXPECT_LT(point.sted, result->points[i - 1].sted);  // and less distortion
    }
  }
  EXPECT_EQ(result->points[3].residual_bits, 8.0);  // baseline rungs: 8, 12, 16 bits
  EXPECT_EQ(result->points[5].residual_bits, 16.0);

  // The middle dmc rung (10.5 residual bits) encoded on its own, as `dmc encode --residual-step`
  // would: the same bytes and the same metrics as the encoder's own closed-loop measurement.
  const RdPoint& middle = result->points[1];
  EXPECT_EQ(middle.residual_bits, 10.5);
  EXPECT_EQ(middle.basis_bits, 11);  // BasisBitsFor rounds 10.5 half away from zero
  EncoderOptions encoder_options;
  encoder_options.operator_name = "tutte";
  encoder_options.residual_step =
      std::max(ComputeBoundingBox(Walker()).diagonal(), 1e-12) * std::exp2(-10.5);
  encoder_options.basis_bits = 11;
  EncodeReport report;
  const StatusOr<std::vector<uint8_t>> bytes = Encode(Walker(), encoder_options, &report);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_EQ(bytes->size(), middle.bytes);
  EXPECT_EQ(report.rank, middle.rank);
  // The per-element bytes and the operators are the encoder's report, and cover the stream.
  EXPECT_EQ(middle.residual_bytes, report.residual_bytes);
  EXPECT_EQ(middle.basis_bytes, report.basis_bytes);
  EXPECT_EQ(middle.header_bytes + middle.connectivity_bytes + middle.mean_bytes +
                middle.basis_bytes + middle.operator_bytes + middle.anchor_bytes +
                middle.residual_bytes,
            middle.bytes);
  EXPECT_EQ(middle.segments, report.segments);
  EXPECT_EQ(middle.segment_operators, "tutte:" + std::to_string(report.segments));
  EXPECT_EQ(result->points[3].residual_bytes, 0u);  // a baseline codec's point has none
  ASSERT_TRUE(report.measured);
  EXPECT_DOUBLE_EQ(report.distortion.kg, middle.kg);
  EXPECT_DOUBLE_EQ(report.distortion.sted, middle.sted);
}

// The encoder's effort reaches every dmc rung: a rung is what `dmc encode --effort` gives.
TEST(RunSweep, RungsAreEncodedAtTheRequestedEffort) {
  for (const int effort : {0, 8}) {
    SweepOptions options;
    options.operators = {"ddl"};
    options.baselines.clear();
    options.points = 2;
    options.effort = effort;
    const StatusOr<SweepResult> result =
        RunSweep(Walker(), options, [](const RdPoint*, const std::string&, int, int) {});
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    ASSERT_EQ(result->points.size(), 2u);
    const RdPoint& coarse = result->points[0];
    EncoderOptions encoder_options;
    encoder_options.effort = effort;
    encoder_options.residual_step =
        std::max(ComputeBoundingBox(Walker()).diagonal(), 1e-12) * std::exp2(-coarse.residual_bits);
    encoder_options.basis_bits = coarse.basis_bits;
    encoder_options.measure = false;
    const StatusOr<std::vector<uint8_t>> bytes = Encode(Walker(), encoder_options);
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    EXPECT_EQ(bytes->size(), coarse.bytes) << "effort " << effort;
  }
}

TEST(RunSweep, UnknownOperatorFailsBeforeAnyWork) {
  SweepOptions options;
  options.operators = {"tutte", "cotangent-typo"};
  int calls = 0;
  const StatusOr<SweepResult> result =
      RunSweep(Walker(), options, [&](const RdPoint*, const std::string&, int, int) { ++calls; });
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(calls, 0);
}

TEST(RunSweep, ACodecThatCannotHandleTheInputIsSkippedWithAWarning) {
  // A bow tie (two triangles sharing one vertex): Draco splits the vertex, the other baseline
  // does not care. The sweep goes on without Draco and says why.
  Triangles triangles(2, 3);
  triangles << 0, 1, 2, 0, 3, 4;
  MeshSequence sequence(5, triangles, 3);
  for (int f = 0; f < 3; ++f) {
    sequence.frame(f) << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0.1f * static_cast<float>(f);
  }
  SweepOptions options;
  options.operators.clear();
  options.baselines = {BaselineKind::kDraco, BaselineKind::kZstd};
  options.points = 2;
  std::vector<int> totals;
  const StatusOr<SweepResult> result = RunSweep(
      sequence, options,
      [&](const RdPoint*, const std::string&, int, int total) { totals.push_back(total); });
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->warnings.size(), 1u);
  EXPECT_THAT(result->warnings[0], HasSubstr("draco skipped: unsupported"));
  ASSERT_EQ(result->points.size(), 2u);
  EXPECT_EQ(result->points[0].codec, "zstd");
  EXPECT_EQ(totals, (std::vector<int>{2, 2, 2}));  // 4 planned, Draco's 2 dropped at once
}

}  // namespace
}  // namespace dmc::sweep
