// glTF import: accessors, node hierarchy, keyframe sampling, morph targets and skinning posed into
// a MeshSequence, with optional seam welding. The maths is summarised in gltf_format.h.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <optional>
#include <string_view>

#include "io/gltf_format.h"

namespace dmc::io_internal {
namespace {

using Matrix4 = Eigen::Matrix4d;

constexpr double kDefaultFrameRate = 30.0;

std::string AccessorLabel(int index, std::string_view what) {
  return "accessor " + std::to_string(index) + " (" + std::string(what) + ")";
}

// One component at `bytes`, converted as the spec's "normalized" rules say when `normalized`.
double ReadComponent(const unsigned char* bytes, int component_type, bool normalized) {
  auto load = [bytes]<typename T>(T) {
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  };
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = load(int8_t{});
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const double v = load(uint8_t{});
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = load(int16_t{});
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = load(uint16_t{});
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return load(uint32_t{});
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return load(float{});
    default:
      return 0.0;  // rejected by ComponentSize before any read
  }
}

int ComponentSize(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

// The bytes of buffer view `view_index` from `offset` on, checked to hold `needed` bytes.
StatusOr<const unsigned char*> ViewBytes(const tinygltf::Model& model, int view_index,
                                         size_t offset, size_t needed, const std::string& label) {
  if (view_index < 0 || static_cast<size_t>(view_index) >= model.bufferViews.size()) {
    return ParseError(label + ": buffer view " + std::to_string(view_index) + " does not exist");
  }
  const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(view_index)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) {
    return ParseError(label + ": buffer " + std::to_string(view.buffer) + " does not exist");
  }
  const tinygltf::Buffer& buffer = model.buffers[static_cast<size_t>(view.buffer)];
  if (view.byteOffset > buffer.data.size() ||
      view.byteLength > buffer.data.size() - view.byteOffset || offset > view.byteLength ||
      needed > view.byteLength - offset) {
    return ParseError(label + ": needs " + std::to_string(needed) + " bytes at offset " +
                      std::to_string(offset) + " of buffer view " + std::to_string(view_index) +
                      ", which does not hold them");
  }
  return buffer.data.data() + view.byteOffset + offset;
}

// Accessor `index` as count × components doubles (sparse substitution applied).
StatusOr<std::vector<double>> ReadAccessor(const tinygltf::Model& model, int index,
                                           std::string_view what, int* components_out = nullptr) {
  const std::string label = AccessorLabel(index, what);
  if (index < 0 || static_cast<size_t>(index) >= model.accessors.size()) {
    return ParseError(label + " does not exist");
  }
  const tinygltf::Accessor& accessor = model.accessors[static_cast<size_t>(index)];
  const int component_size = ComponentSize(accessor.componentType);
  const int components = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(accessor.type));
  if (component_size == 0 || components <= 0) {
    return ParseError(label + ": unsupported component type or element type");
  }
  if (components_out != nullptr) *components_out = components;
  const size_t count = accessor.count;
  // Bounds every size computed below (and the allocation) before the buffer checks run.
  if (count > (size_t{1} << 28)) {
    return ParseError(label + ": " + std::to_string(count) + " elements is more than dmc reads");
  }
  const size_t element_size = static_cast<size_t>(component_size) * static_cast<size_t>(components);
  // The data is located and bounds-checked before anything is allocated for it.
  const unsigned char* base = nullptr;
  size_t stride = element_size;
  if (accessor.bufferView >= 0 && count > 0) {
    if (static_cast<size_t>(accessor.bufferView) >= model.bufferViews.size()) {
      return ParseError(label + ": buffer view " + std::to_string(accessor.bufferView) +
                        " does not exist");
    }
    const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(accessor.bufferView)];
    if (view.byteStride != 0) stride = view.byteStride;
    if (stride < element_size) return ParseError(label + ": byteStride smaller than an element");
    DMC_ASSIGN_OR_RETURN(base, ViewBytes(model, accessor.bufferView, accessor.byteOffset,
                                         stride * (count - 1) + element_size, label));
  } else if (count > (size_t{1} << 24)) {
    return ParseError(label + ": " + std::to_string(count) + " elements without a buffer view");
  }
  std::vector<double> values(count * static_cast<size_t>(components), 0.0);
  if (base != nullptr) {
    for (size_t e = 0; e < count; ++e) {
      for (int c = 0; c < components; ++c) {
        values[e * static_cast<size_t>(components) + static_cast<size_t>(c)] =
            ReadComponent(base + e * stride + static_cast<size_t>(c * component_size),
                          accessor.componentType, accessor.normalized);
      }
    }
  }
  if (accessor.sparse.isSparse && accessor.sparse.count > 0) {
    const size_t sparse_count = static_cast<size_t>(accessor.sparse.count);
    const int index_type = accessor.sparse.indices.componentType;
    const int index_size = ComponentSize(index_type);
    if (index_size == 0 || index_type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
      return ParseError(label + ": sparse indices have an unsupported component type");
    }
    DMC_ASSIGN_OR_RETURN(
        const unsigned char* indices,
        ViewBytes(model, accessor.sparse.indices.bufferView,
                  static_cast<size_t>(accessor.sparse.indices.byteOffset),
                  sparse_count * static_cast<size_t>(index_size), label + " sparse indices"));
    DMC_ASSIGN_OR_RETURN(const unsigned char* sparse_values,
                         ViewBytes(model, accessor.sparse.values.bufferView,
                                   static_cast<size_t>(accessor.sparse.values.byteOffset),
                                   sparse_count * element_size, label + " sparse values"));
    for (size_t s = 0; s < sparse_count; ++s) {
      const double target = ReadComponent(indices + s * static_cast<size_t>(index_size), index_type,
                                          /*normalized=*/false);
      if (target < 0 || target >= static_cast<double>(count)) {
        return ParseError(label + ": sparse index " + std::to_string(target) + " out of range");
      }
      for (int c = 0; c < components; ++c) {
        values[static_cast<size_t>(target) * static_cast<size_t>(components) +
               static_cast<size_t>(c)] = ReadComponent(sparse_values + s * element_size +
                                                           static_cast<size_t>(c * component_size),
                                                       accessor.componentType, accessor.normalized);
      }
    }
  }
  for (double value : values) {
    if (!std::isfinite(value)) return ParseError(label + " holds a non-finite value");
  }
  return values;
}

// ----- Animation sampling -------------------------------------------------------------------

enum class Path { kTranslation, kRotation, kScale, kWeights };
enum class Interpolation { kStep, kLinear, kCubicSpline };

struct Channel {
  int node = -1;
  Path path = Path::kTranslation;
  Interpolation interpolation = Interpolation::kLinear;
  std::vector<double> times;
  std::vector<double> values;  // per key: `width` values (3 × width for CUBICSPLINE)
  int width = 0;

  // Key k's value (CUBICSPLINE: the middle of in-tangent, value, out-tangent).
  const double* Value(size_t k) const {
    const size_t w = static_cast<size_t>(width);
    return interpolation == Interpolation::kCubicSpline ? &values[(3 * k + 1) * w] : &values[k * w];
  }

  std::vector<double> Sample(double t) const {
    const size_t w = static_cast<size_t>(width);
    std::vector<double> out(w);
    const size_t keys = times.size();
    if (keys == 1 || t <= times.front()) {
      std::copy_n(Value(0), w, out.begin());
      return out;
    }
    if (t >= times.back()) {
      std::copy_n(Value(keys - 1), w, out.begin());
      return out;
    }
    const size_t k =
        static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    const double interval = times[k + 1] - times[k];
    const double s = (t - times[k]) / interval;
    const double* a = Value(k);
    const double* b = Value(k + 1);
    switch (interpolation) {
      case Interpolation::kStep:
        std::copy_n(a, w, out.begin());
        return out;
      case Interpolation::kLinear:
        if (path == Path::kRotation) {
          // glTF stores x, y, z, w; Eigen's slerp takes the shorter arc, as the spec asks.
          const Eigen::Quaterniond qa(a[3], a[0], a[1], a[2]);
          const Eigen::Quaterniond qb(b[3], b[0], b[1], b[2]);
          const Eigen::Quaterniond q = qa.normalized().slerp(s, qb.normalized());
          out = {q.x(), q.y(), q.z(), q.w()};
          return out;
        }
        for (size_t c = 0; c < w; ++c) out[c] = a[c] + s * (b[c] - a[c]);
        return out;
      case Interpolation::kCubicSpline: {
        // Hermite basis; tangents are per second, hence the interval factor (spec, appendix C).
        const double s2 = s * s, s3 = s2 * s;
        const double* out_tangent_a = a + w;  // k's out-tangent follows its value
        const double* in_tangent_b = b - w;   // k+1's in-tangent precedes its value
        for (size_t c = 0; c < w; ++c) {
          out[c] = (2 * s3 - 3 * s2 + 1) * a[c] + (s3 - 2 * s2 + s) * interval * out_tangent_a[c] +
                   (-2 * s3 + 3 * s2) * b[c] + (s3 - s2) * interval * in_tangent_b[c];
        }
        if (path == Path::kRotation) {
          const double norm =
              std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
          if (norm > 0) {
            for (double& value : out) value /= norm;
          }
        }
        return out;
      }
    }
    return out;
  }
};

StatusOr<std::vector<Channel>> LoadChannels(const tinygltf::Model& model,
                                            const tinygltf::Animation& animation,
                                            const std::string& animation_label) {
  std::vector<Channel> channels;
  for (size_t c = 0; c < animation.channels.size(); ++c) {
    const tinygltf::AnimationChannel& source = animation.channels[c];
    const std::string label = animation_label + ", channel " + std::to_string(c);
    if (source.target_node < 0) continue;  // targets an extension object: nothing to pose
    if (static_cast<size_t>(source.target_node) >= model.nodes.size()) {
      return ParseError(label + ": node " + std::to_string(source.target_node) + " does not exist");
    }
    if (source.sampler < 0 || static_cast<size_t>(source.sampler) >= animation.samplers.size()) {
      return ParseError(label + ": sampler " + std::to_string(source.sampler) + " does not exist");
    }
    const tinygltf::AnimationSampler& sampler =
        animation.samplers[static_cast<size_t>(source.sampler)];
    Channel channel;
    channel.node = source.target_node;
    if (source.target_path == "translation") {
      channel.path = Path::kTranslation;
    } else if (source.target_path == "rotation") {
      channel.path = Path::kRotation;
    } else if (source.target_path == "scale") {
      channel.path = Path::kScale;
    } else if (source.target_path == "weights") {
      channel.path = Path::kWeights;
    } else {
      continue;  // "pointer" and other extension paths do not move vertices of plain glTF
    }
    if (sampler.interpolation == "STEP") {
      channel.interpolation = Interpolation::kStep;
    } else if (sampler.interpolation == "CUBICSPLINE") {
      channel.interpolation = Interpolation::kCubicSpline;
    } else if (sampler.interpolation == "LINEAR" || sampler.interpolation.empty()) {
      channel.interpolation = Interpolation::kLinear;
    } else {
      return ParseError(label + ": unknown interpolation '" + sampler.interpolation + "'");
    }
    DMC_ASSIGN_OR_RETURN(channel.times, ReadAccessor(model, sampler.input, "animation input"));
    int output_components = 0;
    DMC_ASSIGN_OR_RETURN(channel.values, ReadAccessor(model, sampler.output, "animation output",
                                                      &output_components));
    if (channel.times.empty()) return ParseError(label + ": no keyframes");
    for (size_t k = 1; k < channel.times.size(); ++k) {
      if (!(channel.times[k] > channel.times[k - 1])) {
        return ParseError(label + ": keyframe times are not strictly increasing at key " +
                          std::to_string(k));
      }
    }
    const size_t per_key = channel.interpolation == Interpolation::kCubicSpline ? 3 : 1;
    const size_t keys = channel.times.size();
    if (channel.values.size() % (keys * per_key) != 0) {
      return ParseError(label + ": " + std::to_string(channel.values.size()) +
                        " output values do not divide into " + std::to_string(keys) + " keys");
    }
    channel.width = static_cast<int>(channel.values.size() / (keys * per_key));
    const int expected = channel.path == Path::kRotation  ? 4
                         : channel.path == Path::kWeights ? channel.width
                                                          : 3;
    if (channel.width != expected || channel.width == 0 || output_components <= 0) {
      return ParseError(label + ": " + std::to_string(channel.width) +
                        " values per key, expected " + std::to_string(expected));
    }
    channels.push_back(std::move(channel));
  }
  return channels;
}

// ----- Scene ---------------------------------------------------------------------------------

struct NodePose {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  std::optional<Matrix4> matrix;  // a static `matrix` node (animated paths do not apply to it)
  std::vector<double> weights;

  Matrix4 Local() const {
    if (matrix) return *matrix;
    Eigen::Affine3d transform = Eigen::Translation3d(translation) * rotation * scale.asDiagonal();
    return transform.matrix();
  }
};

NodePose StaticPose(const tinygltf::Node& node) {
  NodePose pose;
  if (node.matrix.size() == 16) {
    pose.matrix = Eigen::Map<const Matrix4>(node.matrix.data());  // column-major, as glTF
  }
  if (node.translation.size() == 3) {
    pose.translation =
        Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]);
  }
  if (node.rotation.size() == 4) {
    pose.rotation =
        Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2])
            .normalized();
  }
  if (node.scale.size() == 3)
    pose.scale = Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]);
  pose.weights = node.weights;
  return pose;
}

// One triangle primitive of one mesh node, with everything its vertices need per frame.
struct PrimitiveInstance {
  int node = -1;
  int skin = -1;
  int vertex_offset = 0;
  int vertex_count = 0;
  std::vector<double> positions;             // 3 per vertex, mesh space
  std::vector<std::vector<double>> targets;  // per morph target: 3 per vertex
  std::vector<double> default_weights;       // mesh.weights
  // Skin influences, `influences` per vertex: joint slot (index into skin.joints) and weight.
  int influences = 0;
  std::vector<int> joints;
  std::vector<double> weights;
};

Status AppendTriangles(const tinygltf::Primitive& primitive, const std::vector<double>& indices,
                       int vertex_count, int offset, std::vector<int32_t>& triangles,
                       const std::string& label) {
  std::vector<int32_t> corner;
  corner.reserve(indices.size());
  for (double index : indices) {
    if (index < 0 || index >= vertex_count) {
      return ParseError(label + ": index " + std::to_string(static_cast<long long>(index)) +
                        " is outside the primitive's " + std::to_string(vertex_count) +
                        " vertices");
    }
    corner.push_back(static_cast<int32_t>(index) + offset);
  }
  const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
  const size_t n = corner.size();
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    triangles.insert(triangles.end(), corner.begin(),
                     corner.begin() + static_cast<long>(n / 3 * 3));
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 0; i + 2 < n; ++i) {
      // Every other triangle of a strip is flipped back to the strip's orientation.
      if (i % 2 == 0) {
        triangles.insert(triangles.end(), {corner[i], corner[i + 1], corner[i + 2]});
      } else {
        triangles.insert(triangles.end(), {corner[i + 1], corner[i], corner[i + 2]});
      }
    }
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (size_t i = 1; i + 1 < n; ++i) {
      triangles.insert(triangles.end(), {corner[0], corner[i], corner[i + 1]});
    }
  }
  return Status::Ok();
}

bool IsTriangleMode(int mode) {
  return mode < 0 || mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
         mode == TINYGLTF_MODE_TRIANGLE_FAN;
}

StatusOr<int> FindAnimation(const tinygltf::Model& model, const std::string& wanted) {
  if (model.animations.empty()) {
    if (!wanted.empty()) {
      return InvalidArgumentError("the file has no animation, so none named '" + wanted + "'");
    }
    return -1;
  }
  if (wanted.empty()) return 0;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    if (model.animations[a].name == wanted) return static_cast<int>(a);
  }
  if (std::all_of(wanted.begin(), wanted.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
      wanted.size() < 9) {
    const int index = std::stoi(wanted);
    if (static_cast<size_t>(index) < model.animations.size()) return index;
  }
  std::string names;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    names += (a ? ", " : "") + (model.animations[a].name.empty() ? "#" + std::to_string(a)
                                                                 : model.animations[a].name);
  }
  return InvalidArgumentError("no animation named '" + wanted + "' (the file has " + names + ")");
}

// Welds vertices whose trajectories coincide within `tolerance` in every frame. Returns the map
// old vertex -> new vertex (new vertices numbered by first occurrence).
std::vector<int32_t> WeldMap(const MeshSequence& sequence, double tolerance) {
  const int vertex_count = sequence.vertex_count();
  const auto frame0 = sequence.frame(0);
  std::vector<int32_t> by_x(static_cast<size_t>(vertex_count));
  std::iota(by_x.begin(), by_x.end(), 0);
  std::sort(by_x.begin(), by_x.end(), [&](int32_t a, int32_t b) {
    return frame0(a, 0) < frame0(b, 0) || (frame0(a, 0) == frame0(b, 0) && a < b);
  });
  // root[v] == v for a group's first-swept vertex; every other member points straight at it.
  std::vector<int32_t> root(static_cast<size_t>(vertex_count));
  std::iota(root.begin(), root.end(), 0);
  auto same_trajectory = [&](int a, int b) {
    for (int f = 0; f < sequence.frame_count(); ++f) {
      const auto frame = sequence.frame(f);
      for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(static_cast<double>(frame(a, axis)) - frame(b, axis)) > tolerance) {
          return false;
        }
      }
    }
    return true;
  };
  // Sweep in x order: a vertex's candidates lie within `tolerance` of it in x.
  for (size_t i = 0; i < by_x.size(); ++i) {
    const int v = by_x[i];
    for (size_t j = i; j-- > 0;) {
      const int u = by_x[j];
      if (static_cast<double>(frame0(v, 0)) - frame0(u, 0) > tolerance) break;
      if (root[static_cast<size_t>(u)] == u && same_trajectory(u, v)) {
        root[static_cast<size_t>(v)] = u;
        break;
      }
    }
  }
  // New indices by first occurrence in file order.
  std::vector<int32_t> map(static_cast<size_t>(vertex_count), -1);
  std::vector<int32_t> group_index(static_cast<size_t>(vertex_count), -1);
  int32_t next = 0;
  for (int v = 0; v < vertex_count; ++v) {
    int32_t& index = group_index[static_cast<size_t>(root[static_cast<size_t>(v)])];
    if (index < 0) index = next++;
    map[static_cast<size_t>(v)] = index;
  }
  return map;
}

// `value[key]`, or a null value when `value` is not an object or has no such member (tinygltf's
// Value::Get asserts on non-objects).
const tinygltf::Value& Member(const tinygltf::Value& value, const char* key) {
  static const tinygltf::Value kNull;
  return value.IsObject() && value.Has(key) ? value.Get(key) : kNull;
}

// The sequence of a dmc "frames" export (see gltf_export.cpp): mesh f holds frame f, all sharing
// one index accessor. Posing the file instead would give every frame mesh at once.
StatusOr<GltfImport> ReadFramesExport(const tinygltf::Model& model, const GltfReadOptions& options,
                                      int max_frames) {
  int frame_count = static_cast<int>(model.meshes.size());
  if (max_frames > 0) frame_count = std::min(frame_count, max_frames);
  GltfImport result;
  for (int f = 0; f < frame_count; ++f) {
    const auto& primitives = model.meshes[static_cast<size_t>(f)].primitives;
    const std::string label = "frame mesh " + std::to_string(f);
    if (primitives.size() != 1 || !primitives[0].attributes.count("POSITION")) {
      return ParseError(label + ": expected one primitive with POSITION");
    }
    DMC_ASSIGN_OR_RETURN(
        const std::vector<double> positions,
        ReadAccessor(model, primitives[0].attributes.at("POSITION"), label + " POSITION"));
    if (f == 0) {
      DMC_ASSIGN_OR_RETURN(const std::vector<double> indices,
                           ReadAccessor(model, primitives[0].indices, label + " indices"));
      std::vector<int32_t> triangles;
      const int vertex_count = static_cast<int>(positions.size() / 3);
      DMC_RETURN_IF_ERROR(
          AppendTriangles(primitives[0], indices, vertex_count, 0, triangles, label));
      Triangles matrix(static_cast<Eigen::Index>(triangles.size() / 3), 3);
      std::copy(triangles.begin(), triangles.end(), matrix.data());
      result.sequence = MeshSequence(vertex_count, matrix, frame_count);
      result.sequence.frame_rate = options.frame_rate;
      result.vertex_map.resize(static_cast<size_t>(vertex_count));
      std::iota(result.vertex_map.begin(), result.vertex_map.end(), 0);
    }
    if (positions.size() != 3 * static_cast<size_t>(result.sequence.vertex_count())) {
      return ParseError(label + ": " + std::to_string(positions.size() / 3) +
                        " vertices, frame 0 has " + std::to_string(result.sequence.vertex_count()));
    }
    float* frame = result.sequence.frame(f).data();
    for (size_t i = 0; i < positions.size(); ++i) frame[i] = static_cast<float>(positions[i]);
  }
  if (frame_count == 0) return UnsupportedError("the dmc frames export holds no frame");
  return result;
}

}  // namespace

StatusOr<tinygltf::Model> LoadGltfModel(const std::filesystem::path& path) {
  tinygltf::TinyGLTF loader;
  // dmc needs no pixels: images stay undecoded.
  loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int,
                           const unsigned char*, int, void*) { return true; },
                        nullptr);
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return IoError("cannot open " + path.string() + ": not a readable file");
  }
  tinygltf::Model model;
  std::string errors, warnings;
  const bool ok = LowercaseExtension(path) == ".glb"
                      ? loader.LoadBinaryFromFile(&model, &errors, &warnings, path.string())
                      : loader.LoadASCIIFromFile(&model, &errors, &warnings, path.string());
  if (!ok) {
    while (!errors.empty() && errors.back() == '\n') errors.pop_back();
    return ParseError(path.string() + ": " + (errors.empty() ? "not a glTF 2.0 file" : errors));
  }
  return model;
}

StatusOr<GltfImport> PoseGltfModel(const tinygltf::Model& model, const GltfReadOptions& requested,
                                   int max_frames) {
  if (!(requested.frame_rate >= 0) || !std::isfinite(requested.frame_rate)) {
    return InvalidArgumentError("glTF frame rate must be positive (or 0: automatic), got " +
                                std::to_string(requested.frame_rate));
  }
  const tinygltf::Value& dmc_extras = Member(model.asset.extras, "dmc");
  GltfReadOptions options = requested;
  if (options.frame_rate == 0) {
    const tinygltf::Value& recorded = Member(dmc_extras, "frame_rate");
    options.frame_rate = recorded.IsNumber() && recorded.GetNumberAsDouble() > 0
                             ? recorded.GetNumberAsDouble()
                             : kDefaultFrameRate;
  }
  // A dmc "frames" export shows one mesh per frame in turn; its sequence is those meshes.
  const tinygltf::Value& layout = Member(dmc_extras, "layout");
  if (layout.IsString() && layout.Get<std::string>() == "frames" && options.mesh.empty()) {
    return ReadFramesExport(model, options, max_frames);
  }
  const size_t node_count = model.nodes.size();
  GltfImport result;

  // Scene roots: the default scene, else the first, else every node that is nobody's child.
  std::vector<int> parent(node_count, -1);
  for (size_t n = 0; n < node_count; ++n) {
    for (int child : model.nodes[n].children) {
      if (child < 0 || static_cast<size_t>(child) >= node_count ||
          parent[static_cast<size_t>(child)] != -1) {
        return ParseError("node " + std::to_string(n) + ": child " + std::to_string(child) +
                          " does not exist or has two parents");
      }
      parent[static_cast<size_t>(child)] = static_cast<int>(n);
    }
  }
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const size_t scene =
        model.defaultScene >= 0 && static_cast<size_t>(model.defaultScene) < model.scenes.size()
            ? static_cast<size_t>(model.defaultScene)
            : 0;
    roots = model.scenes[scene].nodes;
  } else {
    for (size_t n = 0; n < node_count; ++n) {
      if (parent[n] == -1) roots.push_back(static_cast<int>(n));
    }
  }
  // Depth-first order from the roots: parents before children, and the import order of meshes.
  std::vector<int> order;
  std::vector<char> visited(node_count, 0);
  std::vector<int> stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    if (n < 0 || static_cast<size_t>(n) >= node_count) {
      return ParseError("scene node " + std::to_string(n) + " does not exist");
    }
    if (visited[static_cast<size_t>(n)])
      return ParseError("node " + std::to_string(n) + " is reached twice");
    visited[static_cast<size_t>(n)] = 1;
    order.push_back(n);
    const auto& children = model.nodes[static_cast<size_t>(n)].children;
    stack.insert(stack.end(), children.rbegin(), children.rend());
  }

  // The primitives to import.
  std::vector<PrimitiveInstance> instances;
  std::vector<int32_t> triangles;
  int vertex_total = 0;
  bool name_matched = false;
  for (int n : order) {
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(n)];
    if (node.mesh < 0) continue;
    if (static_cast<size_t>(node.mesh) >= model.meshes.size()) {
      return ParseError("node " + std::to_string(n) + ": mesh " + std::to_string(node.mesh) +
                        " does not exist");
    }
    const tinygltf::Mesh& mesh = model.meshes[static_cast<size_t>(node.mesh)];
    if (!options.mesh.empty() && mesh.name != options.mesh && node.name != options.mesh) continue;
    name_matched = true;
    if (node.skin >= 0 && static_cast<size_t>(node.skin) >= model.skins.size()) {
      return ParseError("node " + std::to_string(n) + ": skin " + std::to_string(node.skin) +
                        " does not exist");
    }
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& primitive = mesh.primitives[p];
      const std::string label = "mesh " + std::to_string(node.mesh) +
                                (mesh.name.empty() ? "" : " '" + mesh.name + "'") + ", primitive " +
                                std::to_string(p);
      if (!IsTriangleMode(primitive.mode)) {
        result.warnings.push_back(label + ": points or lines skipped");
        continue;
      }
      const auto position = primitive.attributes.find("POSITION");
      if (position == primitive.attributes.end()) {
        result.warnings.push_back(label + ": no POSITION attribute, skipped");
        continue;
      }
      PrimitiveInstance instance;
      instance.node = n;
      instance.skin = node.skin;
      instance.vertex_offset = vertex_total;
      int components = 0;
      DMC_ASSIGN_OR_RETURN(instance.positions,
                           ReadAccessor(model, position->second, label + " POSITION", &components));
      if (components != 3) return ParseError(label + ": POSITION is not VEC3");
      instance.vertex_count = static_cast<int>(instance.positions.size() / 3);
      std::vector<double> indices;
      if (primitive.indices >= 0) {
        DMC_ASSIGN_OR_RETURN(indices, ReadAccessor(model, primitive.indices, label + " indices"));
      } else {
        indices.resize(static_cast<size_t>(instance.vertex_count));
        std::iota(indices.begin(), indices.end(), 0.0);
      }
      DMC_RETURN_IF_ERROR(AppendTriangles(primitive, indices, instance.vertex_count, vertex_total,
                                          triangles, label));
      for (size_t t = 0; t < primitive.targets.size(); ++t) {
        const auto target = primitive.targets[t].find("POSITION");
        if (target == primitive.targets[t].end()) {
          instance.targets.emplace_back(instance.positions.size(), 0.0);
          continue;
        }
        DMC_ASSIGN_OR_RETURN(auto deltas, ReadAccessor(model, target->second,
                                                       label + " target " + std::to_string(t)));
        if (deltas.size() != instance.positions.size()) {
          return ParseError(label + ": morph target " + std::to_string(t) + " has " +
                            std::to_string(deltas.size() / 3) + " positions, expected " +
                            std::to_string(instance.vertex_count));
        }
        instance.targets.push_back(std::move(deltas));
      }
      instance.default_weights = mesh.weights;
      if (node.skin >= 0) {
        const size_t joint_count = model.skins[static_cast<size_t>(node.skin)].joints.size();
        for (int set = 0;; ++set) {
          const auto joints = primitive.attributes.find("JOINTS_" + std::to_string(set));
          const auto weights = primitive.attributes.find("WEIGHTS_" + std::to_string(set));
          if (joints == primitive.attributes.end() || weights == primitive.attributes.end()) break;
          DMC_ASSIGN_OR_RETURN(auto joint_values,
                               ReadAccessor(model, joints->second, label + " JOINTS"));
          DMC_ASSIGN_OR_RETURN(auto weight_values,
                               ReadAccessor(model, weights->second, label + " WEIGHTS"));
          if (joint_values.size() != 4 * static_cast<size_t>(instance.vertex_count) ||
              weight_values.size() != joint_values.size()) {
            return ParseError(label + ": JOINTS_" + std::to_string(set) + "/WEIGHTS_" +
                              std::to_string(set) + " are not VEC4 per vertex");
          }
          instance.influences += 4;
          for (double j : joint_values) {
            if (j < 0 || j >= static_cast<double>(joint_count)) {
              return ParseError(label + ": joint " + std::to_string(j) + " outside the skin's " +
                                std::to_string(joint_count) + " joints");
            }
          }
          // Interleave the sets per vertex: vertex v's influences are contiguous.
          std::vector<int> merged_joints;
          std::vector<double> merged_weights;
          const int old = instance.influences - 4;
          for (int v = 0; v < instance.vertex_count; ++v) {
            for (int k = 0; k < old; ++k) {
              merged_joints.push_back(instance.joints[static_cast<size_t>(v * old + k)]);
              merged_weights.push_back(instance.weights[static_cast<size_t>(v * old + k)]);
            }
            for (int k = 0; k < 4; ++k) {
              merged_joints.push_back(
                  static_cast<int>(joint_values[static_cast<size_t>(4 * v + k)]));
              merged_weights.push_back(weight_values[static_cast<size_t>(4 * v + k)]);
            }
          }
          instance.joints = std::move(merged_joints);
          instance.weights = std::move(merged_weights);
        }
        if (instance.influences == 0) {
          result.warnings.push_back(label +
                                    ": skinned node without JOINTS_0/WEIGHTS_0; posed by "
                                    "its node transform");
          instance.skin = -1;
        }
      }
      vertex_total += instance.vertex_count;
      instances.push_back(std::move(instance));
    }
  }
  if (!options.mesh.empty() && !name_matched) {
    std::string names;
    for (const auto& mesh : model.meshes) names += (names.empty() ? "" : ", ") + mesh.name;
    return InvalidArgumentError("no mesh or node named '" + options.mesh + "' (meshes: " + names +
                                ")");
  }
  if (instances.empty() || triangles.empty()) {
    return UnsupportedError("the glTF scene holds no triangle mesh to import");
  }

  // Inverse bind matrices of the skins used.
  std::vector<std::vector<Matrix4>> inverse_binds(model.skins.size());
  for (const auto& instance : instances) {
    if (instance.skin < 0 || !inverse_binds[static_cast<size_t>(instance.skin)].empty()) continue;
    const tinygltf::Skin& skin = model.skins[static_cast<size_t>(instance.skin)];
    auto& matrices = inverse_binds[static_cast<size_t>(instance.skin)];
    matrices.assign(skin.joints.size(), Matrix4::Identity());
    for (int joint : skin.joints) {
      if (joint < 0 || static_cast<size_t>(joint) >= node_count) {
        return ParseError("skin " + std::to_string(instance.skin) + ": joint node " +
                          std::to_string(joint) + " does not exist");
      }
    }
    if (skin.inverseBindMatrices >= 0) {
      DMC_ASSIGN_OR_RETURN(auto values,
                           ReadAccessor(model, skin.inverseBindMatrices, "inverse bind matrices"));
      if (values.size() != 16 * skin.joints.size()) {
        return ParseError("skin " + std::to_string(instance.skin) + ": " +
                          std::to_string(values.size() / 16) + " inverse bind matrices for " +
                          std::to_string(skin.joints.size()) + " joints");
      }
      for (size_t j = 0; j < skin.joints.size(); ++j) {
        matrices[j] = Eigen::Map<const Matrix4>(values.data() + 16 * j);
      }
    }
  }

  // Animation and frame times.
  DMC_ASSIGN_OR_RETURN(const int animation_index, FindAnimation(model, options.animation));
  std::vector<Channel> channels;
  double start = 0.0, end = 0.0;
  if (animation_index >= 0) {
    const tinygltf::Animation& animation = model.animations[static_cast<size_t>(animation_index)];
    DMC_ASSIGN_OR_RETURN(
        channels, LoadChannels(model, animation, "animation " + std::to_string(animation_index)));
    bool first = true;
    for (const Channel& channel : channels) {
      start = first ? channel.times.front() : std::min(start, channel.times.front());
      end = first ? channel.times.back() : std::max(end, channel.times.back());
      first = false;
    }
  }
  // A frame at every 1/fps from the start, the last one no later than the end. Key times are
  // float32 (glTF accessors), so start and end each carry up to 2^-24 of their magnitude in
  // rounding: twice that is the slack (in frames), so a clip whose last key is at (F − 1)/fps has
  // its F-th frame (an exported 59-frame, 30 fps sequence read back with 58 frames under 1e-9 of
  // slack).
  const double span = (end - start) * options.frame_rate;
  if (span > 1e7) return InvalidArgumentError("the animation would need more than 10^7 frames");
  const double slack = std::ldexp(std::abs(start) + std::abs(end), -23) * options.frame_rate + 1e-9;
  int frame_count = static_cast<int>(std::floor(span + slack)) + 1;
  if (max_frames > 0) frame_count = std::min(frame_count, max_frames);

  const Triangles triangle_matrix = [&] {
    Triangles t(static_cast<Eigen::Index>(triangles.size() / 3), 3);
    std::copy(triangles.begin(), triangles.end(), t.data());
    return t;
  }();
  MeshSequence sequence(vertex_total, triangle_matrix, frame_count);
  sequence.frame_rate = options.frame_rate;

  std::vector<NodePose> static_poses;
  static_poses.reserve(node_count);
  for (const auto& node : model.nodes) static_poses.push_back(StaticPose(node));
  std::vector<NodePose> poses;
  std::vector<Matrix4> globals(node_count, Matrix4::Identity());
  std::vector<std::vector<Matrix4>> joint_matrices(model.skins.size());
  for (int f = 0; f < frame_count; ++f) {
    const double time = start + f / options.frame_rate;
    poses = static_poses;
    for (const Channel& channel : channels) {
      NodePose& pose = poses[static_cast<size_t>(channel.node)];
      const std::vector<double> value = channel.Sample(time);
      switch (channel.path) {
        case Path::kTranslation:
          pose.translation = Eigen::Vector3d(value[0], value[1], value[2]);
          break;
        case Path::kRotation:
          pose.rotation = Eigen::Quaterniond(value[3], value[0], value[1], value[2]).normalized();
          break;
        case Path::kScale:
          pose.scale = Eigen::Vector3d(value[0], value[1], value[2]);
          break;
        case Path::kWeights:
          pose.weights = value;
          break;
      }
    }
    for (int n : order) {
      const int p = parent[static_cast<size_t>(n)];
      const Matrix4 local = poses[static_cast<size_t>(n)].Local();
      globals[static_cast<size_t>(n)] =
          p >= 0 ? Matrix4(globals[static_cast<size_t>(p)] * local) : local;
    }
    for (size_t s = 0; s < model.skins.size(); ++s) {
      if (inverse_binds[s].empty()) continue;
      const auto& joints = model.skins[s].joints;
      joint_matrices[s].resize(joints.size());
      for (size_t j = 0; j < joints.size(); ++j) {
        joint_matrices[s][j] = globals[static_cast<size_t>(joints[j])] * inverse_binds[s][j];
      }
    }
    auto frame = sequence.frame(f);
    for (const PrimitiveInstance& instance : instances) {
      const NodePose& pose = poses[static_cast<size_t>(instance.node)];
      const std::vector<double>& weights =
          !pose.weights.empty() ? pose.weights : instance.default_weights;
      for (int v = 0; v < instance.vertex_count; ++v) {
        const size_t base = 3 * static_cast<size_t>(v);
        Eigen::Vector4d point(instance.positions[base], instance.positions[base + 1],
                              instance.positions[base + 2], 1.0);
        for (size_t t = 0; t < instance.targets.size() && t < weights.size(); ++t) {
          if (weights[t] == 0.0) continue;
          for (int axis = 0; axis < 3; ++axis)
            point[axis] += weights[t] * instance.targets[t][base + static_cast<size_t>(axis)];
        }
        Eigen::Vector4d posed;
        if (instance.skin >= 0) {
          posed.setZero();
          const auto& matrices = joint_matrices[static_cast<size_t>(instance.skin)];
          for (int k = 0; k < instance.influences; ++k) {
            const size_t slot = static_cast<size_t>(v * instance.influences + k);
            const double w = instance.weights[slot];
            if (w != 0.0)
              posed += w * (matrices[static_cast<size_t>(instance.joints[slot])] * point);
          }
        } else {
          posed = globals[static_cast<size_t>(instance.node)] * point;
        }
        for (int axis = 0; axis < 3; ++axis) {
          frame(instance.vertex_offset + v, axis) = static_cast<float>(posed[axis]);
        }
      }
    }
  }

  result.vertex_map.resize(static_cast<size_t>(vertex_total));
  std::iota(result.vertex_map.begin(), result.vertex_map.end(), 0);
  if (options.weld) {
    const double tolerance = 1e-6 * ComputeBoundingBox(sequence).diagonal();
    result.vertex_map = WeldMap(sequence, tolerance);
    const int welded_count =
        vertex_total == 0
            ? 0
            : *std::max_element(result.vertex_map.begin(), result.vertex_map.end()) + 1;
    std::vector<int32_t> kept;
    int collapsed = 0;
    for (size_t t = 0; t < triangles.size(); t += 3) {
      const int32_t a = result.vertex_map[static_cast<size_t>(triangles[t])];
      const int32_t b = result.vertex_map[static_cast<size_t>(triangles[t + 1])];
      const int32_t c = result.vertex_map[static_cast<size_t>(triangles[t + 2])];
      if (a == b || b == c || a == c) {
        ++collapsed;
        continue;
      }
      kept.insert(kept.end(), {a, b, c});
    }
    if (kept.empty()) return UnsupportedError("welding collapsed every triangle");
    Triangles welded_triangles(static_cast<Eigen::Index>(kept.size() / 3), 3);
    std::copy(kept.begin(), kept.end(), welded_triangles.data());
    MeshSequence welded(welded_count, welded_triangles, frame_count);
    welded.frame_rate = sequence.frame_rate;
    for (int f = 0; f < frame_count; ++f) {
      auto source = sequence.frame(f);
      auto target = welded.frame(f);
      for (int v = 0; v < vertex_total; ++v)
        target.row(result.vertex_map[static_cast<size_t>(v)]) = source.row(v);
    }
    result.warnings.push_back(
        "welded " + std::to_string(vertex_total) + " vertices into " +
        std::to_string(welded_count) +
        (collapsed ? ", dropping " + std::to_string(collapsed) + " triangle(s) that collapsed"
                   : std::string()));
    sequence = std::move(welded);
  }
  result.sequence = std::move(sequence);
  return result;
}

StatusOr<GltfImport> ReadGltf(const std::filesystem::path& path, const GltfReadOptions& options,
                              int max_frames) {
  DMC_ASSIGN_OR_RETURN(const tinygltf::Model model, LoadGltfModel(path));
  StatusOr<GltfImport> result = PoseGltfModel(model, options, max_frames);
  if (!result.ok()) return result.status().WithContext(path.string());
  return result;
}

}  // namespace dmc::io_internal
