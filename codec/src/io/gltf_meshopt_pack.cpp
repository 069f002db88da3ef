// EXT_meshopt_compression packing of an exported model: every buffer view of vertex data, keys or
// indices is compressed with meshoptimizer's vertex or index codec into the GLB's BIN chunk
// (buffer 0), and points at a data-less fallback buffer (buffer 1) holding its decoded layout, as
// the extension defines; other views (images, byte indices) stay in the BIN chunk as they are.
#include <meshoptimizer.h>

#include <nlohmann/json.hpp>
#include <sstream>

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
