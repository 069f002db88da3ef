// The baseline codecs of `dmc sweep`: exact or bounded reconstruction, input vertex order restored,
// the Draco stream identical to what draco::Encoder writes, rate growing with the bits, and
// damaged streams rejected without crashing.
#include "sweep/baselines.h"

#include <draco/compression/encode.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "dmc/synth.h"
#include "test_support.h"

namespace dmc::sweep {
namespace {

// A small animated closed mesh with irregular valences (the walker at its coarsest).
const MeshSequence& Walker() {
  static const MeshSequence sequence = [] {
    SynthOptions options;
    options.frames = 6;
    options.resolution = 300;
    return *Synthesize("walker", options);
  }();
  return sequence;
}

// Largest per-coordinate difference between two comparable sequences.
double MaxCoordinateError(const MeshSequence& a, const MeshSequence& b) {
  double error = 0.0;
  for (size_t i = 0; i < a.position_value_count(); ++i) {
    error = std::max(error, std::abs(static_cast<double>(a.data()[i]) - b.data()[i]));
  }
  return error;
}

StatusOr<MeshSequence> RoundTrip(BaselineKind kind, const MeshSequence& sequence, int bits) {
  DMC_ASSIGN_OR_RETURN(const BaselineStream stream, EncodeBaseline(kind, sequence, bits));
  DMC_ASSIGN_OR_RETURN(const MeshSequence decoded, DecodeBaseline(kind, stream.bytes));
  return RestoreInputOrder(decoded, stream.input_vertex);
}

class EveryBaseline : public ::testing::TestWithParam<BaselineKind> {};

TEST_P(EveryBaseline, DecodesToTheInputOrderWithinHalfAQuantisationStep) {
  const MeshSequence& input = Walker();
  const int bits = 12;
  const StatusOr<MeshSequence> output = RoundTrip(GetParam(), input, bits);
  ASSERT_TRUE(output.ok()) << output.status().ToString();
  // Same vertices and the same oriented triangles, vertex for vertex.
  ASSERT_TRUE(CheckComparable(input, *output).ok()) << CheckComparable(input, *output).ToString();
  // Draco quantises each frame over its own box, the others over the sequence's box: both steps
  // are at most the sequence box's largest extent / (2^bits − 1). Rounding to the nearest level
  // errs by half a step; the slack covers float32 storage of the result.
  const BoundingBox box = ComputeBoundingBox(input);
  const double step = (box.max - box.min).maxCoeff() / ((1 << bits) - 1);
  EXPECT_LE(MaxCoordinateError(input, *output), 0.5 * step + 1e-5);
  EXPECT_GT(MaxCoordinateError(input, *output), 0.0);  // it is lossy at 12 bits
}

TEST_P(EveryBaseline, RateGrowsWithTheQuantisationBits) {
  uint64_t previous = 0;
  for (const int bits : {8, 12, 16}) {
    const StatusOr<BaselineStream> stream = EncodeBaseline(GetParam(), Walker(), bits);
    ASSERT_TRUE(stream.ok()) << stream.status().ToString();
    EXPECT_GT(stream->bytes.size(), previous) << bits << " bits";
    previous = stream->bytes.size();
  }
}

TEST_P(EveryBaseline, EveryTruncationIsRejected) {
  const StatusOr<BaselineStream> stream = EncodeBaseline(GetParam(), Walker(), 10);
  ASSERT_TRUE(stream.ok());
  const std::vector<uint8_t>& bytes = stream->bytes;
  // Every prefix up to 64 bytes, then a spread of longer ones (decoding each is cheap).
  for (size_t size = 0; size < bytes.size(); size += size < 64 ? 1 : bytes.size() / 37 + 1) {
    const StatusOr<MeshSequence> decoded =
        DecodeBaseline(GetParam(), std::span<const uint8_t>(bytes.data(), size));
    EXPECT_FALSE(decoded.ok()) << "prefix of " << size << " of " << bytes.size() << " bytes";
  }
}

TEST_P(EveryBaseline, RejectsBitsOutsideItsRange) {
  for (const int bits : {kMinBaselineBits - 1, kMaxBaselineBits + 1}) {
    const StatusOr<BaselineStream> stream = EncodeBaseline(GetParam(), Walker(), bits);
    ASSERT_FALSE(stream.ok());
    EXPECT_EQ(stream.status().code(), ErrorCode::kInvalidArgument);
  }
}

INSTANTIATE_TEST_SUITE_P(Baselines, EveryBaseline,
                         ::testing::Values(BaselineKind::kDraco, BaselineKind::kMeshopt,
                                           BaselineKind::kZstd),
                         [](const auto& info) { return std::string(BaselineName(info.param)); });

TEST(ZstdBaseline, PositionsOnTheGridComeBackExactly) {
  // Coordinates 0..255 in whole units: the 8-bit grid over the box [0, 255]³ has step 1, so
  // quantisation is exact and the frame differences reproduce every frame bit for bit.
  MeshSequence sequence = testing::PlanarGrid(16, 3);
  for (int f = 0; f < 3; ++f) {
    for (int v = 0; v < sequence.vertex_count(); ++v) {
      sequence.frame(f).row(v) << static_cast<float>(v), static_cast<float>((v * 7 + f) % 256),
          static_cast<float>(255 - v);
    }
  }
  const StatusOr<MeshSequence> output = RoundTrip(BaselineKind::kZstd, sequence, 8);
  ASSERT_TRUE(output.ok()) << output.status().ToString();
  EXPECT_EQ(MaxCoordinateError(sequence, *output), 0.0);
  EXPECT_EQ(output->triangles(), sequence.triangles());
}

TEST(DracoBaseline, EachFrameIsExactlyWhatDracoEncoderWrites) {
  // The baseline drives Draco's edgebreaker encoder directly (to learn its vertex order); its
  // frames must be byte for byte those of the public draco::Encoder with speed 0.
  const MeshSequence& sequence = Walker();
  const int bits = 11;
  const StatusOr<BaselineStream> stream = EncodeBaseline(BaselineKind::kDraco, sequence, bits);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();

  draco::Mesh mesh;
  mesh.set_num_points(static_cast<uint32_t>(sequence.vertex_count()));
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false,
                3 * sizeof(float), 0);
  const int id = mesh.AddAttribute(position, true, static_cast<uint32_t>(sequence.vertex_count()));
  for (int v = 0; v < sequence.vertex_count(); ++v) {
    mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(v),
                                          sequence.frame(0).row(v).data());
  }
  for (int t = 0; t < sequence.triangle_count(); ++t) {
    mesh.AddFace({draco::PointIndex(static_cast<uint32_t>(sequence.triangles()(t, 0))),
                  draco::PointIndex(static_cast<uint32_t>(sequence.triangles()(t, 1))),
                  draco::PointIndex(static_cast<uint32_t>(sequence.triangles()(t, 2)))});
  }
  draco::Encoder encoder;
  encoder.SetSpeedOptions(0, 0);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  draco::EncoderBuffer buffer;
  ASSERT_TRUE(encoder.EncodeMeshToBuffer(mesh, &buffer).ok());

  // The stream is varint frame count, then per frame varint size and the Draco buffer.
  const std::vector<uint8_t>& bytes = stream->bytes;
  ASSERT_EQ(bytes[0], sequence.frame_count());
  size_t offset = 1, size = 0;
  for (int shift = 0;; shift += 7) {
    size |= static_cast<size_t>(bytes[offset] & 0x7F) << shift;
    if ((bytes[offset++] & 0x80) == 0) break;
  }
  ASSERT_EQ(size, buffer.size());
  EXPECT_EQ(std::vector<uint8_t>(bytes.begin() + offset, bytes.begin() + offset + size),
            std::vector<uint8_t>(reinterpret_cast<const uint8_t*>(buffer.data()),
                                 reinterpret_cast<const uint8_t*>(buffer.data()) + buffer.size()));
}

TEST(DracoBaseline, NonManifoldVertexIsUnsupported) {
  // Two triangles touching at vertex 0 only (a bow tie): Draco splits vertex 0, so its output has
  // more vertices than the input and cannot be compared vertex for vertex.
  Triangles triangles(2, 3);
  triangles << 0, 1, 2, 0, 3, 4;
  MeshSequence sequence(5, triangles, 2);
  for (int f = 0; f < 2; ++f) {
    sequence.frame(f) << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, static_cast<float>(f);
  }
  const StatusOr<BaselineStream> stream = EncodeBaseline(BaselineKind::kDraco, sequence, 10);
  ASSERT_FALSE(stream.ok());
  EXPECT_EQ(stream.status().code(), ErrorCode::kUnsupported) << stream.status().ToString();
}

TEST(RestoreInputOrder, AppliesThePermutationToPositionsAndTriangles) {
  MeshSequence decoded = testing::Tetrahedron(2);
  const std::vector<int32_t> input_vertex = {2, 0, 3, 1};  // decoded i is input input_vertex[i]
  const StatusOr<MeshSequence> restored = RestoreInputOrder(decoded, input_vertex);
  ASSERT_TRUE(restored.ok());
  for (int f = 0; f < 2; ++f) {
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(restored->frame(f).row(input_vertex[i]), decoded.frame(f).row(i));
    }
  }
  EXPECT_EQ(restored->triangles()(0, 0), input_vertex[decoded.triangles()(0, 0)]);
  EXPECT_EQ(restored->triangles()(3, 2), input_vertex[decoded.triangles()(3, 2)]);
}

TEST(RestoreInputOrder, RejectsWhatIsNotAPermutation) {
  const MeshSequence decoded = testing::Tetrahedron();
  for (const std::vector<int32_t>& order :
       std::vector<std::vector<int32_t>>{{0, 1, 2}, {0, 1, 2, 2}, {0, 1, 2, 4}, {-1, 0, 1, 2}}) {
    const StatusOr<MeshSequence> restored = RestoreInputOrder(decoded, order);
    ASSERT_FALSE(restored.ok());
    EXPECT_EQ(restored.status().code(), ErrorCode::kMismatch);
  }
}

TEST(ParseBaseline, KnowsTheThreeNamesAndListsThemOtherwise) {
  for (const BaselineKind kind : AllBaselines()) {
    const StatusOr<BaselineKind> parsed = ParseBaseline(BaselineName(kind));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, kind);
  }
  const StatusOr<BaselineKind> unknown = ParseBaseline("gzip");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(unknown.status().message().find("draco, meshopt, zstd"), std::string::npos);
}

}  // namespace
}  // namespace dmc::sweep
