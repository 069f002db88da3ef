// GLB export of a mesh sequence, in one of three layouts (see GlbLayout in gltf_format.h), each
// in one of three encodings (GlbEncoding): float32 positions and normals, or quantised ones
// (KHR_mesh_quantization: 15-bit positions on a grid over every frame, 8-bit normals), optionally
// with every buffer view through EXT_meshopt_compression. The layouts differ in how the animation
// switches frames:
//  - basis (quantised only): frame 0 is the base mesh, and a few single-axis targets per block of
//    frames with per-frame weights (gltf_motion_basis.h) move it; LINEAR interpolation of the
//    weights is that of the positions, since they are linear in the weights.
//  - morph: frame 0 is the base mesh and frame f (f ≥ 1) is morph target f−1 holding
//    frame f − frame 0; the weights animation has one key per frame whose weight vector is one-hot
//    (all zero at frame 0). LINEAR interpolation between two one-hot keys blends exactly the two
//    neighbouring frames, so playback between frames is the linear interpolation of positions.
//    Costs 4·F·(F−1) bytes of weights on top of the vertex data.
//  - frames: one mesh per frame under one parent node; a STEP scale animation shows each frame's
//    node (scale 1) during its frame interval and hides it (scale 0) otherwise. Costs a few hundred
//    bytes of JSON per frame instead of the weights.
// kAuto builds morph and frames (and basis, for compact files) and keeps the smallest file.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "io/gltf_glb_builder.h"

namespace dmc::io_internal {
namespace {

using glb::AddScene;
using glb::FrameNormals;
using glb::FramePositions;
using glb::FrameTimes;
using glb::kDefaultFrameRate;
using glb::ModelBuilder;
using glb::NormalSteps;
using glb::PositionGrid;
using glb::QuantizeNormals;
using glb::RequireCompactExtensions;
using glb::SetExtras;

tinygltf::Model MorphModel(const MeshSequence& sequence, double frame_rate, GlbEncoding encoding) {
  ModelBuilder builder;
  const int frame_count = sequence.frame_count();
  const bool compact = encoding != GlbEncoding::kFloat;
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.indices = builder.AddIndices(sequence.triangles(), sequence.vertex_count());
  const std::vector<float> base = FramePositions(sequence, 0);
  const std::vector<float> base_normals = FrameNormals(sequence, 0);
  const PositionGrid grid(sequence);
  std::vector<int16_t> base_q, previous_q;
  std::vector<int8_t> base_normals_q;
  std::vector<int> normal_sum;
  if (compact) {
    base_q = grid.Quantize(sequence, 0);
    base_normals_q = QuantizeNormals(base_normals);
    primitive.attributes["POSITION"] = builder.AddPaddedVec3(base_q, /*normalized=*/false);
    primitive.attributes["NORMAL"] = builder.AddPaddedVec3(base_normals_q, /*normalized=*/true);
    previous_q = base_q;
    normal_sum.assign(base_normals_q.begin(), base_normals_q.end());
  } else {
    primitive.attributes["POSITION"] = builder.AddFloats(base, TINYGLTF_TYPE_VEC3);
    primitive.attributes["NORMAL"] = builder.AddFloats(base_normals, TINYGLTF_TYPE_VEC3);
  }
  for (int f = 1; f < frame_count; ++f) {
    std::vector<float> normals = FrameNormals(sequence, f);
    if (compact) {
      // Target f holds frame f − frame f−1 (the weights below are cumulative): displacements
      // between neighbouring frames are small, which is what meshopt's codec compresses well,
      // and integer sums on the grid are exact.
      std::vector<int16_t> positions = grid.Quantize(sequence, f);
      std::vector<int16_t> steps(positions.size());
      for (size_t i = 0; i < positions.size(); ++i) {
        steps[i] = static_cast<int16_t>(positions[i] - previous_q[i]);  // |Δ| ≤ 2·16383
      }
      previous_q = std::move(positions);
      primitive.targets.push_back(
          {{"POSITION", builder.AddPaddedVec3(steps, /*normalized=*/false)},
           {"NORMAL",
            builder.AddPaddedVec3(NormalSteps(normals, normal_sum), /*normalized=*/true)}});
      continue;
    }
    std::vector<float> positions = FramePositions(sequence, f);
    for (size_t i = 0; i < positions.size(); ++i) {
      positions[i] -= base[i];
      normals[i] -= base_normals[i];
    }
    primitive.targets.push_back({{"POSITION", builder.AddFloats(positions, TINYGLTF_TYPE_VEC3)},
                                 {"NORMAL", builder.AddFloats(normals, TINYGLTF_TYPE_VEC3)}});
  }
  tinygltf::Mesh mesh;
  mesh.name = sequence.name.empty() ? "dmc" : ReplaceInvalidUtf8(sequence.name);
  mesh.primitives.push_back(primitive);
  mesh.weights.assign(static_cast<size_t>(frame_count - 1), 0.0);
  tinygltf::Model& model = builder.model();
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = mesh.name;
  node.mesh = 0;
  if (compact) {
    grid.Apply(node);
    RequireCompactExtensions(model);
  }
  model.nodes.push_back(node);
  if (frame_count > 1) {
    const size_t targets = static_cast<size_t>(frame_count - 1);
    std::vector<float> weights(static_cast<size_t>(frame_count) * targets, 0.0f);
    // Float: one-hot weights (target f−1 is frame f − frame 0). Compact: cumulative weights
    // (targets 0 … f−1 are the steps up to frame f). Either way LINEAR interpolation between two
    // keys blends exactly the two neighbouring frames.
    for (size_t f = 1; f < static_cast<size_t>(frame_count); ++f) {
      for (size_t t = compact ? 0 : f - 1; t < f; ++t) weights[f * targets + t] = 1;
    }
    tinygltf::AnimationSampler sampler;
    sampler.input = builder.AddFloats(FrameTimes(frame_count, frame_rate), TINYGLTF_TYPE_SCALAR);
    sampler.output = builder.AddFloats(weights, TINYGLTF_TYPE_SCALAR);
    sampler.interpolation = "LINEAR";
    tinygltf::AnimationChannel channel;
    channel.sampler = 0;
    channel.target_node = 0;
    channel.target_path = "weights";
    tinygltf::Animation animation;
    animation.name = "frames";
    animation.samplers.push_back(sampler);
    animation.channels.push_back(channel);
    model.animations.push_back(animation);
  }
  AddScene(model, mesh.name);
  SetExtras(model, sequence, "morph", frame_rate);
  return std::move(model);
}

tinygltf::Model BasisModel(const MeshSequence& sequence, double frame_rate,
                           const std::vector<int>& block_starts) {
  ModelBuilder builder;
  const int frame_count = sequence.frame_count();
  const size_t vertex_count = static_cast<size_t>(sequence.vertex_count());
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.indices = builder.AddIndices(sequence.triangles(), sequence.vertex_count());
  const PositionGrid grid(sequence);
  const std::vector<int16_t> base_q = grid.Quantize(sequence, 0);
  const std::vector<int8_t> base_normals_q = QuantizeNormals(FrameNormals(sequence, 0));
  primitive.attributes["POSITION"] = builder.AddPaddedVec3(base_q, /*normalized=*/false);
  primitive.attributes["NORMAL"] = builder.AddPaddedVec3(base_normals_q, /*normalized=*/true);
  const std::vector<glb::FrameBlock> blocks = glb::SplitBlocks(frame_count, block_starts);
  const auto positions = [&](int j, std::vector<double>& values) {
    const auto frame = sequence.frame(j);
    for (size_t v = 0; v < vertex_count; ++v) {
      for (int c = 0; c < 3; ++c) {
        values[3 * v + static_cast<size_t>(c)] =
            grid.ToGrid(frame(static_cast<Eigen::Index>(v), c), c);
      }
    }
  };
  const auto normals = [&](int j, std::vector<double>& values) {
    const std::vector<float> frame = FrameNormals(sequence, j);
    for (size_t k = 0; k < frame.size(); ++k) values[k] = 32767.0 * frame[k];
  };
  std::vector<double> normal_base(base_normals_q.size());
  for (size_t k = 0; k < normal_base.size(); ++k) {
    normal_base[k] = 32767.0 / 127.0 * base_normals_q[k];
  }
  const auto position_targets =
      glb::FitBlockTargets(positions, std::vector<double>(base_q.begin(), base_q.end()), blocks,
                           glb::kBasisPositionTolerance);
  const auto normal_targets =
      glb::FitBlockTargets(normals, normal_base, blocks, glb::kBasisNormalTolerance);
  glb::AddBasisTargets(builder, position_targets, normal_targets, 0, vertex_count, primitive);
  const size_t target_count = primitive.targets.size();
  tinygltf::Mesh mesh;
  mesh.name = sequence.name.empty() ? "dmc" : ReplaceInvalidUtf8(sequence.name);
  mesh.primitives.push_back(primitive);
  mesh.weights.assign(target_count, 0.0);
  tinygltf::Model& model = builder.model();
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = mesh.name;
  node.mesh = 0;
  grid.Apply(node);
  RequireCompactExtensions(model);
  model.nodes.push_back(node);
  if (frame_count > 1 && target_count > 0) {
    const glb::WeightTable table =
        glb::BasisWeights(position_targets, normal_targets, blocks, frame_count);
    std::vector<float> weights;
    for (const std::vector<float>& frame : table) {
      weights.insert(weights.end(), frame.begin(), frame.end());
    }
    tinygltf::AnimationSampler sampler;
    sampler.input = builder.AddFloats(FrameTimes(frame_count, frame_rate), TINYGLTF_TYPE_SCALAR);
    sampler.output = builder.AddFloats(weights, TINYGLTF_TYPE_SCALAR);
    sampler.interpolation = "LINEAR";
    tinygltf::AnimationChannel channel;
    channel.sampler = 0;
    channel.target_node = 0;
    channel.target_path = "weights";
    tinygltf::Animation animation;
    animation.name = "frames";
    animation.samplers.push_back(sampler);
    animation.channels.push_back(channel);
    model.animations.push_back(animation);
  }
  AddScene(model, mesh.name);
  SetExtras(model, sequence, "basis", frame_rate);
  return std::move(model);
}

tinygltf::Model FramesModel(const MeshSequence& sequence, double frame_rate, GlbEncoding encoding) {
  ModelBuilder builder;
  const bool compact = encoding != GlbEncoding::kFloat;
  const PositionGrid grid(sequence);
  const int frame_count = sequence.frame_count();
  const int indices = builder.AddIndices(sequence.triangles(), sequence.vertex_count());
  const std::string name = sequence.name.empty() ? "dmc" : ReplaceInvalidUtf8(sequence.name);
  tinygltf::Node root;
  root.name = name;
  std::vector<tinygltf::Node> frame_nodes;
  for (int f = 0; f < frame_count; ++f) {
    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.indices = indices;
    if (compact) {
      primitive.attributes["POSITION"] =
          builder.AddPaddedVec3(grid.Quantize(sequence, f), /*normalized=*/false);
      primitive.attributes["NORMAL"] =
          builder.AddPaddedVec3(QuantizeNormals(FrameNormals(sequence, f)), /*normalized=*/true);
    } else {
      primitive.attributes["POSITION"] =
          builder.AddFloats(FramePositions(sequence, f), TINYGLTF_TYPE_VEC3);
      primitive.attributes["NORMAL"] =
          builder.AddFloats(FrameNormals(sequence, f), TINYGLTF_TYPE_VEC3);
    }
    tinygltf::Mesh mesh;
    mesh.name = "frame_" + std::to_string(f);
    mesh.primitives.push_back(primitive);
    builder.model().meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = mesh.name;
    node.mesh = f;
    // Without animation playback, frame 0 is what shows.
    if (f > 0) node.scale = {0.0, 0.0, 0.0};
    frame_nodes.push_back(node);
    root.children.push_back(f + 1);
  }
  tinygltf::Model& model = builder.model();
  if (compact) {
    // The frame nodes inherit the grid's transform; a dmc reader applies it too.
    grid.Apply(root);
    RequireCompactExtensions(model);
  }
  model.nodes.push_back(root);
  model.nodes.insert(model.nodes.end(), frame_nodes.begin(), frame_nodes.end());

  if (frame_count > 1) {
    // Key times and scale values of every frame node, packed into two views.
    const std::vector<float> times = FrameTimes(frame_count, frame_rate);
    std::vector<float> key_times, key_scales;
    std::vector<std::pair<size_t, size_t>> ranges;  // per frame: first key, key count
    for (int f = 0; f < frame_count; ++f) {
      const size_t first = key_times.size();
      auto key = [&](float time, float scale) {
        key_times.push_back(time);
        key_scales.insert(key_scales.end(), {scale, scale, scale});
      };
      const size_t uf = static_cast<size_t>(f);
      if (f > 0) key(0.0f, 0.0f);
      key(times[uf], 1.0f);
      if (f + 1 < frame_count) key(times[uf + 1], 0.0f);
      ranges.emplace_back(first, key_times.size() - first);
    }
    const int time_view = builder.AddView(key_times.data(), key_times.size() * sizeof(float));
    const int scale_view = builder.AddView(key_scales.data(), key_scales.size() * sizeof(float));
    tinygltf::Animation animation;
    animation.name = "frames";
    for (int f = 0; f < frame_count; ++f) {
      const auto [first, count] = ranges[static_cast<size_t>(f)];
      tinygltf::AnimationSampler sampler;
      sampler.input = builder.AddFloats(
          std::vector<float>(key_times.begin() + static_cast<long>(first),
                             key_times.begin() + static_cast<long>(first + count)),
          TINYGLTF_TYPE_SCALAR, time_view, first * sizeof(float));
      sampler.output = builder.AddFloats(
          std::vector<float>(key_scales.begin() + static_cast<long>(3 * first),
                             key_scales.begin() + static_cast<long>(3 * (first + count))),
          TINYGLTF_TYPE_VEC3, scale_view, 3 * first * sizeof(float));
      sampler.interpolation = "STEP";
      tinygltf::AnimationChannel channel;
      channel.sampler = f;
      channel.target_node = f + 1;
      channel.target_path = "scale";
      animation.samplers.push_back(sampler);
      animation.channels.push_back(channel);
    }
    model.animations.push_back(animation);
  }
  AddScene(model, name);
  SetExtras(model, sequence, "frames", frame_rate);
  return std::move(model);
}

StatusOr<std::vector<uint8_t>> Serialize(tinygltf::Model model, GlbEncoding encoding) {
  if (encoding == GlbEncoding::kCompact) return SerializeMeshoptGlb(std::move(model));
  return SerializeGlb(model);
}

}  // namespace

StatusOr<std::vector<uint8_t>> EncodeGlb(const MeshSequence& sequence, GlbLayout layout,
                                         GlbEncoding encoding,
                                         const std::vector<int>& block_starts) {
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  const double frame_rate = sequence.frame_rate > 0 && std::isfinite(sequence.frame_rate)
                                ? sequence.frame_rate
                                : kDefaultFrameRate;
  const bool quantized = encoding != GlbEncoding::kFloat;
  if (layout == GlbLayout::kBasis && !quantized) {
    return InvalidArgumentError(
        "the basis layout stores quantised targets: use the compact or quantized encoding");
  }
  if (layout == GlbLayout::kBasis) {
    return Serialize(BasisModel(sequence, frame_rate, block_starts), encoding);
  }
  if (layout == GlbLayout::kMorph) {
    return Serialize(MorphModel(sequence, frame_rate, encoding), encoding);
  }
  if (layout == GlbLayout::kFrames) {
    return Serialize(FramesModel(sequence, frame_rate, encoding), encoding);
  }
  DMC_ASSIGN_OR_RETURN(auto best, Serialize(MorphModel(sequence, frame_rate, encoding), encoding));
  DMC_ASSIGN_OR_RETURN(auto frames,
                       Serialize(FramesModel(sequence, frame_rate, encoding), encoding));
  if (frames.size() < best.size()) best = std::move(frames);
  // Only compact files consider the basis layout: quantized ones are for importers without a
  // meshopt decoder, Blender's above all, which clamps shape-key values to [0, 1] (see
  // EncodeSceneGlb).
  if (encoding == GlbEncoding::kCompact) {
    DMC_ASSIGN_OR_RETURN(auto basis,
                         Serialize(BasisModel(sequence, frame_rate, block_starts), encoding));
    if (basis.size() < best.size()) best = std::move(basis);
  }
  return best;
}

}  // namespace dmc::io_internal
