// glTF extensions that change how geometry is stored: the file's required extensions checked
// against what dmc can read, EXT_meshopt_compression buffer views decoded with meshoptimizer and
// KHR_draco_mesh_compression primitives decoded with Draco, so the rest of the importer sees plain
// accessors. KHR_mesh_quantization needs nothing here: it only widens the component types that
// ReadAccessor already converts.
#include <draco/compression/decode.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal::gltf {
namespace {

constexpr const char* kMeshopt = "EXT_meshopt_compression";
constexpr const char* kDraco = "KHR_draco_mesh_compression";

// The vertex codec spends at least 2 bits per 16-byte group of a vertex stream, so no stream
// decodes to more than 64 times its size; a larger declared size is a hostile file, refused before
// anything is allocated.
constexpr size_t kMeshoptMaxExpansion = 64;
constexpr size_t kMeshoptExpansionSlack = 1 << 16;
// Writers pad views to 4 bytes (gltfpack) or more; a fallback buffer may end that far past them.
constexpr uint64_t kFallbackPadding = 64;

// Extensions that may be required without changing where vertices are: materials, textures,
// lights and metadata.
bool RequiredExtensionIsHarmless(const std::string& name) {
  static constexpr std::array<const char*, 5> kPrefixes = {
      "KHR_materials_", "KHR_texture_", "EXT_texture_", "KHR_lights_", "KHR_xmp"};
  return std::any_of(kPrefixes.begin(), kPrefixes.end(),
                     [&](const char* prefix) { return name.rfind(prefix, 0) == 0; });
}

// A non-negative integer member of an extension object, or `fallback` when absent.
StatusOr<size_t> SizeMember(const tinygltf::Value& object, const char* key,
                            const std::string& label,
                            std::optional<size_t> fallback = std::nullopt) {
  const tinygltf::Value& value = Member(object, key);
  if (value.IsNumber() || value.IsInt()) {
    const double number = value.GetNumberAsDouble();
    if (number >= 0 && number <= 9.007199254740992e15 &&
        number == static_cast<double>(static_cast<size_t>(number))) {
      return static_cast<size_t>(number);
    }
    return ParseError(label + ": '" + key + "' is not a non-negative integer");
  }
  if (value.Type() == tinygltf::NULL_TYPE && fallback) return *fallback;
  return ParseError(label + ": '" + key + "' is missing");
}

std::string StringMember(const tinygltf::Value& object, const char* key, const char* fallback) {
  const tinygltf::Value& value = Member(object, key);
  return value.IsString() ? value.Get<std::string>() : std::string(fallback);
}

// Decodes one EXT_meshopt_compression buffer view into its (fallback) buffer.
Status DecodeMeshoptView(tinygltf::Model& model, size_t view_index) {
  tinygltf::BufferView& view = model.bufferViews[view_index];
  const tinygltf::Value& extension = view.extensions.at(kMeshopt);
  const std::string label = "buffer view " + std::to_string(view_index) + " (" + kMeshopt + ")";
  DMC_ASSIGN_OR_RETURN(const size_t source_index, SizeMember(extension, "buffer", label));
  DMC_ASSIGN_OR_RETURN(const size_t source_offset, SizeMember(extension, "byteOffset", label, 0));
  DMC_ASSIGN_OR_RETURN(const size_t source_length, SizeMember(extension, "byteLength", label));
  DMC_ASSIGN_OR_RETURN(const size_t stride, SizeMember(extension, "byteStride", label));
  DMC_ASSIGN_OR_RETURN(const size_t count, SizeMember(extension, "count", label));
  const std::string mode = StringMember(extension, "mode", "");
  const std::string filter = StringMember(extension, "filter", "NONE");
  if (source_index >= model.buffers.size()) {
    return ParseError(label + ": buffer " + std::to_string(source_index) + " does not exist");
  }
  const std::vector<unsigned char>& source = model.buffers[source_index].data;
  if (source_offset > source.size() || source_length > source.size() - source_offset) {
    return ParseError(label + ": " + std::to_string(source_length) + " compressed bytes at " +
                      std::to_string(source_offset) + " lie outside buffer " +
                      std::to_string(source_index));
  }
  if (stride == 0 || stride > 256 || count > (size_t{1} << 32) / stride) {
    return ParseError(label + ": byteStride " + std::to_string(stride) + " or count " +
                      std::to_string(count) + " out of range");
  }
  const size_t decoded_size = count * stride;
  if (decoded_size > kMeshoptMaxExpansion * source_length + kMeshoptExpansionSlack) {
    return ParseError(label + ": declares " + std::to_string(decoded_size) + " bytes from " +
                      std::to_string(source_length) +
                      " compressed, more than the codec can expand");
  }
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) {
    return ParseError(label + ": buffer " + std::to_string(view.buffer) + " does not exist");
  }
  std::vector<unsigned char>& target = model.buffers[static_cast<size_t>(view.buffer)].data;
  if (decoded_size > view.byteLength || view.byteOffset > target.size() ||
      view.byteLength > target.size() - view.byteOffset) {
    return ParseError(label + ": " + std::to_string(decoded_size) +
                      " decoded bytes do not fit the view's " + std::to_string(view.byteLength) +
                      " bytes of buffer " + std::to_string(view.buffer));
  }
  unsigned char* destination = target.data() + view.byteOffset;
  const unsigned char* compressed = source.data() + source_offset;
  int result = -1;
  if (mode == "ATTRIBUTES") {
    if (stride % 4 != 0)
      return ParseError(label + ": ATTRIBUTES byteStride is not a multiple of 4");
    result = meshopt_decodeVertexBuffer(destination, count, stride, compressed, source_length);
  } else if (mode == "TRIANGLES" || mode == "INDICES") {
    if (stride != 2 && stride != 4) return ParseError(label + ": index byteStride must be 2 or 4");
    if (mode == "TRIANGLES" && count % 3 != 0) {
      return ParseError(label + ": TRIANGLES count is not a multiple of 3");
    }
    result =
        mode == "TRIANGLES"
            ? meshopt_decodeIndexBuffer(destination, count, stride, compressed, source_length)
            : meshopt_decodeIndexSequence(destination, count, stride, compressed, source_length);
  } else {
    return ParseError(label + ": unknown mode '" + mode + "'");
  }
  if (result != 0) return ParseError(label + ": the compressed data is corrupt");
  if (filter == "OCTAHEDRAL") {
    if (mode != "ATTRIBUTES" || (stride != 4 && stride != 8)) {
      return ParseError(label + ": the OCTAHEDRAL filter needs ATTRIBUTES of stride 4 or 8");
    }
    meshopt_decodeFilterOct(destination, count, stride);
  } else if (filter == "QUATERNION") {
    if (mode != "ATTRIBUTES" || stride != 8) {
      return ParseError(label + ": the QUATERNION filter needs ATTRIBUTES of stride 8");
    }
    meshopt_decodeFilterQuat(destination, count, stride);
  } else if (filter == "EXPONENTIAL") {
    if (mode != "ATTRIBUTES" || stride % 4 != 0) {
      return ParseError(label + ": the EXPONENTIAL filter needs ATTRIBUTES of a stride of 4·k");
    }
    meshopt_decodeFilterExp(destination, count, stride);
  } else if (filter != "NONE") {
    return ParseError(label + ": unknown filter '" + filter + "'");
  }
  view.extensions.erase(kMeshopt);
  return Status::Ok();
}

// Copies `values` (as float32 or uint32) into a new buffer view of the model's last buffer and
// points `accessor` at it with that component type.
template <typename T>
void StoreDecoded(tinygltf::Model& model, tinygltf::Accessor& accessor,
                  const std::vector<T>& values, int component_type) {
  if (model.buffers.empty()) model.buffers.emplace_back();
  accessor.bufferView =
      AppendBufferView(model, model.buffers.size() - 1, values.data(), values.size() * sizeof(T));
  accessor.byteOffset = 0;
  accessor.componentType = component_type;
  accessor.normalized = false;
  accessor.sparse = {};
}

// Replaces a KHR_draco_mesh_compression primitive's index and attribute accessors by plain ones
// holding Draco's decoded points (the extension defines the accessors' counts as Draco's point
// count, and its attribute map names which Draco attribute each accessor holds).
Status DecodeDracoPrimitive(tinygltf::Model& model, tinygltf::Primitive& primitive,
                            const std::string& label) {
  const tinygltf::Value& extension = primitive.extensions.at(kDraco);
  DMC_ASSIGN_OR_RETURN(const size_t view_index, SizeMember(extension, "bufferView", label));
  if (view_index >= model.bufferViews.size()) {
    return ParseError(label + ": buffer view " + std::to_string(view_index) + " does not exist");
  }
  const tinygltf::BufferView& view = model.bufferViews[view_index];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) {
    return ParseError(label + ": buffer " + std::to_string(view.buffer) + " does not exist");
  }
  const std::vector<unsigned char>& buffer = model.buffers[static_cast<size_t>(view.buffer)].data;
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset) {
    return ParseError(label + ": buffer view " + std::to_string(view_index) +
                      " lies outside its buffer");
  }
  draco::DecoderBuffer source;
  source.Init(reinterpret_cast<const char*>(buffer.data() + view.byteOffset), view.byteLength);
  draco::Decoder decoder;
  draco::StatusOr<std::unique_ptr<draco::Mesh>> decoded = decoder.DecodeMeshFromBuffer(&source);
  if (!decoded.ok()) {
    return ParseError(label + ": Draco cannot decode it (" + decoded.status().error_msg_string() +
                      ")");
  }
  const draco::Mesh& mesh = *decoded.value();
  const size_t points = mesh.num_points();
  auto accessor_of = [&](int index) -> StatusOr<tinygltf::Accessor*> {
    if (index < 0 || static_cast<size_t>(index) >= model.accessors.size()) {
      return ParseError(label + ": accessor " + std::to_string(index) + " does not exist");
    }
    return &model.accessors[static_cast<size_t>(index)];
  };
  if (primitive.indices >= 0) {
    DMC_ASSIGN_OR_RETURN(tinygltf::Accessor * accessor, accessor_of(primitive.indices));
    std::vector<uint32_t> indices;
    indices.reserve(3 * static_cast<size_t>(mesh.num_faces()));
    for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f) {
      for (int corner = 0; corner < 3; ++corner) indices.push_back(mesh.face(f)[corner].value());
    }
    if (accessor->count != indices.size()) {
      return ParseError(label + ": the indices accessor counts " + std::to_string(accessor->count) +
                        ", Draco decoded " + std::to_string(indices.size()));
    }
    StoreDecoded(model, *accessor, indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  }
  const tinygltf::Value& attributes = Member(extension, "attributes");
  if (!attributes.IsObject()) return ParseError(label + ": 'attributes' is missing");
  for (const std::string& name : attributes.Keys()) {
    const auto found = primitive.attributes.find(name);
    if (found == primitive.attributes.end()) continue;  // the extension may carry extra data
    DMC_ASSIGN_OR_RETURN(const size_t unique_id,
                         SizeMember(attributes, name.c_str(), label + " attribute " + name));
    const draco::PointAttribute* attribute =
        mesh.GetAttributeByUniqueId(static_cast<uint32_t>(std::min<size_t>(unique_id, UINT32_MAX)));
    if (attribute == nullptr) {
      return ParseError(label + ": Draco holds no attribute " + std::to_string(unique_id) +
                        " for " + name);
    }
    DMC_ASSIGN_OR_RETURN(tinygltf::Accessor * accessor, accessor_of(found->second));
    const int components = tinygltf::GetNumComponentsInType(static_cast<uint32_t>(accessor->type));
    // Vertex attributes have at most 4 components (MAT types are not vertex attributes).
    if (accessor->count != points || components <= 0 || components > 4 ||
        components != attribute->num_components()) {
      return ParseError(label + ": accessor for " + name + " holds " +
                        std::to_string(accessor->count) + " × " + std::to_string(components) +
                        " values, Draco decoded " + std::to_string(points) + " × " +
                        std::to_string(attribute->num_components()));
    }
    // Draco dequantises and denormalises; float32 is exact for every glTF component type but
    // 32-bit integers, which no vertex attribute uses.
    std::vector<float> values(points * static_cast<size_t>(components));
    std::array<float, 4> point_value{};
    for (draco::PointIndex p(0); p < static_cast<uint32_t>(points); ++p) {
      if (!attribute->ConvertValue<float>(attribute->mapped_index(p),
                                          static_cast<int8_t>(components), point_value.data())) {
        return ParseError(label + ": Draco cannot convert attribute " + name);
      }
      std::copy_n(point_value.begin(), components,
                  values.begin() + static_cast<long>(p.value() * static_cast<size_t>(components)));
    }
    StoreDecoded(model, *accessor, values, TINYGLTF_COMPONENT_TYPE_FLOAT);
  }
  primitive.extensions.erase(kDraco);
  return Status::Ok();
}

void DropExtensionName(std::vector<std::string>& names, const char* name) {
  names.erase(std::remove(names.begin(), names.end(), name), names.end());
}

}  // namespace

Status CheckRequiredExtensions(const tinygltf::Model& model) {
  for (const std::string& name : model.extensionsRequired) {
    if (name == kMeshopt || name == kDraco || name == "KHR_mesh_quantization") continue;
    if (RequiredExtensionIsHarmless(name)) continue;
    return UnsupportedError("the file requires the glTF extension " + name +
                            ", which dmc cannot read (it reads KHR_mesh_quantization, " + kMeshopt +
                            ", " + kDraco + " and material, texture and light extensions)");
  }
  return Status::Ok();
}

Status DecodeCompressedGeometry(tinygltf::Model& model) {
  for (size_t v = 0; v < model.bufferViews.size(); ++v) {
    if (model.bufferViews[v].extensions.count(kMeshopt) != 0) {
      DMC_RETURN_IF_ERROR(DecodeMeshoptView(model, v));
    }
  }
  for (size_t m = 0; m < model.meshes.size(); ++m) {
    std::vector<tinygltf::Primitive>& primitives = model.meshes[m].primitives;
    for (size_t p = 0; p < primitives.size(); ++p) {
      if (primitives[p].extensions.count(kDraco) == 0) continue;
      DMC_RETURN_IF_ERROR(DecodeDracoPrimitive(
          model, primitives[p],
          "mesh " + std::to_string(m) + " primitive " + std::to_string(p) + " (" + kDraco + ")"));
    }
  }
  DropExtensionName(model.extensionsRequired, kMeshopt);
  DropExtensionName(model.extensionsUsed, kMeshopt);
  DropExtensionName(model.extensionsRequired, kDraco);
  DropExtensionName(model.extensionsUsed, kDraco);
  return Status::Ok();
}

StatusOr<std::string> PrepareCompressedGeometry(std::string_view json_text,
                                                CompressedGeometryStandIns& stand_ins) {
  nlohmann::json document = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded() || !document.is_object()) return std::string(json_text);
  bool changed = false;
  auto buffers = document.find("buffers");
  for (size_t b = 0; buffers != document.end() && buffers->is_array() && b < buffers->size(); ++b) {
    nlohmann::json& buffer = (*buffers)[b];
    if (!buffer.is_object()) continue;
    const auto extensions = buffer.find("extensions");
    if (extensions == buffer.end() || !extensions->is_object()) continue;
    const auto meshopt = extensions->find(kMeshopt);
    if (meshopt == extensions->end() || !meshopt->is_object()) continue;
    const auto fallback = meshopt->find("fallback");
    if (fallback == meshopt->end() || !fallback->is_boolean() || !fallback->get<bool>()) continue;
    const auto length = buffer.find("byteLength");
    if (length == buffer.end() || !length->is_number_unsigned()) {
      return ParseError("buffer " + std::to_string(b) + " (" + kMeshopt +
                        " fallback): 'byteLength' is not a non-negative integer");
    }
    // A one-byte stand-in: tinygltf cannot load a buffer without data; the real size is restored
    // (and checked against what its compressed views need) before decoding.
    stand_ins.fallbacks.push_back({b, length->get<uint64_t>()});
    buffer["byteLength"] = 1;
    buffer["uri"] = "data:application/octet-stream;base64,AA==";
    changed = true;
  }
  // tinygltf refuses index accessors without a buffer view, which is how Draco primitives come:
  // their "indices" are held back until the Draco data fills the accessor.
  auto meshes = document.find("meshes");
  for (size_t m = 0; meshes != document.end() && meshes->is_array() && m < meshes->size(); ++m) {
    auto primitives =
        (*meshes)[m].is_object() ? (*meshes)[m].find("primitives") : nlohmann::json::iterator();
    if (!(*meshes)[m].is_object() || primitives == (*meshes)[m].end() || !primitives->is_array()) {
      continue;
    }
    for (size_t p = 0; p < primitives->size(); ++p) {
      nlohmann::json& primitive = (*primitives)[p];
      if (!primitive.is_object() || !primitive.contains("extensions") ||
          !primitive["extensions"].is_object() || !primitive["extensions"].contains(kDraco) ||
          !primitive.contains("indices") || !primitive["indices"].is_number_unsigned()) {
        continue;
      }
      stand_ins.draco_indices.push_back({m, p, primitive["indices"].get<uint64_t>()});
      primitive.erase("indices");
      changed = true;
    }
  }
  if (!changed) return std::string(json_text);
  return document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

Status RestoreCompressedGeometry(tinygltf::Model& model,
                                 const CompressedGeometryStandIns& stand_ins) {
  for (const DracoIndices& held : stand_ins.draco_indices) {
    if (held.mesh >= model.meshes.size() ||
        held.primitive >= model.meshes[held.mesh].primitives.size() ||
        held.accessor >= model.accessors.size()) {
      return ParseError("mesh " + std::to_string(held.mesh) + " primitive " +
                        std::to_string(held.primitive) + ": indices accessor " +
                        std::to_string(held.accessor) + " does not exist");
    }
    model.meshes[held.mesh].primitives[held.primitive].indices = static_cast<int>(held.accessor);
  }
  for (const FallbackBuffer& fallback : stand_ins.fallbacks) {
    // Each compressed view decodes to at most kMeshoptMaxExpansion times its compressed bytes,
    // which must lie in their source buffer, and the fallback holds only those views (alignment
    // aside): their sum bounds what is allocated, wherever the views claim to sit.
    uint64_t decodable = 0, extent = 0;
    for (size_t v = 0; v < model.bufferViews.size(); ++v) {
      const tinygltf::BufferView& view = model.bufferViews[v];
      if (view.buffer != static_cast<int>(fallback.index) || view.extensions.count(kMeshopt) == 0) {
        continue;
      }
      const std::string label = "buffer view " + std::to_string(v) + " (" + kMeshopt + ")";
      const tinygltf::Value& extension = view.extensions.at(kMeshopt);
      DMC_ASSIGN_OR_RETURN(const size_t source, SizeMember(extension, "buffer", label));
      DMC_ASSIGN_OR_RETURN(const size_t offset, SizeMember(extension, "byteOffset", label, 0));
      DMC_ASSIGN_OR_RETURN(const size_t compressed, SizeMember(extension, "byteLength", label));
      if (source >= model.buffers.size() || offset > model.buffers[source].data.size() ||
          compressed > model.buffers[source].data.size() - offset) {
        return ParseError(label + ": its compressed bytes lie outside their buffer");
      }
      const uint64_t cap = kMeshoptMaxExpansion * uint64_t{compressed} + kMeshoptExpansionSlack;
      if (view.byteLength > cap) {
        return ParseError(label + ": declares " + std::to_string(view.byteLength) + " bytes from " +
                          std::to_string(compressed) +
                          " compressed, more than the codec can expand");
      }
      decodable += view.byteLength + kFallbackPadding;
      extent = std::max<uint64_t>(extent, uint64_t{view.byteOffset} + view.byteLength);
    }
    if (fallback.byte_length > decodable || extent > decodable) {
      return ParseError("buffer " + std::to_string(fallback.index) + " (" + kMeshopt +
                        " fallback): " + std::to_string(std::max(fallback.byte_length, extent)) +
                        " bytes exceed the " + std::to_string(decodable) + " its views decode to");
    }
    model.buffers[fallback.index].data.assign(static_cast<size_t>(fallback.byte_length), 0);
  }
  return Status::Ok();
}

}  // namespace dmc::io_internal::gltf
