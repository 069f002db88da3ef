// Internal: what the GLB writers share (gltf_export.cpp for a sequence alone, gltf_scene_export.cpp
// for a sequence with its scene record): a model builder appending to buffer 0, per-frame
// positions and normals, and the compact encoding's quantisation (KHR_mesh_quantization).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "io/gltf_format.h"
#include "io/gltf_motion_basis.h"
#include "io/utf8_text.h"

namespace dmc::io_internal::glb {

inline constexpr double kDefaultFrameRate = 30.0;

// Builds a tinygltf model whose single buffer becomes the GLB's BIN chunk.
class ModelBuilder {
 public:
  ModelBuilder() {
    model_.buffers.emplace_back();
    model_.asset.version = "2.0";
    model_.asset.generator = "dmc";
  }
  // Appends to `model`'s buffer 0 (created when it has none); nothing else changes.
  explicit ModelBuilder(tinygltf::Model model) : model_(std::move(model)) {
    if (model_.buffers.empty()) model_.buffers.emplace_back();
  }

  // Appends `bytes` as a new buffer view (4-byte aligned, as every accessor here needs).
  int AddView(const void* bytes, size_t size, int target = 0) {
    return AppendBufferView(model_, 0, bytes, size, target);
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
    // min/max are the stored integers (glTF 2.0, accessor.min); only positions need them, and
    // leaving them out of normals keeps the JSON of a many-frame file smaller.
    if (normalized) {
      accessor.minValues.clear();
      accessor.maxValues.clear();
    }
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

inline std::vector<float> FramePositions(const MeshSequence& sequence, int f) {
  const float* begin = sequence.frame(f).data();
  return {begin, begin + 3 * static_cast<size_t>(sequence.vertex_count())};
}

// Area-weighted vertex normals of frame f (unit length; +z for vertices without area, since the
// spec requires unit normals).
inline std::vector<float> FrameNormals(const MeshSequence& sequence, int f) {
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

inline std::vector<float> FrameTimes(int frame_count, double frame_rate) {
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
    Fit(lo, hi);
  }
  // A grid over the box [lo, hi], no finer than `min_step`.
  PositionGrid(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double min_step = 0) {
    Fit(lo, hi);
    step_ = std::max(step_, min_step);
  }
  double step() const { return step_; }

  std::vector<int16_t> Quantize(const MeshSequence& sequence, int f) const {
    const auto frame = sequence.frame_d(f);
    std::vector<double> values(frame.data(), frame.data() + frame.size());
    return Quantize(values);
  }
  // Points given as x, y, z, x, y, z, ...
  std::vector<int16_t> Quantize(const std::vector<double>& points) const {
    std::vector<int16_t> q(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      const double value = std::round((points[i] - center_[static_cast<long>(i % 3)]) / step_);
      q[i] = static_cast<int16_t>(std::clamp(value, -kHalfRange, kHalfRange));
    }
    return q;
  }

  // A coordinate in grid units, unrounded and unclamped.
  double ToGrid(double value, int axis) const { return (value - center_[axis]) / step_; }

  void Fit(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    center_ = 0.5 * (lo + hi);
    const double half_extent = 0.5 * (hi - lo).maxCoeff();
    step_ = half_extent > 0 ? half_extent / kHalfRange : 1.0;
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

inline std::vector<int8_t> QuantizeNormals(const std::vector<float>& normals) {
  std::vector<int8_t> q(normals.size());
  for (size_t i = 0; i < normals.size(); ++i) {
    q[i] = static_cast<int8_t>(std::clamp(std::round(normals[i] * 127.0), -127.0, 127.0));
  }
  return q;
}

// What the basis layout's fits must reproduce: positions in grid units (so within one grid step,
// half of it on average), normals in units of 1/32767 on int8 targets (within 4/127, on average
// half of 1/127, about the 8-bit base normals' own rounding).
inline constexpr FitTolerance kBasisPositionTolerance{0.5, 1.0, 32767};
inline constexpr FitTolerance kBasisNormalTolerance{0.5 * 32767.0 / 127.0, 4.0 * 32767.0 / 127.0,
                                                    127};

// Per frame, the weight of every target of a mesh.
using WeightTable = std::vector<std::vector<float>>;

// The basis layout's targets of one primitive, vertices [first, first + count) of those fitted:
// the position targets (int16 in grid units), then the normal targets (normalised int8). Each
// target has both attributes, the other one zero (one shared accessor): three.js's GLTFLoader
// fills a target's missing attribute with the base mesh's, which it then adds as a displacement.
inline void AddBasisTargets(ModelBuilder& builder, const std::vector<BlockTarget>& positions,
                            const std::vector<BlockTarget>& normals, size_t first, size_t count,
                            tinygltf::Primitive& primitive) {
  const auto slice = [&](const AxisTarget& target) {
    if (target.steps()) {
      return std::vector<int16_t>(target.values.begin() + static_cast<long>(3 * first),
                                  target.values.begin() + static_cast<long>(3 * (first + count)));
    }
    std::vector<int16_t> out(3 * count, 0);
    for (size_t v = 0; v < count; ++v) {
      out[3 * v + static_cast<size_t>(target.axis)] = target.values[first + v];
    }
    return out;
  };
  const int zero_normal =
      builder.AddPaddedVec3(std::vector<int8_t>(3 * count, 0), /*normalized=*/true);
  for (const BlockTarget& t : positions) {
    primitive.targets.push_back(
        {{"POSITION", builder.AddPaddedVec3(slice(t.target), /*normalized=*/false)},
         {"NORMAL", zero_normal}});
  }
  if (normals.empty()) return;
  const int zero_position =
      builder.AddPaddedVec3(std::vector<int16_t>(3 * count, 0), /*normalized=*/false);
  for (const BlockTarget& t : normals) {
    const std::vector<int16_t> wide = slice(t.target);  // within int8 (kBasisNormalTolerance)
    primitive.targets.push_back(
        {{"POSITION", zero_position},
         {"NORMAL", builder.AddPaddedVec3(std::vector<int8_t>(wide.begin(), wide.end()),
                                          /*normalized=*/true)}});
  }
}

// The weights of AddBasisTargets' targets, in their order.
inline WeightTable BasisWeights(const std::vector<BlockTarget>& positions,
                                const std::vector<BlockTarget>& normals,
                                std::span<const FrameBlock> blocks, int frame_count) {
  WeightTable weights = TargetWeights(positions, blocks, frame_count);
  WeightTable normal_weights = TargetWeights(normals, blocks, frame_count);
  // Fitted in units of 1/32767, stored as normalised int8 (units of 1/127); steps are int8 units.
  for (std::vector<float>& frame : normal_weights) {
    for (size_t t = 0; t < frame.size(); ++t) {
      if (!normals[t].target.steps()) frame[t] *= 127.0f / 32767.0f;
    }
  }
  for (size_t j = 0; j < weights.size(); ++j) {
    weights[j].insert(weights[j].end(), normal_weights[j].begin(), normal_weights[j].end());
  }
  return weights;
}

inline void RequireCompactExtensions(tinygltf::Model& model) {
  model.extensionsUsed.push_back("KHR_mesh_quantization");
  model.extensionsRequired.push_back("KHR_mesh_quantization");
}

inline void SetExtras(tinygltf::Model& model, const MeshSequence& sequence, const char* layout,
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

inline void AddScene(tinygltf::Model& model, const std::string& name) {
  tinygltf::Scene scene;
  scene.name = name;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
}

}  // namespace dmc::io_internal::glb
