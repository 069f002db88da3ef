// EXT_meshopt_compression packing of an exported model: every buffer view of vertex data, keys or
// indices is compressed with meshoptimizer's vertex or index codec into the GLB's BIN chunk
// (buffer 0), and points at a data-less fallback buffer (buffer 1) holding its decoded layout, as
// the extension defines; other views (images, byte indices) stay in the BIN chunk as they are.
#include <meshoptimizer.h>

#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "io/gltf_format.h"

namespace dmc::io_internal {
namespace {

constexpr const char* kMeshopt = "EXT_meshopt_compression";

size_t ComponentBytes(int component_type) {
  return static_cast<size_t>(
      tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(component_type)));
}

void AddExtensionName(std::vector<std::string>& names, const std::string& name) {
  if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
}

// Packs the vertex-attribute views of one byte stride, and the views of other accessors (keys,
// weights) of one element size, into shared views, in order: every compressed view costs an
// extension entry (about 200 bytes of JSON), which for a few hundred morph targets outweighs their
// data. Index views and views that images or sparse accessors use stay as they are. A shared view
// holds at most 64 MiB.
void MergeViews(tinygltf::Model& model) {
  constexpr size_t kMaxShared = size_t{64} << 20;
  const size_t view_count = model.bufferViews.size();
  std::vector<size_t> element(view_count, 0);  // the element size its accessors share; 0: mixed
  std::vector<char> eligible(view_count, 0);
  for (const tinygltf::Accessor& accessor : model.accessors) {
    if (accessor.bufferView < 0 || static_cast<size_t>(accessor.bufferView) >= view_count) continue;
    const auto v = static_cast<size_t>(accessor.bufferView);
    const size_t size =
        ComponentBytes(accessor.componentType) *
        static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(accessor.type)));
    if (eligible[v] == 0 && element[v] == 0) {
      element[v] = size;
      eligible[v] = 1;
    } else if (element[v] != size) {
      eligible[v] = -1;
    }
  }
  const auto exclude = [&](int view) {
    if (view >= 0 && static_cast<size_t>(view) < view_count)
      eligible[static_cast<size_t>(view)] = -1;
  };
  for (const tinygltf::Image& image : model.images) exclude(image.bufferView);
  for (const tinygltf::Accessor& accessor : model.accessors) {
    if (accessor.sparse.isSparse) {
      exclude(accessor.bufferView);
      exclude(accessor.sparse.indices.bufferView);
      exclude(accessor.sparse.values.bufferView);
    }
  }
  // Views of vertex attributes: shared, they need a byteStride (a multiple of 4).
  std::vector<char> vertex_data(view_count, 0);
  const auto view_of = [&](int accessor) {
    return accessor >= 0 && static_cast<size_t>(accessor) < model.accessors.size()
               ? model.accessors[static_cast<size_t>(accessor)].bufferView
               : -1;
  };
  for (const tinygltf::Mesh& mesh : model.meshes) {
    for (const tinygltf::Primitive& primitive : mesh.primitives) {
      exclude(view_of(primitive.indices));
      std::vector<int> attributes;
      for (const auto& [name, accessor] : primitive.attributes) attributes.push_back(accessor);
      for (const auto& target : primitive.targets) {
        for (const auto& [name, accessor] : target) attributes.push_back(accessor);
      }
      for (const int accessor : attributes) {
        const int view = view_of(accessor);
        if (view < 0 || static_cast<size_t>(view) >= view_count) continue;
        vertex_data[static_cast<size_t>(view)] = 1;
        if (model.bufferViews[static_cast<size_t>(view)].byteStride == 0 &&
            element[static_cast<size_t>(view)] % 4 != 0) {
          exclude(view);
        }
      }
    }
  }
  const std::vector<unsigned char>& raw = model.buffers[0].data;
  std::vector<unsigned char> data;
  std::vector<tinygltf::BufferView> views;
  std::vector<int> new_view(view_count, -1);
  std::vector<size_t> offset_in_view(view_count, 0);
  std::map<std::tuple<size_t, int, size_t>, int> open;  // (stride, target, element) → shared view
  std::vector<std::vector<unsigned char>> shared;       // bytes of each shared view so far
  std::vector<int> shared_view;                         // its index in `views`
  for (size_t v = 0; v < view_count; ++v) {
    const tinygltf::BufferView& view = model.bufferViews[v];
    const size_t unit = view.byteStride != 0 ? view.byteStride : element[v];
    const bool merge = eligible[v] == 1 && view.buffer == 0 && unit != 0 &&
                       view.byteLength % unit == 0 &&
                       view.byteOffset + view.byteLength <= raw.size();
    if (!merge) {
      tinygltf::BufferView copy = view;
      new_view[v] = static_cast<int>(views.size());
      if (view.buffer == 0 && view.byteOffset + view.byteLength <= raw.size()) {
        while (data.size() % 4 != 0) data.push_back(0);
        copy.byteOffset = data.size();
        data.insert(data.end(), raw.begin() + static_cast<long>(view.byteOffset),
                    raw.begin() + static_cast<long>(view.byteOffset + view.byteLength));
      }
      views.push_back(copy);
      continue;
    }
    const size_t stride =
        view.byteStride != 0 ? view.byteStride : (vertex_data[v] ? element[v] : 0);
    const auto key = std::make_tuple(stride, view.target, element[v]);
    auto found = open.find(key);
    if (found == open.end() ||
        shared[static_cast<size_t>(found->second)].size() + view.byteLength > kMaxShared) {
      tinygltf::BufferView fresh;
      fresh.buffer = 0;
      fresh.byteStride = stride;
      fresh.target = view.target;
      shared_view.push_back(static_cast<int>(views.size()));
      views.push_back(fresh);
      shared.emplace_back();
      found = open.insert_or_assign(key, static_cast<int>(shared.size()) - 1).first;
    }
    std::vector<unsigned char>& bytes = shared[static_cast<size_t>(found->second)];
    new_view[v] = shared_view[static_cast<size_t>(found->second)];
    offset_in_view[v] = bytes.size();
    bytes.insert(bytes.end(), raw.begin() + static_cast<long>(view.byteOffset),
                 raw.begin() + static_cast<long>(view.byteOffset + view.byteLength));
  }
  for (size_t g = 0; g < shared.size(); ++g) {
    while (data.size() % 4 != 0) data.push_back(0);
    tinygltf::BufferView& view = views[static_cast<size_t>(shared_view[g])];
    view.byteOffset = data.size();
    view.byteLength = shared[g].size();
    data.insert(data.end(), shared[g].begin(), shared[g].end());
  }
  const auto remap = [&](int& view) {
    if (view >= 0 && static_cast<size_t>(view) < view_count)
      view = new_view[static_cast<size_t>(view)];
  };
  for (tinygltf::Accessor& accessor : model.accessors) {
    if (accessor.bufferView >= 0 && static_cast<size_t>(accessor.bufferView) < view_count) {
      accessor.byteOffset += offset_in_view[static_cast<size_t>(accessor.bufferView)];
    }
    remap(accessor.bufferView);
    if (accessor.sparse.isSparse) {
      remap(accessor.sparse.indices.bufferView);
      remap(accessor.sparse.values.bufferView);
    }
  }
  for (tinygltf::Image& image : model.images) remap(image.bufferView);
  model.bufferViews = std::move(views);
  model.buffers[0].data = std::move(data);
}

}  // namespace

StatusOr<std::vector<uint8_t>> SerializeGlb(const tinygltf::Model& model) {
  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  try {
    if (!writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/false,
                                       /*writeBinary=*/true)) {
      return InternalError("tinygltf failed to serialise the GLB");
    }
  } catch (const std::bad_alloc&) {
    throw;  // GuardAllocation's concern (resource-limit)
  } catch (const std::exception& error) {
    // nlohmann refuses strings that are not UTF-8 (a scene record's names, say).
    return ParseError(std::string("the glTF cannot be written: ") + error.what());
  }
  const std::string bytes = std::move(stream).str();
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

StatusOr<std::vector<uint8_t>> SerializeMeshoptGlb(tinygltf::Model model) {
  if (model.buffers.size() != 1) return InternalError("meshopt packing expects one buffer");
  MergeViews(model);
  const std::vector<unsigned char> raw = std::move(model.buffers[0].data);
  std::vector<int> index_size(model.bufferViews.size(), 0);
  std::vector<char> triangle_list(model.bufferViews.size(), 1);
  // Which views hold indices: the index codecs need the index size. The triangle codec may
  // rotate a triangle's corners, so it is used only for views of triangle lists whose accessors
  // all start on a triangle.
  const size_t view_count = model.bufferViews.size();
  auto valid_view = [&](int view) { return view >= 0 && static_cast<size_t>(view) < view_count; };
  for (const tinygltf::Mesh& mesh : model.meshes) {
    for (const tinygltf::Primitive& primitive : mesh.primitives) {
      if (primitive.indices < 0 ||
          static_cast<size_t>(primitive.indices) >= model.accessors.size()) {
        continue;
      }
      const tinygltf::Accessor& accessor = model.accessors[static_cast<size_t>(primitive.indices)];
      if (!valid_view(accessor.bufferView)) continue;
      const size_t view = static_cast<size_t>(accessor.bufferView);
      const size_t bytes = ComponentBytes(accessor.componentType);
      index_size[view] = static_cast<int>(bytes);
      if (primitive.mode != TINYGLTF_MODE_TRIANGLES || bytes == 0 ||
          accessor.byteOffset % (3 * bytes) != 0) {
        triangle_list[view] = 0;
      }
    }
  }
  // The element size of each view (for views without byteStride).
  std::vector<size_t> element_size(model.bufferViews.size(), 0);
  for (const tinygltf::Accessor& accessor : model.accessors) {
    if (!valid_view(accessor.bufferView)) continue;
    element_size[static_cast<size_t>(accessor.bufferView)] =
        ComponentBytes(accessor.componentType) *
        static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(accessor.type)));
  }

  std::vector<unsigned char> packed;
  size_t fallback_size = 0;
  // tinygltf 2.7 does not serialise buffer views' extensions: they are written into the JSON below.
  std::vector<nlohmann::json> view_extensions;
  for (size_t v = 0; v < model.bufferViews.size(); ++v) {
    tinygltf::BufferView& view = model.bufferViews[v];
    const unsigned char* source = raw.data() + view.byteOffset;
    const size_t length = view.byteLength;
    std::vector<unsigned char> compressed;
    nlohmann::json extension;
    size_t count = 0, stride = 0;
    const size_t attribute_stride = view.byteStride != 0 ? view.byteStride : element_size[v];
    const bool indices_view = index_size[v] != 0;
    const bool compressible = indices_view
                                  ? (index_size[v] == 2 || index_size[v] == 4)
                                  : (attribute_stride != 0 && attribute_stride % 4 == 0 &&
                                     attribute_stride <= 256 && length % attribute_stride == 0);
    if (!compressible) {
      // Images, byte indices, odd strides: stored as they are in the BIN chunk.
      while (packed.size() % 4 != 0) packed.push_back(0);
      view.buffer = 0;
      view.byteOffset = packed.size();
      packed.insert(packed.end(), source, source + length);
      view_extensions.push_back(nullptr);
      continue;
    }
    if (indices_view) {
      stride = static_cast<size_t>(index_size[v]);
      count = length / stride;
      std::vector<uint32_t> indices(count);
      for (size_t i = 0; i < count; ++i) {
        uint32_t value = 0;
        std::memcpy(&value, source + i * stride, stride);  // little-endian
        indices[i] = value;
      }
      // The triangle codec may rotate a triangle's corners (keeping its winding), which only a
      // triangle list tolerates; strips, fans and odd counts keep their order (INDICES).
      uint32_t largest = 0;
      for (const uint32_t index : indices) largest = std::max(largest, index);
      if (triangle_list[v] && count % 3 == 0) {
        compressed.resize(meshopt_encodeIndexBufferBound(count, size_t{largest} + 1));
        compressed.resize(
            meshopt_encodeIndexBuffer(compressed.data(), compressed.size(), indices.data(), count));
        extension["mode"] = "TRIANGLES";
      } else {
        compressed.resize(meshopt_encodeIndexSequenceBound(count, size_t{largest} + 1));
        compressed.resize(meshopt_encodeIndexSequence(compressed.data(), compressed.size(),
                                                      indices.data(), count));
        extension["mode"] = "INDICES";
      }
    } else {
      stride = attribute_stride;
      count = length / stride;
      compressed.resize(meshopt_encodeVertexBufferBound(count, stride));
      compressed.resize(
          meshopt_encodeVertexBuffer(compressed.data(), compressed.size(), source, count, stride));
      extension["mode"] = "ATTRIBUTES";
    }
    if (compressed.empty() && count != 0) {
      return InternalError("meshoptimizer failed to compress buffer view " + std::to_string(v));
    }
    while (packed.size() % 4 != 0) packed.push_back(0);
    extension["buffer"] = 0;
    extension["byteOffset"] = packed.size();
    extension["byteLength"] = compressed.size();
    extension["byteStride"] = stride;
    extension["count"] = count;
    packed.insert(packed.end(), compressed.begin(), compressed.end());
    while (fallback_size % 4 != 0) ++fallback_size;
    view.buffer = 1;
    view.byteOffset = fallback_size;
    fallback_size += length;
    view_extensions.push_back(std::move(extension));
  }
  model.buffers[0].data = std::move(packed);
  model.buffers.emplace_back();  // the fallback; tinygltf cannot express it, fixed below
  AddExtensionName(model.extensionsUsed, kMeshopt);
  AddExtensionName(model.extensionsRequired, kMeshopt);
  DMC_ASSIGN_OR_RETURN(std::vector<uint8_t> glb, SerializeGlb(model));

  // tinygltf writes a buffer's byteLength from its data, and would embed buffer 1 as a data URI:
  // the JSON chunk is rewritten with the fallback buffer as the extension declares it.
  const std::string_view bytes(reinterpret_cast<const char*>(glb.data()), glb.size());
  DMC_ASSIGN_OR_RETURN(const GlbJsonChunk chunk, CheckGlbContainer(bytes));
  nlohmann::json document = nlohmann::json::parse(bytes.substr(chunk.offset, chunk.length), nullptr,
                                                  /*allow_exceptions=*/false);
  if (document.is_discarded() || !document.contains("buffers") || document["buffers"].size() != 2) {
    return InternalError("tinygltf wrote an unexpected GLB");
  }
  document["buffers"][1] = {{"byteLength", fallback_size},
                            {"extensions", {{kMeshopt, {{"fallback", true}}}}}};
  for (size_t v = 0; v < view_extensions.size(); ++v) {
    if (view_extensions[v].is_null()) continue;
    document["bufferViews"][v]["extensions"][kMeshopt] = std::move(view_extensions[v]);
  }
  const std::string out = ReplaceGlbJson(
      bytes, chunk, document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  return std::vector<uint8_t>(out.begin(), out.end());
}

}  // namespace dmc::io_internal
