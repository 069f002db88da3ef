// glTF accessors (typed, strided, normalised, sparse) read as doubles, and primitives' index
// lists as triangles.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal::gltf {
namespace {

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

// Substitutes the sparse elements of `accessor` into `values` (count × components).
Status ApplySparse(const tinygltf::Model& model, const tinygltf::Accessor& accessor,
                   const std::string& label, int components, int component_size,
                   std::vector<double>& values) {
  const size_t count = accessor.count;
  const size_t element_size = static_cast<size_t>(component_size) * static_cast<size_t>(components);
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
             static_cast<size_t>(c)] =
          ReadComponent(sparse_values + s * element_size + static_cast<size_t>(c * component_size),
                        accessor.componentType, accessor.normalized);
    }
  }
  return Status::Ok();
}

}  // namespace

StatusOr<std::vector<double>> ReadAccessor(const tinygltf::Model& model, int index,
                                           std::string_view what, int* components_out) {
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
    DMC_RETURN_IF_ERROR(ApplySparse(model, accessor, label, components, component_size, values));
  }
  for (double value : values) {
    if (!std::isfinite(value)) return ParseError(label + " holds a non-finite value");
  }
  return values;
}

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

Triangles ToTriangles(const std::vector<int32_t>& indices) {
  Triangles triangles(static_cast<Eigen::Index>(indices.size() / 3), 3);
  std::copy(indices.begin(), indices.end(), triangles.data());
  return triangles;
}

}  // namespace dmc::io_internal::gltf
