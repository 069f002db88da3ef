// StreamingDistortion (metrics/streaming_distortion.h) against the in-memory DistortionMeter:
// every figure must be bit for bit equal whatever the segmentation, because both run the same
// accumulation code in the same summation order. The segments are copied into buffers holding
// exactly OriginalWindow's frames, so a read outside the documented window is caught under the
// sanitizers.
#include "metrics/streaming_distortion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "dmc/metrics.h"
#include "test_support.h"

namespace dmc {
namespace {

// A 20×20 grid (400 vertices: two temporal blocks of 256, the second partial) under a travelling
// wave; its first `resting_rows` rows never move, so with dt = 0 their te is 0 in A.
MeshSequence WavingGrid(int frames, int resting_rows = 0) {
  constexpr int kSide = 20;
  MeshSequence sequence = testing::PlanarGrid(kSide, frames);
  for (int f = 0; f < frames; ++f) {
    for (int v = resting_rows * kSide; v < kSide * kSide; ++v) {
      const float x = sequence.frame(f)(v, 0);
      const float y = sequence.frame(f)(v, 1);
      sequence.frame(f)(v, 2) = 0.2f * std::sin(6.0f * x + 0.3f * static_cast<float>(f)) * y;
      sequence.frame(f)(v, 0) = x + 0.01f * static_cast<float>(f);
    }
  }
  return sequence;
}

// `original` with deterministic noise of amplitude `amplitude` on every coordinate, except the
// first `resting_vertices` vertices, which are left exactly as they are.
MeshSequence Noisy(const MeshSequence& original, float amplitude, int resting_vertices = 0) {
  MeshSequence distorted = original;
  std::mt19937 generator(12345);
  std::uniform_real_distribution<float> noise(-amplitude, amplitude);
  for (int f = 0; f < distorted.frame_count(); ++f) {
    for (int v = resting_vertices; v < distorted.vertex_count(); ++v) {
      for (int k = 0; k < 3; ++k) distorted.frame(f)(v, k) += noise(generator);
    }
  }
  return distorted;
}

// Measures `distorted` against `original` with StreamingDistortion, segment lengths taken in turn
// from `lengths` (cycled) until the sequence ends.
StatusOr<DistortionReport> MeasureStreaming(const MeshSequence& original,
                                            const MeshSequence& distorted,
                                            const std::vector<int>& lengths,
                                            const StedOptions& options = {}) {
  const int frames = original.frame_count();
  const size_t frame_values = static_cast<size_t>(original.vertex_count()) * 3;
  DMC_ASSIGN_OR_RETURN(StreamingDistortion meter,
                       StreamingDistortion::Create(original.triangles(), original.vertex_count(),
                                                   frames, original.data(), options));
  for (int f = 0; f < frames; ++f) meter.AddOriginalFrame(original.data() + f * frame_values);
  DMC_RETURN_IF_ERROR(meter.FinishOriginal());
  size_t next_length = 0;
  for (int first = 0; first < frames;) {
    const int count = std::min(lengths[next_length++ % lengths.size()], frames - first);
    const auto [window_first, window_end] = meter.OriginalWindow(first, count);
    const std::vector<float> original_window(original.data() + window_first * frame_values,
                                             original.data() + window_end * frame_values);
    const std::vector<float> decoded(distorted.data() + first * frame_values,
                                     distorted.data() + (first + count) * frame_values);
    DMC_RETURN_IF_ERROR(meter.AddSegment(first, count, original_window.data(), decoded.data()));
    first += count;
  }
  return meter.Report();
}

void ExpectIdentical(const DistortionReport& streamed, const DistortionReport& memory) {
  EXPECT_EQ(streamed.kg, memory.kg);
  EXPECT_EQ(streamed.sted, memory.sted);
  EXPECT_EQ(streamed.sted_s, memory.sted_s);
  EXPECT_EQ(streamed.sted_t, memory.sted_t);
  EXPECT_EQ(streamed.rmse_rel, memory.rmse_rel);
  EXPECT_EQ(streamed.max_error, memory.max_error);
  EXPECT_EQ(streamed.frames, memory.frames);
  EXPECT_EQ(streamed.vertices, memory.vertices);
}

void ExpectSameAsInMemory(const MeshSequence& original, const MeshSequence& distorted,
                          const StedOptions& options) {
  const auto memory = MeasureDistortion(original, distorted, options);
  ASSERT_TRUE(memory.ok()) << memory.status().ToString();
  for (const std::vector<int>& lengths : std::vector<std::vector<int>>{
           {original.frame_count()}, {1}, {7}, {3, 10, 1, 2}, {original.frame_count() - 1, 1}}) {
    SCOPED_TRACE("first segment length " + std::to_string(lengths.front()));
    const auto streamed = MeasureStreaming(original, distorted, lengths, options);
    ASSERT_TRUE(streamed.ok()) << streamed.status().ToString();
    ExpectIdentical(*streamed, *memory);
  }
}

TEST(StreamingDistortion, EqualsInMemoryMeterForEverySegmentationAndWindow) {
  const MeshSequence original = WavingGrid(30);
  const MeshSequence distorted = Noisy(original, 1e-3f);
  // s = 1, the default 5, and a window wider than the sequence (capped at F).
  for (const int window : {1, 5, 100}) {
    SCOPED_TRACE("window " + std::to_string(window));
    StedOptions options;
    options.window = window;
    ExpectSameAsInMemory(original, distorted, options);
  }
}

TEST(StreamingDistortion, EqualsInMemoryMeterForOtherWidths) {
  const MeshSequence original = WavingGrid(12);
  const MeshSequence distorted = Noisy(original, 5e-3f);
  for (const int width : {0, 2}) {
    SCOPED_TRACE("width " + std::to_string(width));
    StedOptions options;
    options.width = width;
    ExpectSameAsInMemory(original, distorted, options);
  }
}

TEST(StreamingDistortion, EqualsInMemoryMeterWhenTermsAreUndefined) {
  // dt = 0 and rows at rest in both sequences: their temporal terms are 0/0 and skipped.
  const int resting_rows = 3;
  const MeshSequence original = WavingGrid(16, resting_rows);
  const MeshSequence distorted = Noisy(original, 1e-3f, resting_rows * 20);
  StedOptions options;
  options.dt = 0.0;
  ExpectSameAsInMemory(original, distorted, options);
  const auto memory = MeasureDistortion(original, distorted, options);
  ASSERT_TRUE(memory.ok());
  EXPECT_TRUE(std::isfinite(memory->sted_t));

  // A zero-length edge in some frames of A: avg(v) is NaN for the vertices that see it.
  MeshSequence collapsed = WavingGrid(10);
  for (int f = 2; f < 6; ++f) collapsed.frame(f).row(1) = collapsed.frame(f).row(0);
  ExpectSameAsInMemory(collapsed, Noisy(collapsed, 1e-3f), StedOptions{});
}

TEST(StreamingDistortion, SingleFrameHasNoTemporalPart) {
  const MeshSequence original = WavingGrid(1);
  const MeshSequence distorted = Noisy(original, 1e-2f);
  const auto streamed = MeasureStreaming(original, distorted, {1});
  ASSERT_TRUE(streamed.ok()) << streamed.status().ToString();
  EXPECT_EQ(streamed->sted_t, 0.0);
  EXPECT_GT(streamed->sted_s, 0.0);
  ExpectIdentical(*streamed, *MeasureDistortion(original, distorted));
}

TEST(StreamingDistortion, OriginalWindowReachesTheSpeedWindowBeyondTheSegment) {
  const MeshSequence original = WavingGrid(30);
  StedOptions options;
  options.window = 4;
  auto meter = StreamingDistortion::Create(original.triangles(), original.vertex_count(), 30,
                                           original.data(), options);
  ASSERT_TRUE(meter.ok()) << meter.status().ToString();
  EXPECT_EQ(meter->OriginalWindow(0, 10), std::make_pair(0, 14));
  EXPECT_EQ(meter->OriginalWindow(10, 10), std::make_pair(6, 24));
  EXPECT_EQ(meter->OriginalWindow(20, 10), std::make_pair(16, 30));
}

TEST(StreamingDistortion, UndefinedMetricsFailAsTheInMemoryMeterDoes) {
  // Frame 0 a single point, later frames not: D = 0, STED_t undefined.
  MeshSequence point_first = WavingGrid(3);
  point_first.frame(0).setZero();
  const auto memory = MeasureDistortion(point_first, point_first);
  ASSERT_FALSE(memory.ok());
  const auto streamed = MeasureStreaming(point_first, point_first, {3});
  ASSERT_FALSE(streamed.ok());
  EXPECT_EQ(streamed.status().code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(streamed.status().message(), memory.status().message());

  // Every frame a single point: KG undefined (D = 0 is fine with one frame).
  MeshSequence point = WavingGrid(1);
  point.frame(0).setConstant(1.0f);
  const auto memory_point = MeasureDistortion(point, point);
  ASSERT_FALSE(memory_point.ok());
  const auto streamed_point = MeasureStreaming(point, point, {1});
  ASSERT_FALSE(streamed_point.ok());
  EXPECT_EQ(streamed_point.status().code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(streamed_point.status().message(), memory_point.status().message());
}

TEST(StreamingDistortion, RejectsMisuseAndNonFiniteDecodedFrames) {
  const MeshSequence original = WavingGrid(4);
  const size_t frame_values = static_cast<size_t>(original.vertex_count()) * 3;
  auto meter = StreamingDistortion::Create(original.triangles(), original.vertex_count(), 4,
                                           original.data());
  ASSERT_TRUE(meter.ok()) << meter.status().ToString();
  EXPECT_EQ(meter->FinishOriginal().code(), ErrorCode::kInternal);  // no frame added yet
  for (int f = 0; f < 4; ++f) meter->AddOriginalFrame(original.data() + f * frame_values);
  ASSERT_TRUE(meter->FinishOriginal().ok());

  EXPECT_EQ(meter->AddSegment(1, 1, original.data(), original.data()).code(),
            ErrorCode::kInvalidArgument);                            // does not start at frame 0
  EXPECT_EQ(meter->Report().status().code(), ErrorCode::kInternal);  // nothing measured yet

  std::vector<float> decoded(original.data(), original.data() + 2 * frame_values);
  decoded[frame_values + 3 * 7 + 2] = std::numeric_limits<float>::quiet_NaN();
  const Status non_finite = meter->AddSegment(0, 2, original.data(), decoded.data());
  EXPECT_EQ(non_finite.code(), ErrorCode::kInvalidSequence);
  EXPECT_EQ(non_finite.message(), "distorted: frame 1, vertex 7: coordinate z is not finite");

  EXPECT_EQ(
      StreamingDistortion::Create(original.triangles(), original.vertex_count(), 0, original.data())
          .status()
          .code(),
      ErrorCode::kInvalidSequence);
  StedOptions bad;
  bad.window = 0;
  EXPECT_EQ(StreamingDistortion::Create(original.triangles(), original.vertex_count(), 4,
                                        original.data(), bad)
                .status()
                .code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dmc
