// The scene record (BuildGltfScene) and the GLB written around decoded motion (WriteSequence with
// WriteOptions::scene): what the record keeps and drops, node placement, clips, every encoding,
// and the five glTF samples of ../shared/data.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include "dmc/io.h"
#include "gltf_test_models.h"
#include "io/gltf_import_internal.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::GltfBuilder;
using testing::UnitTriangle;

std::filesystem::path TempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir = std::filesystem::temp_directory_path() /
                   ("dmc_gltf_scene_" + std::string(info->test_suite_name()) + "_" + info->name());
  std::filesystem::create_directories(dir);
  return dir;
}

// Two mesh nodes with a material and UVs each: "body" under a static "root" translated by
// (1, 0, 0), and "arm", which the clip "lift" moves; "slide" moves a node without a mesh. The
// asset names a copyright.
std::filesystem::path WriteTestScene(const std::filesystem::path& dir) {
  GltfBuilder builder;
  tinygltf::Model& model = builder.model;
  model.asset.copyright = "CC-BY 4.0 dmc tests";
  tinygltf::Material material;
  material.name = "skin";
  model.materials.push_back(material);
  const int body = builder.MeshNode(UnitTriangle(), {0, 1, 2}, "body");
  const int arm = builder.MeshNode({0, 0, 1, 1, 0, 1, 0, 1, 1}, {0, 1, 2}, "arm");
  for (tinygltf::Mesh& mesh : model.meshes) {
    mesh.primitives[0].material = 0;
    mesh.primitives[0].attributes["TEXCOORD_0"] =
        builder.Floats({0, 0, 1, 0, 0, 1}, TINYGLTF_TYPE_VEC2);
  }
  tinygltf::Node root;
  root.name = "root";
  root.translation = {1, 0, 0};
  root.children = {body};
  const int root_index = builder.AddNode(root);
  tinygltf::Node prop;
  prop.name = "prop";
  const int prop_index = builder.AddNode(prop);
  builder.Channel(prop_index, "translation", "LINEAR", {0, 1}, {0, 0, 0, 0, 0, 5},
                  TINYGLTF_TYPE_VEC3);
  model.animations.back().name = "slide";
  model.animations.emplace_back();
  builder.Channel(arm, "translation", "LINEAR", {0, 0.5f}, {0, 0, 0, 0, 2, 0}, TINYGLTF_TYPE_VEC3);
  model.animations.back().name = "lift";
  builder.FinishScene();
  (void)root_index;
  const auto path = dir / "scene.glb";
  tinygltf::TinyGLTF writer;
  EXPECT_TRUE(writer.WriteGltfSceneToFile(&model, path.string(), false, false, false, true));
  return path;
}

struct Imported {
  MeshSequence sequence;
  ReadReport report;
  std::vector<uint8_t> scene;
};

Imported Import(const std::filesystem::path& path, const ReadOptions& options = {}) {
  Imported out;
  auto sequence = ReadSequence(path, options, &out.report);
  EXPECT_TRUE(sequence.ok()) << sequence.status().ToString();
  out.sequence = std::move(sequence).value();
  auto scene = BuildGltfScene(path, options, out.report, out.sequence.vertex_count());
  EXPECT_TRUE(scene.ok()) << scene.status().ToString();
  out.scene = std::move(scene).value();
  return out;
}

std::set<std::string> NodeNames(const tinygltf::Model& model) {
  std::set<std::string> names;
  for (const tinygltf::Node& node : model.nodes) names.insert(node.name);
  return names;
}

TEST(GltfSceneTest, TheRecordKeepsEverythingButTheMotion) {
  const Imported imported = Import(WriteTestScene(TempDir()));
  ASSERT_FALSE(imported.scene.empty());
  auto record = io_internal::LoadGlbBytes(imported.scene, "record");
  ASSERT_TRUE(record.ok()) << record.status().ToString();
  EXPECT_EQ(record->asset.copyright, "CC-BY 4.0 dmc tests");
  EXPECT_EQ(NodeNames(*record), (std::set<std::string>{"body_node", "arm_node", "root", "prop"}));
  ASSERT_EQ(record->materials.size(), 1u);
  EXPECT_EQ(record->materials[0].name, "skin");
  for (const tinygltf::Mesh& mesh : record->meshes) {
    const auto& attributes = mesh.primitives[0].attributes;
    EXPECT_EQ(attributes.count("POSITION"), 0u);
    EXPECT_EQ(attributes.count("TEXCOORD_0"), 1u);
    EXPECT_EQ(mesh.primitives[0].material, 0);
  }
  // The node channels stay; the clips map frames back to them.
  ASSERT_EQ(record->animations.size(), 2u);
  auto clips = SceneClips(imported.scene);
  ASSERT_TRUE(clips.ok());
  ASSERT_EQ(clips->size(), 2u);
  EXPECT_EQ((*clips)[0].name, "slide");
  EXPECT_EQ((*clips)[1].name, "lift");
  EXPECT_EQ((*clips)[1].first_frame, (*clips)[0].frame_count);
  // Not a glTF input, or not a record: said so.
  EXPECT_EQ(BuildGltfScene("x.pc2", {}, {}, 3).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(SceneClips(std::vector<uint8_t>{1, 2, 3}).status().code(), ErrorCode::kParseError);
}

TEST(GltfSceneTest, TheSceneComesBackAroundTheMotionInEveryEncoding) {
  const auto dir = TempDir();
  const Imported imported = Import(WriteTestScene(dir));
  for (const char* encoding : {"compact", "quantized", "float"}) {
    SCOPED_TRACE(encoding);
    WriteOptions write;
    write.glb_encoding = encoding;
    write.scene = imported.scene;
    const auto out = dir / (std::string(encoding) + ".glb");
    const Status written = WriteSequence(imported.sequence, out, write);
    ASSERT_TRUE(written.ok()) << written.ToString();
    auto model = io_internal::LoadGltfModel(out);
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    EXPECT_EQ(model->asset.copyright, "CC-BY 4.0 dmc tests");
    EXPECT_EQ(model->materials.size(), 1u);
    EXPECT_TRUE(model->skins.empty());
    std::set<std::string> animations;
    for (const tinygltf::Animation& animation : model->animations) {
      animations.insert(animation.name);
    }
    EXPECT_EQ(animations, (std::set<std::string>{"slide", "lift"}));
    for (const tinygltf::Mesh& mesh : model->meshes) {
      const tinygltf::Primitive& primitive = mesh.primitives[0];
      ASSERT_EQ(primitive.attributes.count("TEXCOORD_0"), 1u);
      auto uvs =
          io_internal::gltf::ReadAccessor(*model, primitive.attributes.at("TEXCOORD_0"), "uv");
      ASSERT_TRUE(uvs.ok());
      EXPECT_EQ(*uvs, (std::vector<double>{0, 0, 1, 0, 0, 1}));
      // Float: the morph layout (a target per later frame). Quantised: the basis layout, whose
      // targets hold only what the node's own animation does not (here nothing).
      if (std::string(encoding) == "float") {
        EXPECT_EQ(primitive.targets.size(),
                  static_cast<size_t>(imported.sequence.frame_count() - 1));
      }
    }
    // Read back, the file poses to the decoded frames (within the compact grid).
    ReadReport report;
    auto back = ReadSequence(out, {}, &report);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    ASSERT_EQ(back->frame_count(), imported.sequence.frame_count());
    ASSERT_EQ(back->vertex_count(), imported.sequence.vertex_count());
    const BoundingBox box = ComputeBoundingBox(imported.sequence);
    // Quantised: the basis layout's bound, one grid step.
    const double tolerance = std::string(encoding) == "float"
                                 ? 1e-5
                                 : (box.max - box.min).maxCoeff() / (2 * 16383.0) * 1.01 + 1e-6;
    double worst = 0;
    for (int f = 0; f < back->frame_count(); ++f) {
      worst = std::max<double>(worst,
                               (back->frame(f) - imported.sequence.frame(f)).cwiseAbs().maxCoeff());
    }
    EXPECT_LE(worst, tolerance);
    ASSERT_EQ(report.clips.size(), 2u);
    EXPECT_EQ(report.clips[1].name, "lift");
  }
}

TEST(GltfSceneTest, OneClipAndErrors) {
  const auto dir = TempDir();
  const Imported imported = Import(WriteTestScene(dir));
  WriteOptions write;
  write.scene = imported.scene;
  write.clip = "lift";
  const auto out = dir / "lift.glb";
  ASSERT_TRUE(WriteSequence(imported.sequence, out, write).ok());
  ReadReport report;
  auto back = ReadSequence(out, {}, &report);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(report.clips.size(), 1u);
  EXPECT_EQ(report.clips[0].name, "lift");
  EXPECT_EQ(back->frame_count(), imported.report.clips[1].frame_count);

  write.clip = "dance";
  const Status unknown = WriteSequence(imported.sequence, out, write);
  EXPECT_EQ(unknown.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(unknown.message().find("slide, lift"), std::string::npos) << unknown.ToString();
  write.clip.clear();
  write.glb_layout = "frames";
  EXPECT_EQ(WriteSequence(imported.sequence, out, write).code(), ErrorCode::kInvalidArgument);
  write.glb_layout = "auto";
  write.scene = {1, 2, 3};
  EXPECT_EQ(WriteSequence(imported.sequence, out, write).code(), ErrorCode::kParseError);
  // A record for another vertex count.
  write.scene = imported.scene;
  MeshSequence other = testing::PlanarGrid(3, 2);
  EXPECT_EQ(WriteSequence(other, out, write).code(), ErrorCode::kParseError);
}

// A scene record comes from a stream: whatever it holds, writing a GLB from it either works or
// says what is wrong, and never reads or writes out of bounds.
TEST(GltfSceneTest, HostileRecordsAreRefused) {
  const auto dir = TempDir();
  const Imported imported = Import(WriteTestScene(dir));
  const auto [json, bin] = testing::SplitGlb(imported.scene);
  auto write = [&](const nlohmann::json& edited) {
    WriteOptions options;
    options.scene = testing::Glb(edited, bin);
    return WriteSequence(imported.sequence, dir / "hostile.glb", options);
  };
  ASSERT_TRUE(write(json).ok());
  {
    nlohmann::json edited = json;
    edited["accessors"][0]["bufferView"] = 100000;
    EXPECT_EQ(write(edited).code(), ErrorCode::kParseError);
  }
  {
    nlohmann::json edited = json;
    edited["bufferViews"][0]["byteLength"] = uint64_t{1} << 40;
    EXPECT_EQ(write(edited).code(), ErrorCode::kParseError);
  }
  {
    nlohmann::json edited = json;  // an instance on a node that shows another mesh
    nlohmann::json& instance = edited["extras"]["dmc_scene"]["instances"][0];
    instance["mesh"] = 1 - instance["mesh"].get<int>();
    EXPECT_EQ(write(edited).code(), ErrorCode::kParseError);
  }
  {
    nlohmann::json edited = json;  // clips that overlap
    edited["extras"]["dmc_scene"]["clips"][1]["first_frame"] = 0;
    EXPECT_EQ(write(edited).code(), ErrorCode::kParseError);
  }
  {
    nlohmann::json edited = json;
    edited["extras"]["dmc_scene"]["vertex_map"] = 1e300;
    EXPECT_EQ(write(edited).code(), ErrorCode::kParseError);
  }
  {
    nlohmann::json edited = json;
    edited["extras"]["dmc_scene"] = "not an object";
    EXPECT_EQ(write(edited).code(), ErrorCode::kParseError);
  }
  {
    nlohmann::json edited = json;  // a channel whose sampler does not exist
    edited["animations"][0]["channels"][0]["sampler"] = 99;
    const Status status = write(edited);
    EXPECT_TRUE(status.ok() || status.code() == ErrorCode::kParseError) << status.ToString();
  }
  {
    // JSON nested far deeper than any file: refused before tinygltf recurses into it.
    std::string text = json.dump();
    const std::string deep = std::string(20000, '[') + std::string(20000, ']');
    text.insert(text.size() - 1, ",\"extras\":" + deep);
    std::vector<uint8_t> glb = testing::Glb(nlohmann::json::object(), bin);
    // Glb() takes a json value; splice the raw text in instead.
    while (text.size() % 4 != 0) text.push_back(' ');
    std::vector<uint8_t> raw(glb.begin(), glb.begin() + 12);
    auto put = [&](uint32_t value) {
      for (int b = 0; b < 4; ++b) raw.push_back(static_cast<uint8_t>(value >> (8 * b)));
    };
    put(static_cast<uint32_t>(text.size()));
    put(0x4E4F534Au);
    raw.insert(raw.end(), text.begin(), text.end());
    std::vector<uint8_t> padded_bin = bin;
    while (padded_bin.size() % 4 != 0) padded_bin.push_back(0);
    put(static_cast<uint32_t>(padded_bin.size()));
    put(0x004E4942u);
    raw.insert(raw.end(), padded_bin.begin(), padded_bin.end());
    const uint32_t total = static_cast<uint32_t>(raw.size());
    std::memcpy(raw.data() + 8, &total, 4);
    WriteOptions options;
    options.scene = raw;
    const Status status = WriteSequence(imported.sequence, dir / "deep.glb", options);
    EXPECT_EQ(status.code(), ErrorCode::kParseError);
    EXPECT_NE(status.message().find("nests deeper"), std::string::npos) << status.ToString();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "deep.glb"));
}

// Every sample: its materials, textures, images, UVs, clip names and copyright survive, and the
// file read back poses to the frames it was written from.
TEST(GltfSceneTest, EverySampleKeepsItsScene) {
  for (const char* sample :
       {"cesium-man/CesiumMan.glb", "fox/Fox.glb", "threejs-horse-morph/Horse.glb",
        "robot-expressive/RobotExpressive.glb", "brainstem/BrainStem.glb"}) {
    SCOPED_TRACE(sample);
    DMC_REQUIRE_SHARED_DATA(path, sample);
    // The two large samples are cut to their first frames (their clips' node animations then
    // outlast the frames, so only the scene is compared).
    const bool whole = std::string(sample).find("Robot") == std::string::npos &&
                       std::string(sample).find("BrainStem") == std::string::npos;
    ReadOptions options;
    if (!whole) options.max_frames = 12;
    const Imported imported = Import(path, options);
    auto original = io_internal::LoadGltfModel(path);
    ASSERT_TRUE(original.ok());
    const auto out = TempDir() / "sample.glb";
    WriteOptions write;
    write.scene = imported.scene;
    const Status written = WriteSequence(imported.sequence, out, write);
    ASSERT_TRUE(written.ok()) << written.ToString();
    auto model = io_internal::LoadGltfModel(out);
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    EXPECT_EQ(model->asset.copyright, original->asset.copyright);
    EXPECT_EQ(model->materials.size(), original->materials.size());
    EXPECT_EQ(model->textures.size(), original->textures.size());
    EXPECT_EQ(model->images.size(), original->images.size());
    for (const std::string& name : NodeNames(*original)) {
      EXPECT_EQ(NodeNames(*model).count(name), 1u) << "node " << name;
    }
    if (!whole) continue;
    ReadReport report;
    auto back = ReadSequence(out, {}, &report);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->frame_count(), imported.sequence.frame_count());
    const BoundingBox box = ComputeBoundingBox(imported.sequence);
    double worst = 0;
    for (int f = 0; f < back->frame_count(); ++f) {
      worst = std::max<double>(worst,
                               (back->frame(f) - imported.sequence.frame(f)).cwiseAbs().maxCoeff());
    }
    // The basis layout's bound: one grid step.
    EXPECT_LE(worst, (box.max - box.min).maxCoeff() / (2 * 16383.0) * 1.01 + 1e-6 * box.diagonal());
    EXPECT_EQ(back->vertex_count(), imported.sequence.vertex_count());
    ASSERT_EQ(report.clips.size(), imported.report.clips.size());
    for (size_t c = 0; c < report.clips.size(); ++c) {
      EXPECT_EQ(report.clips[c].name, imported.report.clips[c].name);
    }
  }
}

}  // namespace
}  // namespace dmc
