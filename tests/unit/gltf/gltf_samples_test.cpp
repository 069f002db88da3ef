// The glTF samples of ../shared/data (skipped when absent): every one imports with the vertex and
// triangle counts its README documents, moves, honours mesh selection and welding; CesiumMan's
// skin posed with identity joint matrices reproduces its bind mesh; and a CesiumMan clip survives
// import → encode → decode → GLB export → import.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "dmc/io.h"
#include "dmc/metrics.h"
#include "io/gltf_format.h"
#include "test_support.h"

namespace dmc {
namespace {

struct Sample {
  const char* path;
  int vertices;
  int triangles;
};

// Counts from ../shared/data/README.md.
const Sample kSamples[] = {
    {"cesium-man/CesiumMan.glb", 3273, 4672},
    {"fox/Fox.glb", 1728, 576},
    {"threejs-horse-morph/Horse.glb", 796, 984},
    {"robot-expressive/RobotExpressive.glb", 7214, 3237},
    {"brainstem/BrainStem.glb", 34159, 61666},
};

double LargestMotion(const MeshSequence& sequence) {
  double largest = 0.0;
  for (int f = 1; f < sequence.frame_count(); ++f) {
    largest = std::max(largest, static_cast<double>(
                                    (sequence.frame(f) - sequence.frame(0)).cwiseAbs().maxCoeff()));
  }
  return largest;
}

TEST(GltfSamplesTest, EverySampleImportsAndMoves) {
  for (const Sample& sample : kSamples) {
    DMC_REQUIRE_SHARED_DATA(path, sample.path);
    ReadOptions options;
    options.gltf.frame_rate = 10.0;
    options.max_frames = 8;
    ReadReport report;
    auto sequence = ReadSequence(path, options, &report);
    ASSERT_TRUE(sequence.ok()) << sample.path << ": " << sequence.status().ToString();
    EXPECT_EQ(sequence->vertex_count(), sample.vertices) << sample.path;
    EXPECT_EQ(sequence->triangle_count(), sample.triangles) << sample.path;
    EXPECT_EQ(sequence->frame_count(), 8) << sample.path;
    EXPECT_EQ(sequence->frame_rate, 10.0);
    EXPECT_EQ(report.vertex_map.size(), static_cast<size_t>(sample.vertices));
    const double diagonal = ComputeBoundingBox(*sequence).diagonal();
    EXPECT_GT(LargestMotion(*sequence), 1e-3 * diagonal) << sample.path << " does not move";
  }
}

TEST(GltfSamplesTest, FrameCountFollowsTheClip) {
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  DMC_REQUIRE_SHARED_DATA(horse, "threejs-horse-morph/Horse.glb");
  ReadOptions options;
  options.gltf.frame_rate = 24.0;
  // CesiumMan's keys run from 1/24 s to 2 s: 47 intervals at 24 fps.
  EXPECT_EQ(ReadSequence(cesium, options)->frame_count(), 48);
  // The horse's weights run from 0 to 1.5 s: at 10 fps 16 frames.
  options.gltf.frame_rate = 10.0;
  EXPECT_EQ(ReadSequence(horse, options)->frame_count(), 16);
}

TEST(GltfSamplesTest, MeshAndAnimationSelection) {
  DMC_REQUIRE_SHARED_DATA(robot, "robot-expressive/RobotExpressive.glb");
  ReadOptions options;
  options.gltf.frame_rate = 10.0;
  options.max_frames = 3;
  options.gltf.mesh = "Head";  // three primitives with morph targets
  options.gltf.animation = "Wave";
  auto head = ReadSequence(robot, options);
  ASSERT_TRUE(head.ok()) << head.status().ToString();
  auto model = io_internal::LoadGltfModel(robot);
  ASSERT_TRUE(model.ok());
  int head_vertices = 0;
  for (const auto& mesh : model->meshes) {
    if (mesh.name != "Head") continue;
    ASSERT_EQ(mesh.primitives.size(), 3u);
    for (const auto& primitive : mesh.primitives) {
      head_vertices += static_cast<int>(
          model->accessors[static_cast<size_t>(primitive.attributes.at("POSITION"))].count);
    }
  }
  EXPECT_EQ(head->vertex_count(), head_vertices);
  options.gltf.animation = "Moonwalk";
  EXPECT_EQ(ReadSequence(robot, options).status().code(), ErrorCode::kInvalidArgument);
}

TEST(GltfSamplesTest, WeldingTheFoxSoupKeepsEveryPosition) {
  DMC_REQUIRE_SHARED_DATA(fox, "fox/Fox.glb");
  ReadOptions options;
  options.gltf.frame_rate = 10.0;
  options.max_frames = 5;
  auto soup = ReadSequence(fox, options);
  ASSERT_TRUE(soup.ok());
  options.gltf.weld = true;
  ReadReport report;
  auto welded = ReadSequence(fox, options, &report);
  ASSERT_TRUE(welded.ok()) << welded.status().ToString();
  // Every triangle had its own three vertices; shared corners now merge.
  EXPECT_LT(welded->vertex_count(), soup->vertex_count() / 2);
  ASSERT_EQ(report.vertex_map.size(), static_cast<size_t>(soup->vertex_count()));
  const float tolerance = 1e-5f * static_cast<float>(ComputeBoundingBox(*soup).diagonal());
  for (int f = 0; f < 5; ++f) {
    for (int v = 0; v < soup->vertex_count(); ++v) {
      const int w = report.vertex_map[static_cast<size_t>(v)];
      ASSERT_LT((welded->frame(f).row(w) - soup->frame(f).row(v)).cwiseAbs().maxCoeff(), tolerance);
    }
  }
}

TEST(GltfSamplesTest, CesiumManWithIdentityJointsIsItsBindMesh) {
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  auto loaded = io_internal::LoadGltfModel(cesium);
  ASSERT_TRUE(loaded.ok());
  tinygltf::Model model = std::move(loaded).value();
  const tinygltf::Skin& skin = model.skins.at(0);
  // Inverse bind matrices, then every joint's local matrix chosen so that its global matrix is
  // the inverse of its inverse bind matrix: the joint matrices global · inverseBind are identity.
  const tinygltf::Accessor& ibm_accessor =
      model.accessors[static_cast<size_t>(skin.inverseBindMatrices)];
  const tinygltf::BufferView& ibm_view =
      model.bufferViews[static_cast<size_t>(ibm_accessor.bufferView)];
  std::vector<Eigen::Matrix4d> bind_globals;
  for (size_t j = 0; j < skin.joints.size(); ++j) {
    Eigen::Matrix4f ibm;
    std::memcpy(
        ibm.data(),
        model.buffers[0].data.data() + ibm_view.byteOffset + ibm_accessor.byteOffset + 64 * j, 64);
    bind_globals.push_back(ibm.cast<double>().inverse());
  }
  std::vector<int> parent(model.nodes.size(), -1);
  for (size_t n = 0; n < model.nodes.size(); ++n) {
    for (int child : model.nodes[n].children)
      parent[static_cast<size_t>(child)] = static_cast<int>(n);
  }
  auto local = [](const tinygltf::Node& node) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (node.matrix.size() == 16)
      return Eigen::Matrix4d(Eigen::Map<const Eigen::Matrix4d>(node.matrix.data()));
    Eigen::Affine3d t = Eigen::Affine3d::Identity();
    if (node.translation.size() == 3)
      t.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4)
      t.rotate(Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1],
                                  node.rotation[2]));
    if (node.scale.size() == 3)
      t.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
    m = t.matrix();
    return m;
  };
  // Globals of the unmodified hierarchy above the joints, then joints get their bind globals.
  std::function<Eigen::Matrix4d(int)> global = [&](int n) -> Eigen::Matrix4d {
    const auto joint = std::find(skin.joints.begin(), skin.joints.end(), n);
    if (joint != skin.joints.end())
      return bind_globals[static_cast<size_t>(joint - skin.joints.begin())];
    const Eigen::Matrix4d own = local(model.nodes[static_cast<size_t>(n)]);
    return parent[static_cast<size_t>(n)] < 0
               ? own
               : Eigen::Matrix4d(global(parent[static_cast<size_t>(n)]) * own);
  };
  std::vector<std::vector<double>> new_matrices;
  for (int joint : skin.joints) {
    const int p = parent[static_cast<size_t>(joint)];
    const Eigen::Matrix4d parent_global = p < 0 ? Eigen::Matrix4d::Identity() : global(p);
    const Eigen::Matrix4d wanted = parent_global.inverse() * global(joint);
    new_matrices.emplace_back(wanted.data(), wanted.data() + 16);
  }
  for (size_t j = 0; j < skin.joints.size(); ++j) {
    tinygltf::Node& node = model.nodes[static_cast<size_t>(skin.joints[j])];
    node.translation.clear();
    node.rotation.clear();
    node.scale.clear();
    node.matrix = new_matrices[j];
  }
  model.animations.clear();
  GltfReadOptions options;
  auto posed = io_internal::PoseGltfModel(model, options);
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  const auto& primitive = model.meshes[0].primitives[0];
  const tinygltf::Accessor& positions =
      model.accessors[static_cast<size_t>(primitive.attributes.at("POSITION"))];
  const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(positions.bufferView)];
  const size_t stride = view.byteStride ? view.byteStride : 12;
  ASSERT_EQ(posed->sequence.vertex_count(), static_cast<int>(positions.count));
  const double diagonal = ComputeBoundingBox(posed->sequence).diagonal();
  double worst = 0.0;
  for (size_t v = 0; v < positions.count; ++v) {
    float bind[3];
    std::memcpy(bind,
                model.buffers[0].data.data() + view.byteOffset + positions.byteOffset + v * stride,
                12);
    for (int axis = 0; axis < 3; ++axis) {
      worst = std::max(
          worst, std::abs(static_cast<double>(posed->sequence.frame(0)(static_cast<int>(v), axis)) -
                          bind[axis]));
    }
  }
  EXPECT_LT(worst, 1e-5 * diagonal);
}

TEST(GltfSamplesTest, CesiumManRoundTripsThroughTheCodecAndGlb) {
  DMC_REQUIRE_SHARED_DATA(cesium, "cesium-man/CesiumMan.glb");
  ReadOptions read;
  read.gltf.frame_rate = 12.0;
  read.max_frames = 12;
  auto original = ReadSequence(cesium, read);
  ASSERT_TRUE(original.ok()) << original.status().ToString();
  EncoderOptions encode;
  encode.measure = false;
  auto stream = Encode(*original, encode);
  ASSERT_TRUE(stream.ok()) << stream.status().ToString();
  auto decoded = Decode(*stream);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  ASSERT_TRUE(CheckComparable(*original, *decoded).ok());
  auto kg = KgError(*original, *decoded);
  ASSERT_TRUE(kg.ok());
  EXPECT_LT(*kg, 5.0);  // the codec's defaults: a fraction of a percent on real meshes

  const auto dir = std::filesystem::temp_directory_path() / "dmc_gltf_cesium_round_trip";
  std::filesystem::create_directories(dir);
  for (const char* layout : {"morph", "frames"}) {
    const auto path = dir / (std::string(layout) + ".glb");
    WriteOptions write;
    write.glb_layout = layout;
    ASSERT_TRUE(WriteSequence(*decoded, path, write).ok());
    auto model = io_internal::LoadGltfModel(path);
    ASSERT_TRUE(model.ok()) << layout;
    EXPECT_EQ(model->asset.extras.Get("dmc").Get("layout").Get<std::string>(), layout);
  }
  // Both layouts read back as the decoded frames, at the frame rate the export recorded.
  for (const char* layout : {"morph", "frames"}) {
    auto back = ReadSequence(dir / (std::string(layout) + ".glb"));
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->frame_rate, 12.0) << layout;
    ASSERT_TRUE(CheckComparable(*decoded, *back).ok()) << layout;
    // The compact GLB's grid: half of 1/32766 of the largest extent (over every frame).
    const BoundingBox box = ComputeBoundingBox(*decoded);
    const float tolerance = static_cast<float>(
        (box.max - box.min).maxCoeff() / (4 * 16383.0) * 1.001 + 1e-6 * box.diagonal());
    for (int f = 0; f < decoded->frame_count(); ++f) {
      EXPECT_LT((back->frame(f) - decoded->frame(f)).cwiseAbs().maxCoeff(), tolerance) << f;
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(GltfSamplesTest, EveryClipIsReadWithItsName) {
  DMC_REQUIRE_SHARED_DATA(fox, "fox/Fox.glb");
  ReadReport report;
  auto sequence = ReadSequence(fox, {}, &report);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  ASSERT_EQ(report.clips.size(), 3u);
  EXPECT_EQ(report.clips[0].name, "Survey");
  EXPECT_EQ(report.clips[1].name, "Walk");
  EXPECT_EQ(report.clips[2].name, "Run");
  int frames = 0;
  for (const ClipInfo& clip : report.clips) {
    EXPECT_EQ(clip.first_frame, frames);
    frames += clip.frame_count;
  }
  EXPECT_EQ(frames, sequence->frame_count());
}

}  // namespace
}  // namespace dmc
