// glTF posing on small in-memory models whose posed positions are computed by hand: keyframe
// interpolation (STEP, LINEAR, slerp, CUBICSPLINE), node hierarchy, skinning, morph targets,
// welding, frame counts and errors.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gltf_test_models.h"

namespace dmc {
namespace {

using io_internal::GltfImport;
using io_internal::PoseGltfModel;
using testing::GltfBuilder;
using testing::UnitTriangle;

GltfReadOptions AtFps(double fps) {
  GltfReadOptions options;
  options.frame_rate = fps;
  return options;
}

// A triangle node whose translation is animated from (0,0,0) at t=0 to (2,0,0) at t=1.
GltfImport PoseTranslation(const std::string& interpolation, const std::vector<float>& values,
                           double fps) {
  GltfBuilder builder;
  const int node = builder.MeshNode(UnitTriangle(), {0, 1, 2});
  builder.Channel(node, "translation", interpolation, {0, 1}, values, TINYGLTF_TYPE_VEC3);
  builder.FinishScene();
  auto posed = PoseGltfModel(builder.model, AtFps(fps));
  EXPECT_TRUE(posed.ok()) << posed.status().ToString();
  return std::move(posed).value();
}

TEST(GltfPoseTest, LinearTranslationIsInterpolatedAtTheFrameRate) {
  const GltfImport posed = PoseTranslation("LINEAR", {0, 0, 0, 2, 0, 0}, 4.0);
  ASSERT_EQ(posed.sequence.frame_count(), 5);  // t = 0, 0.25, 0.5, 0.75, 1
  EXPECT_EQ(posed.sequence.frame_rate, 4.0);
  for (int f = 0; f < 5; ++f) {
    EXPECT_NEAR(posed.sequence.frame(f)(1, 0), 1.0 + 0.5 * f, 1e-6) << "frame " << f;
    EXPECT_NEAR(posed.sequence.frame(f)(2, 1), 1.0, 1e-6);
  }
}

TEST(GltfPoseTest, StepHoldsThePreviousKey) {
  const GltfImport posed = PoseTranslation("STEP", {0, 0, 0, 2, 0, 0}, 4.0);
  ASSERT_EQ(posed.sequence.frame_count(), 5);
  const float expected_x0[] = {0, 0, 0, 0, 2};
  for (int f = 0; f < 5; ++f) EXPECT_EQ(posed.sequence.frame(f)(0, 0), expected_x0[f]);
}

TEST(GltfPoseTest, CubicSplineFollowsTheHermiteFormula) {
  // Keys (in-tangent, value, out-tangent): key 0 = (0, 0, 4), key 1 = (0, 2, 0) along x.
  // x(s) = (-2s³ + 3s²)·2 + (s³ - 2s² + s)·4 over the unit interval.
  const GltfImport posed =
      PoseTranslation("CUBICSPLINE", {0, 0, 0, 0, 0, 0, 4, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0}, 4.0);
  ASSERT_EQ(posed.sequence.frame_count(), 5);
  const double expected[] = {0.0, 0.875, 1.5, 1.875, 2.0};
  for (int f = 0; f < 5; ++f) {
    EXPECT_NEAR(posed.sequence.frame(f)(0, 0), expected[f], 1e-6) << "frame " << f;
  }
}

// Rotation keys from identity to 90° about z; vertex (1,0,0) at t = 0.25 must be at 22.5° (slerp),
// not at the 21.6° a normalised lerp would give.
void ExpectSlerp(const std::vector<float>& end_key) {
  GltfBuilder builder;
  const int node = builder.MeshNode(UnitTriangle(), {0, 1, 2});
  std::vector<float> keys = {0, 0, 0, 1};
  keys.insert(keys.end(), end_key.begin(), end_key.end());
  builder.Channel(node, "rotation", "LINEAR", {0, 1}, keys, TINYGLTF_TYPE_VEC4);
  builder.FinishScene();
  auto posed = PoseGltfModel(builder.model, AtFps(4.0));
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  const auto frame = posed->sequence.frame(1);
  const double angle = std::atan2(frame(1, 1), frame(1, 0)) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(angle, 22.5, 1e-4);
  EXPECT_NEAR(std::hypot(frame(1, 0), frame(1, 1)), 1.0, 1e-6);
}

TEST(GltfPoseTest, RotationIsSlerped) {
  const float s = static_cast<float>(std::sqrt(0.5));
  ExpectSlerp({0, 0, s, s});
}

TEST(GltfPoseTest, SlerpTakesTheShorterArcOfANegatedQuaternion) {
  const float s = static_cast<float>(std::sqrt(0.5));
  ExpectSlerp({0, 0, -s, -s});  // the same rotation; the long way round would pass 180° - 22.5°
}

TEST(GltfPoseTest, NodeHierarchyComposesParentThenChild) {
  GltfBuilder builder;
  const int child = builder.MeshNode(UnitTriangle(), {0, 1, 2});
  builder.model.nodes[static_cast<size_t>(child)].scale = {2, 2, 2};
  tinygltf::Node parent;
  parent.translation = {1, 2, 3};
  parent.children = {child};
  builder.AddNode(parent);
  builder.FinishScene();
  auto posed = PoseGltfModel(builder.model, AtFps(30));
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  ASSERT_EQ(posed->sequence.frame_count(), 1);  // no animation: one frame
  const auto frame = posed->sequence.frame(0);
  EXPECT_FLOAT_EQ(frame(1, 0), 3.0f);  // (1,0,0)·2 + (1,2,3)
  EXPECT_FLOAT_EQ(frame(1, 1), 2.0f);
  EXPECT_FLOAT_EQ(frame(2, 1), 4.0f);  // (0,1,0)·2 + (1,2,3)
}

// Joint A at the origin, joint B its child at (0,1,0); the mesh node has a transform that
// skinning must ignore. v0 follows A, v1 is half A half B, v2 follows B.
GltfBuilder SkinnedModel(bool animate_b) {
  GltfBuilder builder;
  tinygltf::Node joint_b;
  joint_b.translation = {0, 1, 0};
  const int b = builder.AddNode(joint_b);
  tinygltf::Node joint_a;
  joint_a.children = {b};
  const int a = builder.AddNode(joint_a);
  const int mesh_node = builder.MeshNode(UnitTriangle(), {0, 1, 2});
  builder.model.nodes[static_cast<size_t>(mesh_node)].translation = {100, 0, 0};
  tinygltf::Primitive& primitive = builder.model.meshes[0].primitives[0];
  primitive.attributes["JOINTS_0"] = builder.Joints({0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0});
  primitive.attributes["WEIGHTS_0"] =
      builder.Floats({1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 1, 0, 0, 0}, TINYGLTF_TYPE_VEC4);
  tinygltf::Skin skin;
  skin.joints = {a, b};
  // Inverse bind matrices (column-major): identity for A, translate(0,-1,0) for B.
  skin.inverseBindMatrices = builder.Floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,
                                             1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1},
                                            TINYGLTF_TYPE_MAT4);
  builder.model.skins.push_back(skin);
  builder.model.nodes[static_cast<size_t>(mesh_node)].skin = 0;
  if (animate_b) {
    const float s = static_cast<float>(std::sqrt(0.5));
    builder.Channel(b, "rotation", "STEP", {0, 1}, {0, 0, 0, 1, 0, 0, s, s}, TINYGLTF_TYPE_VEC4);
  }
  builder.FinishScene();
  return builder;
}

TEST(GltfPoseTest, BindPoseReproducesTheBindMesh) {
  // Joint globals equal the inverse bind matrices' inverses: every joint matrix is the identity,
  // so skinning returns POSITION exactly, whatever the mesh node's own transform.
  const GltfBuilder builder = SkinnedModel(/*animate_b=*/false);
  auto posed = PoseGltfModel(builder.model, AtFps(30));
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  const std::vector<float> bind = UnitTriangle();
  for (int v = 0; v < 3; ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_FLOAT_EQ(posed->sequence.frame(0)(v, axis), bind[static_cast<size_t>(3 * v + axis)]);
    }
  }
}

TEST(GltfPoseTest, LinearBlendSkinningMatchesHandComputation) {
  // At t = 1 joint B turns 90° about z around its origin (0,1,0).
  // v1 = (1,0,0): A keeps it, B moves it to (1,2,0); the 50/50 blend is (1,1,0).
  const GltfBuilder builder = SkinnedModel(/*animate_b=*/true);
  auto posed = PoseGltfModel(builder.model, AtFps(1));
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  ASSERT_EQ(posed->sequence.frame_count(), 2);
  const auto frame = posed->sequence.frame(1);
  EXPECT_NEAR(frame(0, 0), 0.0, 1e-6);
  EXPECT_NEAR(frame(0, 1), 0.0, 1e-6);
  EXPECT_NEAR(frame(1, 0), 1.0, 1e-6);
  EXPECT_NEAR(frame(1, 1), 1.0, 1e-6);
  EXPECT_NEAR(frame(2, 0), 0.0, 1e-6);  // B's origin does not move
  EXPECT_NEAR(frame(2, 1), 1.0, 1e-6);
}

GltfBuilder MorphModel() {
  GltfBuilder builder;
  const int node = builder.MeshNode(UnitTriangle(), {0, 1, 2});
  tinygltf::Primitive& primitive = builder.model.meshes[0].primitives[0];
  primitive.targets.push_back(
      {{"POSITION", builder.Floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, TINYGLTF_TYPE_VEC3)}});
  primitive.targets.push_back(
      {{"POSITION", builder.Floats({0, 0, 0, 1, 0, 0, 0, 0, 0}, TINYGLTF_TYPE_VEC3)}});
  builder.model.meshes[0].weights = {1, 0};
  (void)node;
  return builder;
}

TEST(GltfPoseTest, MorphTargetsUseTheMeshWeightsWithoutAnimation) {
  GltfBuilder builder = MorphModel();
  builder.FinishScene();
  auto posed = PoseGltfModel(builder.model, AtFps(30));
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  EXPECT_FLOAT_EQ(posed->sequence.frame(0)(1, 0), 1.0f);
  EXPECT_FLOAT_EQ(posed->sequence.frame(0)(1, 2), 1.0f);
}

TEST(GltfPoseTest, MorphWeightsAnimationBlendsTargets) {
  GltfBuilder builder = MorphModel();
  builder.Channel(0, "weights", "LINEAR", {0, 1}, {0, 0, 1, 0.5f}, TINYGLTF_TYPE_SCALAR);
  builder.FinishScene();
  auto posed = PoseGltfModel(builder.model, AtFps(2));
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  ASSERT_EQ(posed->sequence.frame_count(), 3);
  // t = 0.5: weights (0.5, 0.25); v1 = (1,0,0) + 0.5·(0,0,1) + 0.25·(1,0,0).
  EXPECT_NEAR(posed->sequence.frame(1)(1, 0), 1.25, 1e-6);
  EXPECT_NEAR(posed->sequence.frame(1)(1, 2), 0.5, 1e-6);
  EXPECT_NEAR(posed->sequence.frame(1)(0, 0), 0.0, 1e-6);
  // t = 0: the animation's zero weights override mesh.weights.
  EXPECT_FLOAT_EQ(posed->sequence.frame(0)(1, 2), 0.0f);
}

TEST(GltfPoseTest, WeldMergesSeamDuplicatesAndKeepsTheMap) {
  GltfBuilder builder;
  // Two triangles of a unit square as a soup: corners (1,0,0) and (0,1,0) are duplicated.
  builder.MeshNode({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 1, 2, 3, 4, 5});
  builder.FinishScene();
  GltfReadOptions options = AtFps(30);
  auto unwelded = PoseGltfModel(builder.model, options);
  ASSERT_TRUE(unwelded.ok());
  EXPECT_EQ(unwelded->sequence.vertex_count(), 6);
  EXPECT_EQ(unwelded->vertex_map, (std::vector<int32_t>{0, 1, 2, 3, 4, 5}));
  options.weld = true;
  auto welded = PoseGltfModel(builder.model, options);
  ASSERT_TRUE(welded.ok()) << welded.status().ToString();
  EXPECT_EQ(welded->sequence.vertex_count(), 4);
  EXPECT_EQ(welded->vertex_map, (std::vector<int32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(welded->sequence.triangles().row(1), Eigen::RowVector3i(1, 3, 2).cast<int32_t>());
  for (int v = 0; v < 6; ++v) {
    EXPECT_EQ(welded->sequence.frame(0).row(welded->vertex_map[static_cast<size_t>(v)]),
              unwelded->sequence.frame(0).row(v));
  }
}

TEST(GltfPoseTest, WeldKeepsVerticesThatOnlyMeetInSomeFrames) {
  GltfBuilder builder;
  builder.MeshNode(UnitTriangle(), {0, 1, 2}, "still");
  const int moving = builder.MeshNode(UnitTriangle(), {0, 1, 2}, "moving");
  builder.Channel(moving, "translation", "LINEAR", {0, 1}, {0, 0, 0, 0, 0, 1}, TINYGLTF_TYPE_VEC3);
  builder.FinishScene();
  GltfReadOptions options = AtFps(1);
  options.weld = true;
  auto posed = PoseGltfModel(builder.model, options);
  ASSERT_TRUE(posed.ok()) << posed.status().ToString();
  EXPECT_EQ(posed->sequence.vertex_count(), 6);  // same place at t = 0, apart at t = 1
}

TEST(GltfPoseTest, MeshSelectionByName) {
  GltfBuilder builder;
  builder.MeshNode(UnitTriangle(), {0, 1, 2}, "first");
  builder.MeshNode({0, 0, 0, 2, 0, 0, 0, 2, 0}, {0, 1, 2}, "second");
  builder.FinishScene();
  GltfReadOptions options = AtFps(30);
  auto both = PoseGltfModel(builder.model, options);
  ASSERT_TRUE(both.ok());
  EXPECT_EQ(both->sequence.vertex_count(), 6);
  EXPECT_EQ(both->sequence.triangles().row(1), Eigen::RowVector3i(3, 4, 5).cast<int32_t>());
  options.mesh = "second";
  auto second = PoseGltfModel(builder.model, options);
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(second->sequence.vertex_count(), 3);
  EXPECT_FLOAT_EQ(second->sequence.frame(0)(1, 0), 2.0f);
  options.mesh = "third";
  EXPECT_EQ(PoseGltfModel(builder.model, options).status().code(), ErrorCode::kInvalidArgument);
}

TEST(GltfPoseTest, FrameCountCoversTheClipAndHonoursMaxFrames) {
  GltfBuilder builder;
  const int node = builder.MeshNode(UnitTriangle(), {0, 1, 2});
  builder.Channel(node, "translation", "LINEAR", {0, 2}, {0, 0, 0, 1, 0, 0}, TINYGLTF_TYPE_VEC3);
  builder.model.animations[0].name = "walk";
  builder.FinishScene();
  auto posed = PoseGltfModel(builder.model, AtFps(24));
  ASSERT_TRUE(posed.ok());
  EXPECT_EQ(posed->sequence.frame_count(), 49);  // 0 .. 2 s inclusive at 24 fps
  EXPECT_EQ(PoseGltfModel(builder.model, AtFps(24), 10)->sequence.frame_count(), 10);
  GltfReadOptions options = AtFps(24);
  options.animation = "walk";
  EXPECT_TRUE(PoseGltfModel(builder.model, options).ok());
  options.animation = "0";
  EXPECT_TRUE(PoseGltfModel(builder.model, options).ok());
  options.animation = "run";
  EXPECT_EQ(PoseGltfModel(builder.model, options).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(PoseGltfModel(builder.model, AtFps(-1)).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(PoseGltfModel(builder.model, AtFps(0))->sequence.frame_rate, 30.0);  // automatic
}

TEST(GltfPoseTest, BrokenFilesAreParseErrors) {
  GltfBuilder out_of_range = SkinnedModel(false);
  // Joint slot 7 of a two-joint skin.
  out_of_range.model.buffers[0]
      .data[out_of_range.model
                .bufferViews[static_cast<size_t>(
                    out_of_range.model
                        .accessors[static_cast<size_t>(
                            out_of_range.model.meshes[0].primitives[0].attributes.at("JOINTS_0"))]
                        .bufferView)]
                .byteOffset] = 7;
  EXPECT_EQ(PoseGltfModel(out_of_range.model, AtFps(30)).status().code(), ErrorCode::kParseError);

  GltfBuilder truncated;
  truncated.MeshNode(UnitTriangle(), {0, 1, 2});
  truncated.model.accessors[0].count = 1000;  // POSITION claims more than its view holds
  truncated.FinishScene();
  EXPECT_EQ(PoseGltfModel(truncated.model, AtFps(30)).status().code(), ErrorCode::kParseError);

  GltfBuilder bad_index;
  bad_index.MeshNode(UnitTriangle(), {0, 1, 3});
  bad_index.FinishScene();
  EXPECT_EQ(PoseGltfModel(bad_index.model, AtFps(30)).status().code(), ErrorCode::kParseError);

  GltfBuilder empty;
  empty.FinishScene();
  EXPECT_EQ(PoseGltfModel(empty.model, AtFps(30)).status().code(), ErrorCode::kUnsupported);
}

// Without a requested or recorded rate, a baked clip (keys on one grid of 12 to 240 per second)
// is sampled at its key rate; sparser or irregular keys at 30 fps.
TEST(GltfPoseTest, UniformKeysSetTheDefaultRate) {
  struct Case {
    std::vector<float> times;
    double expected_rate;
  };
  auto grid = [](int keys, double rate, double start) {
    std::vector<float> times;
    for (int k = 0; k < keys; ++k) times.push_back(static_cast<float>(start + k / rate));
    return times;
  };
  const std::vector<Case> cases = {
      {grid(48, 24.0, 1.0 / 24), 24.0},                 // CesiumMan's keying: 1/24 s .. 2 s
      {grid(31, 30000.0 / 1001, 0.0), 30000.0 / 1001},  // NTSC
      {grid(100, 60.0, 7.5), 60.0},                     // late start
      {grid(3, 1.0, 0.0), 30.0},                        // sparse keys: interpolation is the motion
      {grid(50, 1000.0, 0.0), 30.0},                    // beyond 240 per second
      {{0.0f, 0.1f, 0.35f, 0.5f}, 30.0},                // irregular
  };
  for (const Case& c : cases) {
    GltfBuilder builder;
    const int node = builder.MeshNode(UnitTriangle(), {0, 1, 2});
    std::vector<float> values;
    for (size_t k = 0; k < c.times.size(); ++k) values.insert(values.end(), {float(k), 0, 0});
    builder.Channel(node, "translation", "LINEAR", c.times, values, TINYGLTF_TYPE_VEC3);
    builder.FinishScene();
    auto posed = PoseGltfModel(builder.model, GltfReadOptions{});
    ASSERT_TRUE(posed.ok()) << posed.status().ToString();
    EXPECT_DOUBLE_EQ(posed->sequence.frame_rate, c.expected_rate) << c.times.size() << " keys";
    if (c.expected_rate != 30.0) {
      // Sampling at the key rate gives the keys themselves.
      ASSERT_EQ(posed->sequence.frame_count(), static_cast<int>(c.times.size()));
      for (int f = 0; f < posed->sequence.frame_count(); ++f) {
        EXPECT_NEAR(posed->sequence.frame(f)(0, 0), f, 1e-4) << "frame " << f;
      }
    }
  }
}

// Every clip by default, one after the other, each from its own start; "all" says the same; a
// name or an index picks one.
TEST(GltfPoseTest, EveryClipIsPosedInTurn) {
  GltfBuilder builder;
  const int node = builder.MeshNode(UnitTriangle(), {0, 1, 2});
  // "slide": x from 0 to 3 over 0..1 s; "lift": y from 0 to 2 over 5..5.5 s.
  builder.Channel(node, "translation", "LINEAR", {0, 1}, {0, 0, 0, 3, 0, 0}, TINYGLTF_TYPE_VEC3);
  builder.model.animations.back().name = "slide";
  builder.model.animations.emplace_back();
  builder.Channel(node, "translation", "LINEAR", {5, 5.5f}, {0, 0, 0, 0, 2, 0}, TINYGLTF_TYPE_VEC3);
  builder.model.animations.back().name = "lift";
  builder.FinishScene();
  for (const char* wanted : {"", "all"}) {
    GltfReadOptions options = AtFps(4);
    options.animation = wanted;
    auto posed = PoseGltfModel(builder.model, options);
    ASSERT_TRUE(posed.ok()) << posed.status().ToString();
    ASSERT_EQ(posed->clips.size(), 2u);
    EXPECT_EQ(posed->clips[0].name, "slide");
    EXPECT_EQ(posed->clips[0].first_frame, 0);
    EXPECT_EQ(posed->clips[0].frame_count, 5);  // 0, 0.25, ..., 1 s
    EXPECT_EQ(posed->clips[1].name, "lift");
    EXPECT_EQ(posed->clips[1].first_frame, 5);
    EXPECT_EQ(posed->clips[1].frame_count, 3);  // 5, 5.25, 5.5 s
    ASSERT_EQ(posed->sequence.frame_count(), 8);
    EXPECT_NEAR(posed->sequence.frame(4)(0, 0), 3.0, 1e-6);  // the end of "slide"
    EXPECT_NEAR(posed->sequence.frame(5)(0, 1), 0.0, 1e-6);  // "lift" from its own start
    EXPECT_NEAR(posed->sequence.frame(7)(0, 1), 2.0, 1e-6);
  }
  GltfReadOptions one = AtFps(4);
  one.animation = "lift";
  auto lift = PoseGltfModel(builder.model, one);
  ASSERT_TRUE(lift.ok());
  ASSERT_EQ(lift->clips.size(), 1u);
  EXPECT_EQ(lift->clips[0].name, "lift");
  EXPECT_EQ(lift->sequence.frame_count(), 3);
  one.animation = "0";
  EXPECT_EQ(PoseGltfModel(builder.model, one)->clips[0].name, "slide");
  // max_frames counts across the clips.
  auto cut = PoseGltfModel(builder.model, AtFps(4), 6);
  ASSERT_TRUE(cut.ok());
  EXPECT_EQ(cut->sequence.frame_count(), 6);
  ASSERT_EQ(cut->clips.size(), 2u);
  EXPECT_EQ(cut->clips[1].frame_count, 1);
}

}  // namespace
}  // namespace dmc
