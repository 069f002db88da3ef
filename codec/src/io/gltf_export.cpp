// GLB export of a mesh sequence, in one of two layouts (see GlbLayout in gltf_format.h), each in
// one of three encodings (GlbEncoding): float32 positions and normals, or quantised ones
// (KHR_mesh_quantization: 15-bit positions on a grid over every frame, 8-bit normals), optionally
// with every buffer view through EXT_meshopt_compression. The layouts differ in how the animation
// switches frames:
//  - morph: frame 0 is the base mesh and frame f (f ≥ 1) is morph target f−1 holding
//    frame f − frame 0; the weights animation has one key per frame whose weight vector is one-hot
//    (all zero at frame 0). LINEAR interpolation between two one-hot keys blends exactly the two
//    neighbouring frames, so playback between frames is the linear interpolation of positions.
//    Costs 4·F·(F−1) bytes of weights on top of the vertex data.
//  - frames: one mesh per frame under one parent node; a STEP scale animation shows each frame's
//    node (scale 1) during its frame interval and hides it (scale 0) otherwise. Costs a few hundred
//    bytes of JSON per frame instead of the weights.
// kAuto builds both and keeps the smaller file.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "io/gltf_format.h"
#include "io/utf8_text.h"

namespace dmc::io_internal {
namespace {

constexpr double kDefaultFrameRate = 30.0;

// Builds a tinygltf model whose single buffer becomes the GLB's BIN chunk.
class ModelBuilder {
 public:
  ModelBuilder() {
    model_.buffers.emplace_back();
    model_.asset.version = "2.0";
    model_.asset.generator = "dmc";
  }

  // Appends `bytes` as a new buffer view (4-byte aligned, as every accessor here needs).
  int AddView(const void* bytes, size_t size, int target = 0) {
    std::vector<unsigned char>& data = model_.buffers[0].data;
    while (data.size() % 4 != 0) data.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = data.size();
    view.byteLength = size;
    view.target = target;
    const auto* begin = static_cast<const unsigned char*>(bytes);
    data.insert(data.end(), begin, begin + size);
    model_.bufferViews.push_back(view);
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  // A float accessor of `count` elements of `type` (VEC3, SCALAR) over `values`, with min/max
  // (required by the spec for POSITION and animation inputs, harmless elsewhere).
  int AddFloats(const std::vector<float>& values, int type, int view = -1, size_t offset = 0) {
    const int components = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(type));
    const size_t count = values.size() / static_cast<size_t>(components);
    if (view < 0) {
      view = AddView(values.data(), values.size() * sizeof(float),
                     type == TINYGLTF_TYPE_VEC3 ? TINYGLTF_TARGET_ARRAY_BUFFER : 0);
    }
    tinygltf::Accessor accessor;
    accessor.bufferView = view;
    accessor.byteOffset = offset;
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    accessor.type = type;
    accessor.count = count;
    accessor.minValues.assign(static_cast<size_t>(components), HUGE_VAL);
    accessor.maxValues.assign(static_cast<size_t>(components), -HUGE_VAL);
    for (size_t e = 0; e < count; ++e) {
      for (size_t c = 0; c < static_cast<size_t>(components); ++c) {
        const double value = values[e * static_cast<size_t>(components) + c];
        accessor.minValues[c] = std::min(accessor.minValues[c], value);
        accessor.maxValues[c] = std::max(accessor.maxValues[c], value);
      }
    }
    model_.accessors.push_back(accessor);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  // A VEC3 accessor of int16 (unnormalised: quantised positions and their deltas) or int8
  // (normalised: normals and their deltas) elements, each padded to 4-byte alignment as the
  // spec requires, with min/max.
  template <typename T>
  int AddPaddedVec3(const std::vector<T>& values, bool normalized) {
    constexpr size_t kStride = sizeof(T) == 2 ? 8 : 4;
    const size_t count = values.size() / 3;
    std::vector<unsigned char> bytes(count * kStride, 0);
    tinygltf::Accessor accessor;
    accessor.minValues.assign(3, HUGE_VAL);
    accessor.maxValues.assign(3, -HUGE_VAL);
    for (size_t e = 0; e < count; ++e) {
      std::memcpy(bytes.data() + e * kStride, &values[3 * e], 3 * sizeof(T));
      for (size_t c = 0; c < 3; ++c) {
        const double value = values[3 * e + c];
        accessor.minValues[c] = std::min(accessor.minValues[c], value);
        accessor.maxValues[c] = std::max(accessor.maxValues[c], value);
      }
    }
    // min/max are the stored integers, normalised or not (glTF 2.0, accessor.min).
    accessor.bufferView = AddView(bytes.data(), bytes.size(), TINYGLTF_TARGET_ARRAY_BUFFER);
    model_.bufferViews.back().byteStride = kStride;
    accessor.componentType =
        sizeof(T) == 2 ? TINYGLTF_COMPONENT_TYPE_SHORT : TINYGLTF_COMPONENT_TYPE_BYTE;
    accessor.normalized = normalized;
    accessor.type = TINYGLTF_TYPE_VEC3;
    accessor.count = count;
    model_.accessors.push_back(accessor);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  int AddIndices(const Triangles& triangles, int vertex_count) {
    tinygltf::Accessor accessor;
    const size_t count = static_cast<size_t>(triangles.size());
    if (vertex_count <= 65535) {
      // 16-bit indices halve the index data of meshes below 64k vertices.
      std::vector<uint16_t> narrow(triangles.data(), triangles.data() + count);
      accessor.bufferView =
          AddView(narrow.data(), count * sizeof(uint16_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
      std::vector<uint32_t> wide(triangles.data(), triangles.data() + count);
      accessor.bufferView =
          AddView(wide.data(), count * sizeof(uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    accessor.type = TINYGLTF_TYPE_SCALAR;
    accessor.count = count;
    model_.accessors.push_back(accessor);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  tinygltf::Model& model() { return model_; }

 private:
  tinygltf::Model model_;
};

std::vector<float> FramePositions(const MeshSequence& sequence, int f) {
  const float* begin = sequence.frame(f).data();
  return {begin, begin + 3 * static_cast<size_t>(sequence.vertex_count())};
}

// Area-weighted vertex normals of frame f (unit length; +z for vertices without area, since the
// spec requires unit normals).
std::vector<float> FrameNormals(const MeshSequence& sequence, int f) {
  const auto frame = sequence.frame_d(f);
  FramePositionsD sums = FramePositionsD::Zero(sequence.vertex_count(), 3);
  const Triangles& triangles = sequence.triangles();
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = frame.row(triangles(t, 0));
    const Eigen::Vector3d b = frame.row(triangles(t, 1));
    const Eigen::Vector3d c = frame.row(triangles(t, 2));
    const Eigen::RowVector3d area_normal = (b - a).cross(c - a).transpose();
    for (int corner = 0; corner < 3; ++corner) sums.row(triangles(t, corner)) += area_normal;
  }
  std::vector<float> normals(3 * static_cast<size_t>(sequence.vertex_count()));
  for (int v = 0; v < sequence.vertex_count(); ++v) {
    Eigen::Vector3d n = sums.row(v).transpose();
    const double length = n.norm();
    n = length > 0 && std::isfinite(length) ? Eigen::Vector3d(n / length)
                                            : Eigen::Vector3d(0, 0, 1);
    for (int axis = 0; axis < 3; ++axis) {
      normals[3 * static_cast<size_t>(v) + static_cast<size_t>(axis)] = static_cast<float>(n[axis]);
    }
  }
  return normals;
}

std::vector<float> FrameTimes(int frame_count, double frame_rate) {
  std::vector<float> times(static_cast<size_t>(frame_count));
  for (int f = 0; f < frame_count; ++f) {
    times[static_cast<size_t>(f)] = static_cast<float>(f / frame_rate);
  }
  return times;
}

// The compact encoding's position grid: one cubic grid over every frame, so positions of any frame
// and their differences from frame 0 are exact int16 values, and the node's uniform scale keeps
// normals' directions (KHR_mesh_quantization recommends a uniform scale).
class PositionGrid {
 public:
  // 15 bits per coordinate: differences of two grid values then fit int16.
  static constexpr double kHalfRange = 16383.0;

  explicit PositionGrid(const MeshSequence& sequence) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL);
    Eigen::Vector3d hi = -lo;
    for (int f = 0; f < sequence.frame_count(); ++f) {
      const auto frame = sequence.frame_d(f);
      lo = lo.cwiseMin(frame.colwise().minCoeff().transpose());
      hi = hi.cwiseMax(frame.colwise().maxCoeff().transpose());
    }
    center_ = 0.5 * (lo + hi);
    const double half_extent = 0.5 * (hi - lo).maxCoeff();
    step_ = half_extent > 0 ? half_extent / kHalfRange : 1.0;
  }

  std::vector<int16_t> Quantize(const MeshSequence& sequence, int f) const {
    const auto frame = sequence.frame_d(f);
    std::vector<int16_t> q(3 * static_cast<size_t>(sequence.vertex_count()));
    for (int v = 0; v < sequence.vertex_count(); ++v) {
      for (int c = 0; c < 3; ++c) {
        const double value = std::round((frame(v, c) - center_[c]) / step_);
        q[3 * static_cast<size_t>(v) + static_cast<size_t>(c)] =
            static_cast<int16_t>(std::clamp(value, -kHalfRange, kHalfRange));
      }
    }
    return q;
  }

  // The node transform that maps grid values back.
  void Apply(tinygltf::Node& node) const {
    node.translation = {center_[0], center_[1], center_[2]};
    node.scale = {step_, step_, step_};
  }

 private:
  Eigen::Vector3d center_;
  double step_ = 1.0;
};

std::vector<int8_t> QuantizeNormals(const std::vector<float>& normals) {
  std::vector<int8_t> q(normals.size());
  for (size_t i = 0; i < normals.size(); ++i) {
    q[i] = static_cast<int8_t>(std::clamp(std::round(normals[i] * 127.0), -127.0, 127.0));
  }
  return q;
}

// The compact morph layout's normal displacements from frame f−1 to frame f, closed loop on the
// running sum `sum` (int8 units, starts as the base normals): renderers normalise n_0 + Σ w·δ, so
// the sum need only point along n_f, and s·n_f with the largest s ≤ 1 that keeps every step within
// int8 is taken (at least 1/16; a normal that turns over in one frame may then be clamped).
std::vector<int8_t> NormalSteps(const std::vector<float>& normals, std::vector<int>& sum) {
  std::vector<int8_t> q(normals.size());
  for (size_t v = 0; v < normals.size() / 3; ++v) {
    double s = 1.0;
    for (size_t c = 0; c < 3; ++c) {
      const double target = 127.0 * normals[3 * v + c];
      const double previous = sum[3 * v + c];
      if (target - previous > 127.0) s = std::min(s, (previous + 127.0) / target);
      if (target - previous < -127.0) s = std::min(s, (previous - 127.0) / target);
    }
    s = std::max(s, 1.0 / 16);
    for (size_t c = 0; c < 3; ++c) {
      const double step = std::round(s * 127.0 * normals[3 * v + c]) - sum[3 * v + c];
      q[3 * v + c] = static_cast<int8_t>(std::clamp(step, -127.0, 127.0));
      sum[3 * v + c] += q[3 * v + c];
    }
  }
  return q;
}

void RequireCompactExtensions(tinygltf::Model& model) {
  model.extensionsUsed.push_back("KHR_mesh_quantization");
  model.extensionsRequired.push_back("KHR_mesh_quantization");
}

void SetExtras(tinygltf::Model& model, const MeshSequence& sequence, const char* layout,
               double frame_rate) {
  tinygltf::Value::Object dmc;
  dmc["layout"] = tinygltf::Value(std::string(layout));
  dmc["frames"] = tinygltf::Value(sequence.frame_count());
  dmc["vertices"] = tinygltf::Value(sequence.vertex_count());
  dmc["frame_rate"] = tinygltf::Value(frame_rate);
  tinygltf::Value::Object extras;
  extras["dmc"] = tinygltf::Value(dmc);
  model.asset.extras = tinygltf::Value(extras);
}

void AddScene(tinygltf::Model& model, const std::string& name) {
  tinygltf::Scene scene;
  scene.name = name;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
}

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
                                         GlbEncoding encoding) {
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  const double frame_rate = sequence.frame_rate > 0 && std::isfinite(sequence.frame_rate)
                                ? sequence.frame_rate
                                : kDefaultFrameRate;
  if (layout == GlbLayout::kMorph) {
    return Serialize(MorphModel(sequence, frame_rate, encoding), encoding);
  }
  if (layout == GlbLayout::kFrames) {
    return Serialize(FramesModel(sequence, frame_rate, encoding), encoding);
  }
  DMC_ASSIGN_OR_RETURN(auto morph, Serialize(MorphModel(sequence, frame_rate, encoding), encoding));
  DMC_ASSIGN_OR_RETURN(auto frames,
                       Serialize(FramesModel(sequence, frame_rate, encoding), encoding));
  return morph.size() <= frames.size() ? std::move(morph) : std::move(frames);
}

}  // namespace dmc::io_internal
