// GLB export: both layouts hold every frame, normals are unit length, the size rule picks the
// smaller file, and WriteSequence/ReadSequence round-trip a sequence through a .glb.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "dmc/io.h"
#include "gltf_test_models.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::TempFile;

using io_internal::GlbEncoding;
using io_internal::GlbLayout;

// These tests check exact float values: the float32 encoding (gltf_compact_test.cpp covers the
// compact ones).
StatusOr<std::vector<uint8_t>> FloatGlb(const MeshSequence& sequence, GlbLayout layout) {
  return io_internal::EncodeGlb(sequence, layout, GlbEncoding::kFloat);
}

// A 5×5 grid waving over 6 frames at 25 fps.
MeshSequence WavingGrid() {
  MeshSequence sequence = testing::PlanarGrid(5, 6);
  for (int f = 0; f < 6; ++f) {
    for (int v = 0; v < sequence.vertex_count(); ++v) {
      sequence.frame(f)(v, 2) = 0.1f * static_cast<float>(f) * sequence.frame(f)(v, 0);
    }
  }
  sequence.frame_rate = 25.0;
  sequence.name = "grid";
  return sequence;
}

tinygltf::Model LoadBack(const std::vector<uint8_t>& glb, const std::string& name) {
  const auto path = TempFile(name);
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(glb.data()), static_cast<std::streamsize>(glb.size()));
  auto model = io_internal::LoadGltfModel(path);
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return std::move(model).value();
}

// A tightly packed float accessor's values.
std::vector<float> AccessorFloats(const tinygltf::Model& model, int index) {
  const tinygltf::Accessor& accessor = model.accessors[static_cast<size_t>(index)];
  const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(accessor.bufferView)];
  const size_t count =
      accessor.count * static_cast<size_t>(tinygltf::GetNumComponentsInType(accessor.type));
  std::vector<float> values(count);
  std::memcpy(values.data(), model.buffers[0].data.data() + view.byteOffset + accessor.byteOffset,
              count * sizeof(float));
  return values;
}

TEST(GltfExportTest, MorphLayoutPlaysBackEveryFrame) {
  const MeshSequence sequence = WavingGrid();
  auto glb = FloatGlb(sequence, GlbLayout::kMorph);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  const tinygltf::Model model = LoadBack(*glb, "morph.glb");
  ASSERT_EQ(model.meshes.size(), 1u);
  EXPECT_EQ(model.meshes[0].primitives[0].targets.size(), 5u);
  ASSERT_EQ(model.animations.size(), 1u);
  EXPECT_EQ(model.asset.extras.Get("dmc").Get("layout").Get<std::string>(), "morph");
  EXPECT_EQ(model.asset.extras.Get("dmc").Get("frames").Get<int>(), 6);
  // Posing the file at its frame rate gives the frames back (up to float rounding of the
  // frame-0-relative targets).
  GltfReadOptions options;
  options.frame_rate = 25.0;
  auto posed = io_internal::PoseGltfModel(model, options);
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  ASSERT_EQ(posed->sequence.frame_count(), 6);
  for (int f = 0; f < 6; ++f) {
    EXPECT_LT((posed->sequence.frame(f) - sequence.frame(f)).cwiseAbs().maxCoeff(), 1e-6f)
        << "frame " << f;
  }
  // Unit normals: the grid is flat in frame 0, so every normal is ±z.
  const auto normals = AccessorFloats(model, model.meshes[0].primitives[0].attributes.at("NORMAL"));
  for (size_t v = 0; v < normals.size() / 3; ++v) {
    EXPECT_NEAR(std::abs(normals[3 * v + 2]), 1.0f, 1e-6f);
  }
}

TEST(GltfExportTest, FramesLayoutHoldsOneExactMeshPerFrame) {
  const MeshSequence sequence = WavingGrid();
  auto glb = FloatGlb(sequence, GlbLayout::kFrames);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  const tinygltf::Model model = LoadBack(*glb, "frames.glb");
  ASSERT_EQ(model.meshes.size(), 6u);
  EXPECT_EQ(model.asset.extras.Get("dmc").Get("layout").Get<std::string>(), "frames");
  ASSERT_EQ(model.animations.size(), 1u);
  EXPECT_EQ(model.animations[0].channels.size(), 6u);
  for (int f = 0; f < 6; ++f) {
    const auto positions = AccessorFloats(
        model, model.meshes[static_cast<size_t>(f)].primitives[0].attributes.at("POSITION"));
    ASSERT_EQ(positions.size(), 75u);
    EXPECT_EQ(0, std::memcmp(positions.data(), sequence.frame(f).data(), 75 * sizeof(float)));
  }
  // The frame nodes' scale keys: frame 2 is shown from t = 2/25 s to t = 3/25 s.
  const tinygltf::AnimationSampler& sampler = model.animations[0].samplers[2];
  const auto times = AccessorFloats(model, sampler.input);
  const auto scales = AccessorFloats(model, sampler.output);
  EXPECT_EQ(times, (std::vector<float>{0.0f, 2.0f / 25, 3.0f / 25}));
  EXPECT_EQ(scales, (std::vector<float>{0, 0, 0, 1, 1, 1, 0, 0, 0}));
}

TEST(GltfExportTest, AutoLayoutIsTheSmallerFile) {
  for (int frames : {2, 40}) {
    MeshSequence sequence = testing::PlanarGrid(4, frames);
    const auto morph = FloatGlb(sequence, GlbLayout::kMorph);
    const auto stepped = FloatGlb(sequence, GlbLayout::kFrames);
    const auto chosen = FloatGlb(sequence, GlbLayout::kAuto);
    ASSERT_TRUE(morph.ok() && stepped.ok() && chosen.ok());
    EXPECT_EQ(chosen->size(), std::min(morph->size(), stepped->size())) << frames << " frames";
  }
}

TEST(GltfExportTest, WriteAndReadSequenceRoundTripThroughGlb) {
  const MeshSequence sequence = WavingGrid();
  const auto path = TempFile("grid.glb");
  WriteOptions write;
  write.glb_layout = "morph";
  write.glb_encoding = "float";
  ASSERT_TRUE(WriteSequence(sequence, path, write).ok());
  ReadOptions read;
  read.gltf.frame_rate = 25.0;
  ReadReport report;
  auto back = ReadSequence(path, read, &report);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->name, "grid");
  EXPECT_EQ(back->frame_rate, 25.0);
  EXPECT_TRUE(CheckComparable(sequence, *back).ok());
  EXPECT_EQ(report.vertex_map.size(), 25u);
  for (int f = 0; f < 6; ++f) {
    EXPECT_LT((back->frame(f) - sequence.frame(f)).cwiseAbs().maxCoeff(), 1e-6f);
  }
  write.glb_layout = "sideways";
  EXPECT_EQ(WriteSequence(sequence, path, write).code(), ErrorCode::kInvalidArgument);
}

// glTF key times are float32, so the last frame's time is F − 1 frame periods only to within
// float rounding: an exported sequence must read back with its own frame count at its recorded
// rate (59 frames at 30 fps once came back as 58).
TEST(GltfExportTest, EveryFrameCountReadsBackAtTheRecordedRate) {
  const auto path = TempFile("count.glb");
  for (const double fps : {24.0, 25.0, 29.97, 30.0, 60.0}) {
    for (int frames = 2; frames <= 90; ++frames) {
      MeshSequence sequence = testing::PlanarGrid(3, frames);
      sequence.frame_rate = fps;
      WriteOptions write;
      write.glb_layout = "morph";
      ASSERT_TRUE(WriteSequence(sequence, path, write).ok());
      auto back = ReadSequence(path);
      ASSERT_TRUE(back.ok()) << back.status().ToString();
      EXPECT_EQ(back->frame_count(), frames) << fps << " fps";
    }
  }
}

TEST(GltfExportTest, SingleFrameHasNoAnimation) {
  auto glb = FloatGlb(testing::Tetrahedron(1), GlbLayout::kMorph);
  ASSERT_TRUE(glb.ok());
  const tinygltf::Model model = LoadBack(*glb, "tetrahedron.glb");
  EXPECT_TRUE(model.animations.empty());
  EXPECT_TRUE(model.meshes[0].primitives[0].targets.empty());
}

TEST(GltfExportTest, NotGltfIsAParseError) {
  const auto path = TempFile("junk.glb");
  std::ofstream(path) << "this is not a GLB";
  EXPECT_EQ(ReadSequence(path).status().code(), ErrorCode::kParseError);
}

}  // namespace
}  // namespace dmc
