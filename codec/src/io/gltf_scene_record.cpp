// The scene record of a glTF input (BuildGltfScene): the input's own document with the vertex
// motion taken out, for the stream's scene chunk. What the codec carries (positions of every
// imported primitive, the normals, tangents and morph targets that follow them, skins and the
// weights animations) is removed; what it does not (nodes, meshes' other attributes and
// indices, materials, textures, images, samplers, node animations, asset) is kept, and the
// record says how the stream's vertices and frames map back (asset.extras.dmc_scene, see
// gltf_format.h).
#include <algorithm>
#include <map>
#include <set>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal {
namespace {

bool IsMotionAttribute(const std::string& name) {
  return name == "POSITION" || name == "NORMAL" || name == "TANGENT" ||
         name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0;
}

// A uint32 SCALAR accessor over `values`, appended to buffer 0.
int AddUint32Accessor(tinygltf::Model& model, const std::vector<int32_t>& values) {
  if (model.buffers.empty()) model.buffers.emplace_back();
  tinygltf::Accessor accessor;
  accessor.bufferView = AppendBufferView(model, 0, values.data(), values.size() * sizeof(int32_t));
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  accessor.type = TINYGLTF_TYPE_SCALAR;
  accessor.count = values.size();
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size()) - 1;
}

}  // namespace

Status CompactBuffers(tinygltf::Model& model, std::vector<int>& extra_accessors) {
  // Every reference is checked first: the models here may come from a stream (a scene record).
  for (size_t v = 0; v < model.bufferViews.size(); ++v) {
    const tinygltf::BufferView& view = model.bufferViews[v];
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size() ||
        view.byteOffset > model.buffers[static_cast<size_t>(view.buffer)].data.size() ||
        view.byteLength >
            model.buffers[static_cast<size_t>(view.buffer)].data.size() - view.byteOffset) {
      return ParseError("buffer view " + std::to_string(v) + " lies outside its buffer");
    }
  }
  for (size_t a = 0; a < model.accessors.size(); ++a) {
    const tinygltf::Accessor& accessor = model.accessors[a];
    const int sparse_indices = accessor.sparse.isSparse ? accessor.sparse.indices.bufferView : -1;
    const int sparse_values = accessor.sparse.isSparse ? accessor.sparse.values.bufferView : -1;
    for (const int view : {accessor.bufferView, sparse_indices, sparse_values}) {
      if (view < -1 || view >= static_cast<int>(model.bufferViews.size())) {
        return ParseError("accessor " + std::to_string(a) + " names buffer view " +
                          std::to_string(view) + ", which does not exist");
      }
    }
  }
  for (const tinygltf::Image& image : model.images) {
    if (image.bufferView < -1 || image.bufferView >= static_cast<int>(model.bufferViews.size())) {
      return ParseError("an image names a buffer view that does not exist");
    }
  }
  std::vector<int> accessor_map(model.accessors.size(), -1);
  std::vector<int> kept_accessors;
  auto keep_accessor = [&](int& index) {
    if (index < 0 || static_cast<size_t>(index) >= model.accessors.size()) return;
    int& mapped = accessor_map[static_cast<size_t>(index)];
    if (mapped < 0) {
      mapped = static_cast<int>(kept_accessors.size());
      kept_accessors.push_back(index);
    }
    index = mapped;
  };
  for (tinygltf::Mesh& mesh : model.meshes) {
    for (tinygltf::Primitive& primitive : mesh.primitives) {
      keep_accessor(primitive.indices);
      for (auto& [name, accessor] : primitive.attributes) keep_accessor(accessor);
      for (auto& target : primitive.targets) {
        for (auto& [name, accessor] : target) keep_accessor(accessor);
      }
    }
  }
  for (tinygltf::Animation& animation : model.animations) {
    for (tinygltf::AnimationSampler& sampler : animation.samplers) {
      keep_accessor(sampler.input);
      keep_accessor(sampler.output);
    }
  }
  for (tinygltf::Skin& skin : model.skins) keep_accessor(skin.inverseBindMatrices);
  for (int& accessor : extra_accessors) keep_accessor(accessor);

  std::vector<int> view_map(model.bufferViews.size(), -1);
  std::vector<int> kept_views;
  auto keep_view = [&](int& index) {
    if (index < 0 || static_cast<size_t>(index) >= model.bufferViews.size()) return;
    int& mapped = view_map[static_cast<size_t>(index)];
    if (mapped < 0) {
      mapped = static_cast<int>(kept_views.size());
      kept_views.push_back(index);
    }
    index = mapped;
  };
  std::vector<tinygltf::Accessor> accessors;
  for (const int index : kept_accessors) {
    tinygltf::Accessor accessor = model.accessors[static_cast<size_t>(index)];
    keep_view(accessor.bufferView);
    if (accessor.sparse.isSparse) {
      keep_view(accessor.sparse.indices.bufferView);
      keep_view(accessor.sparse.values.bufferView);
    }
    accessors.push_back(std::move(accessor));
  }
  for (tinygltf::Image& image : model.images) keep_view(image.bufferView);

  // One buffer, each kept view copied 4-byte aligned (every accessor offset inside a view keeps
  // its alignment).
  std::vector<unsigned char> data;
  std::vector<tinygltf::BufferView> views;
  for (const int index : kept_views) {
    tinygltf::BufferView view = model.bufferViews[static_cast<size_t>(index)];
    while (data.size() % 4 != 0) data.push_back(0);
    const std::vector<unsigned char>& source = model.buffers[static_cast<size_t>(view.buffer)].data;
    const size_t offset = data.size();
    data.insert(data.end(), source.begin() + static_cast<long>(view.byteOffset),
                source.begin() + static_cast<long>(view.byteOffset + view.byteLength));
    view.buffer = 0;
    view.byteOffset = offset;
    views.push_back(std::move(view));
  }
  model.accessors = std::move(accessors);
  model.bufferViews = std::move(views);
  tinygltf::Buffer buffer;
  buffer.data = std::move(data);
  model.buffers = {std::move(buffer)};
  return Status::Ok();
}

StatusOr<std::vector<uint8_t>> BuildSceneRecord(tinygltf::Model model,
                                                const GltfReadOptions& options,
                                                const std::vector<int32_t>& vertex_map,
                                                const std::vector<ClipInfo>& clips,
                                                int stream_vertices) {
  if (gltf::IsDmcFramesExport(model) && options.mesh.empty()) {
    return std::vector<uint8_t>();  // a dmc frames export: one mesh per frame, no scene to keep
  }
  DMC_ASSIGN_OR_RETURN(const gltf::SceneOrder scene, gltf::OrderScene(model));
  std::vector<std::string> warnings;
  DMC_ASSIGN_OR_RETURN(const gltf::ScenePrimitives primitives,
                       gltf::CollectPrimitives(model, scene.order, options.mesh, warnings));
  if (vertex_map.size() != static_cast<size_t>(primitives.vertex_total)) {
    return InvalidArgumentError("the vertex map has " + std::to_string(vertex_map.size()) +
                                " entries, the file's primitives " +
                                std::to_string(primitives.vertex_total) + " vertices");
  }
  for (const int32_t v : vertex_map) {
    if (v < 0 || v >= stream_vertices) {
      return InvalidArgumentError("the vertex map names vertex " + std::to_string(v) + " of " +
                                  std::to_string(stream_vertices));
    }
  }

  const int vertex_map_accessor = AddUint32Accessor(model, vertex_map);
  // The motion out: what the stream carries, and what follows from it.
  std::set<int> imported_nodes, imported_meshes;
  tinygltf::Value::Array instances;
  for (const gltf::PrimitiveInstance& instance : primitives.instances) {
    imported_nodes.insert(instance.node);
    imported_meshes.insert(instance.mesh);
    tinygltf::Primitive& primitive = model.meshes[static_cast<size_t>(instance.mesh)]
                                         .primitives[static_cast<size_t>(instance.primitive)];
    for (auto it = primitive.attributes.begin(); it != primitive.attributes.end();) {
      it = IsMotionAttribute(it->first) ? primitive.attributes.erase(it) : std::next(it);
    }
    primitive.targets.clear();
    // glTF wants at least one attribute per primitive (tinygltf drops a primitive without): the
    // stripped ones name the vertex map, which the writer replaces by the decoded positions.
    primitive.attributes[kSceneVertexAttribute] = vertex_map_accessor;
    tinygltf::Value::Object entry;
    entry["node"] = tinygltf::Value(instance.node);
    entry["mesh"] = tinygltf::Value(instance.mesh);
    entry["primitive"] = tinygltf::Value(instance.primitive);
    entry["first_vertex"] = tinygltf::Value(instance.vertex_offset);
    entry["vertex_count"] = tinygltf::Value(instance.vertex_count);
    instances.emplace_back(entry);
  }
  for (const int mesh : imported_meshes) model.meshes[static_cast<size_t>(mesh)].weights.clear();
  for (const int node : imported_nodes) model.nodes[static_cast<size_t>(node)].weights.clear();
  for (tinygltf::Node& node : model.nodes) node.skin = -1;
  model.skins.clear();
  // Animations left without channels (they only played imported weights) go; the clips name the
  // ones kept by their new index, or none.
  std::vector<int> animation_map(model.animations.size(), -1);
  std::vector<tinygltf::Animation> kept_animations;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    tinygltf::Animation& animation = model.animations[a];
    std::vector<tinygltf::AnimationChannel> channels;
    for (const tinygltf::AnimationChannel& channel : animation.channels) {
      if (channel.target_path == "weights" && imported_nodes.count(channel.target_node)) continue;
      channels.push_back(channel);
    }
    // Channels whose sampler does not exist are dropped (the importer never reads them either).
    channels.erase(std::remove_if(channels.begin(), channels.end(),
                                  [&](const tinygltf::AnimationChannel& channel) {
                                    return channel.sampler < 0 ||
                                           static_cast<size_t>(channel.sampler) >=
                                               animation.samplers.size();
                                  }),
                   channels.end());
    // Samplers no channel uses any more go too.
    std::map<int, int> sampler_map;
    std::vector<tinygltf::AnimationSampler> samplers;
    for (tinygltf::AnimationChannel& channel : channels) {
      auto [it, added] =
          sampler_map.try_emplace(channel.sampler, static_cast<int>(samplers.size()));
      if (added) samplers.push_back(animation.samplers[static_cast<size_t>(channel.sampler)]);
      channel.sampler = it->second;
    }
    animation.channels = std::move(channels);
    animation.samplers = std::move(samplers);
    if (animation.channels.empty()) continue;
    animation_map[a] = static_cast<int>(kept_animations.size());
    kept_animations.push_back(std::move(animation));
  }
  model.animations = std::move(kept_animations);

  std::vector<int> extra_accessors = {vertex_map_accessor};
  DMC_RETURN_IF_ERROR(CompactBuffers(model, extra_accessors));

  tinygltf::Value::Array clip_entries;
  for (const ClipInfo& clip : clips) {
    tinygltf::Value::Object entry;
    entry["name"] = tinygltf::Value(clip.name);
    entry["animation"] = tinygltf::Value(
        clip.animation >= 0 && static_cast<size_t>(clip.animation) < animation_map.size()
            ? animation_map[static_cast<size_t>(clip.animation)]
            : -1);
    entry["start_time"] = tinygltf::Value(clip.start_time);
    entry["first_frame"] = tinygltf::Value(clip.first_frame);
    entry["frame_count"] = tinygltf::Value(clip.frame_count);
    clip_entries.emplace_back(entry);
  }
  tinygltf::Value::Object record;
  record["version"] = tinygltf::Value(1);
  record["vertex_map"] = tinygltf::Value(extra_accessors[0]);
  record["stream_vertices"] = tinygltf::Value(stream_vertices);
  record["instances"] = tinygltf::Value(instances);
  record["clips"] = tinygltf::Value(clip_entries);
  tinygltf::Value::Object extras = model.extras.IsObject()
                                       ? model.extras.Get<tinygltf::Value::Object>()
                                       : tinygltf::Value::Object();
  extras[kSceneRecordKey] = tinygltf::Value(record);
  model.extras = tinygltf::Value(extras);
  return SerializeGlb(model);
}

StatusOr<const tinygltf::Value*> FindSceneRecord(const tinygltf::Model& model) {
  const tinygltf::Value& record = gltf::Member(model.extras, kSceneRecordKey);
  if (!record.IsObject()) return ParseError("the scene holds no dmc scene record");
  return &record;
}

std::vector<ClipInfo> RecordClips(const tinygltf::Value& record) {
  const tinygltf::Value& clips = gltf::Member(record, "clips");
  std::vector<ClipInfo> out;
  for (size_t c = 0; clips.IsArray() && c < clips.ArrayLen(); ++c) {
    const tinygltf::Value& entry = clips.Get(static_cast<int>(c));
    ClipInfo clip;
    const tinygltf::Value& name = gltf::Member(entry, "name");
    clip.name = name.IsString() ? name.Get<std::string>() : std::string();
    clip.animation = gltf::IntMember(entry, "animation");
    clip.first_frame = gltf::IntMember(entry, "first_frame");
    clip.frame_count = gltf::IntMember(entry, "frame_count");
    const tinygltf::Value& start = gltf::Member(entry, "start_time");
    clip.start_time = start.IsNumber() ? start.GetNumberAsDouble() : 0.0;
    out.push_back(std::move(clip));
  }
  return out;
}

StatusOr<std::vector<ClipInfo>> ReadSceneClips(std::span<const uint8_t> scene) {
  DMC_ASSIGN_OR_RETURN(const tinygltf::Model model, LoadGlbBytes(scene, "the scene"));
  DMC_ASSIGN_OR_RETURN(const tinygltf::Value* record, FindSceneRecord(model));
  if (!record->Has("clips")) return ParseError("the scene record lists no clips");
  return RecordClips(*record);
}

}  // namespace dmc::io_internal
