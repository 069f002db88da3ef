// The encoder never writes what the decoder rejects (issue 21): every value it writes is checked
// against the format's limits, and what cannot be coded is refused as kUnsupported with the
// remedy; quantisation follows the sequence's own scale, so a tiny or huge but codable input
// keeps its quality; a sequence of one point (all vertices coincide) encodes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/metrics.h"
#include "dmc/synth.h"

namespace dmc {
namespace {

MeshSequence Blob() {
  SynthOptions options;
  options.frames = 12;
  options.resolution = 300;
  StatusOr<MeshSequence> blob = Synthesize("blob", options);
  EXPECT_TRUE(blob.ok()) << blob.status().ToString();
  return std::move(blob).value();
}

MeshSequence Scaled(const MeshSequence& sequence, double scale) {
  MeshSequence scaled = sequence;
  for (int f = 0; f < scaled.frame_count(); ++f) {
    scaled.frame(f) = (sequence.frame(f).cast<double>() * scale).cast<float>();
  }
  return scaled;
}

// Every vertex of every frame at `point`.
MeshSequence OnePoint(const Eigen::RowVector3f& point) {
  MeshSequence sequence = Blob();
  for (int f = 0; f < sequence.frame_count(); ++f) sequence.frame(f).rowwise() = point;
  return sequence;
}

// Encodes (measuring unless `measure` is off) and decodes, failing the test on any error.
MeshSequence RoundTrip(const MeshSequence& sequence, bool measure, EncodeReport* report) {
  EncoderOptions options;
  options.measure = measure;
  StatusOr<std::vector<uint8_t>> stream = Encode(sequence, options, report);
  EXPECT_TRUE(stream.ok()) << stream.status().ToString();
  if (!stream.ok()) return MeshSequence();
  StatusOr<MeshSequence> decoded = Decode(*stream);
  EXPECT_TRUE(decoded.ok()) << decoded.status().ToString();
  return decoded.ok() ? std::move(decoded).value() : MeshSequence();
}

TEST(EncoderLimits, OnePointSequencesEncodeAndDecodeToThatPoint) {
  for (const Eigen::RowVector3f& point :
       {Eigen::RowVector3f(0, 0, 0), Eigen::RowVector3f(5, -5, 2.5f),
        Eigen::RowVector3f(1e-30f, 3e20f, -7)}) {
    SCOPED_TRACE(::testing::Message() << "point " << point);
    const MeshSequence original = OnePoint(point);
    for (const bool measure : {true, false}) {
      EncodeReport report;
      const MeshSequence decoded = RoundTrip(original, measure, &report);
      ASSERT_EQ(decoded.frame_count(), original.frame_count());
      // KG and STED are undefined for a point: not measured, but decoded and checked.
      EXPECT_FALSE(report.measured);
      EXPECT_EQ(report.not_measured_reason.empty(), !measure) << report.not_measured_reason;
      const double tolerance = std::ldexp(point.cwiseAbs().maxCoeff(), -24);
      for (int f = 0; f < decoded.frame_count(); ++f) {
        const double error = (decoded.frame(f).cast<double>() - original.frame(f).cast<double>())
                                 .cwiseAbs()
                                 .maxCoeff();
        EXPECT_LE(error, tolerance) << "frame " << f;
      }
    }
  }
}

// From 1e-20 to 1e20 the quantisation is relative to the sequence's own size: the same stream
// size and KG as at scale 1 (at 1e-15 the step used to stop at 9.77e-16, the rank drop to 0 and
// KG reach 100 %).
TEST(EncoderLimits, QualityDoesNotDependOnTheScale) {
  const MeshSequence blob = Blob();
  EncodeReport unit;
  RoundTrip(blob, true, &unit);
  ASSERT_TRUE(unit.measured);
  ASSERT_LT(unit.distortion.kg, 5.0);
  for (const double scale : {1e-20, 1e-15, 1e-10, 1e-5, 1e5, 1e10, 1e15, 1e20}) {
    SCOPED_TRACE(::testing::Message() << "scale " << scale);
    EncodeReport report;
    const MeshSequence decoded = RoundTrip(Scaled(blob, scale), true, &report);
    ASSERT_TRUE(report.measured);
    EXPECT_EQ(report.rank, unit.rank);
    EXPECT_NEAR(report.distortion.kg, unit.distortion.kg, 0.05 * unit.distortion.kg);
    EXPECT_NEAR(static_cast<double>(report.bytes), static_cast<double>(unit.bytes),
                0.02 * static_cast<double>(unit.bytes));
  }
}

// Beyond what the format's steps (at most 2^64) can carry: refused, naming the step and the
// remedy, with or without measuring (the stream used to be written and rejected by the decoder).
TEST(EncoderLimits, CoordinatesBeyondTheStepLimitAreRefusedWithTheRemedy) {
  const MeshSequence blob = Blob();
  for (const double scale : {1e24, 1e30, 1e37}) {
    for (const bool measure : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "scale " << scale << " measure " << measure);
      EncoderOptions options;
      options.measure = measure;
      const StatusOr<std::vector<uint8_t>> stream = Encode(Scaled(blob, scale), options);
      ASSERT_FALSE(stream.ok());
      EXPECT_EQ(stream.status().code(), ErrorCode::kUnsupported) << stream.status().ToString();
      EXPECT_NE(stream.status().message().find("the residual step"), std::string::npos)
          << stream.status().message();
      EXPECT_NE(stream.status().message().find("rescale the input"), std::string::npos)
          << stream.status().message();
    }
  }
  // The largest codable diagonal at 10 residual bits is 2^74 (about 1.9e22): just below it
  // encodes.
  EXPECT_TRUE(RoundTrip(Scaled(blob, 4e21), false, nullptr).frame_count() > 0);
}

// A flat sequence far from the origin: the mean's step grows with its magnitude (its values must
// stay within 2^52 steps) while that keeps it finer than the residual step; farther, refused.
TEST(EncoderLimits, FlatSequencesFarFromTheOriginEncodeOrAreRefused) {
  MeshSequence plane = Blob();
  for (int f = 0; f < plane.frame_count(); ++f) plane.frame(f).col(2).setConstant(1e12f);
  EncodeReport report;
  const MeshSequence decoded = RoundTrip(plane, true, &report);
  ASSERT_TRUE(report.measured);
  EXPECT_LT(report.distortion.kg, 5.0);

  for (int f = 0; f < plane.frame_count(); ++f) plane.frame(f).col(2).setConstant(1e17f);
  const StatusOr<std::vector<uint8_t>> far = Encode(plane, EncoderOptions());
  ASSERT_FALSE(far.ok());
  EXPECT_EQ(far.status().code(), ErrorCode::kUnsupported) << far.status().ToString();
  EXPECT_NE(far.status().message().find("translate the input nearer the origin"), std::string::npos)
      << far.status().message();
}

}  // namespace
}  // namespace dmc
