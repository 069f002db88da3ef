// GLB export of a decoded sequence into its scene record (EncodeSceneGlb): the input's nodes,
// materials, textures, UVs and clips come back from the record, the motion from the sequence.
//
// Each node that showed imported primitives gets a new leaf node (same name, first among its
// children, so the scene's depth-first order, which is the vertex order of an import, is kept)
// holding a new mesh: the node's primitives with their kept attributes and indices, plus POSITION
// and NORMAL of the first written frame and one morph target per later frame, played by a weights
// channel in each clip's animation. The stream's positions are world positions; each frame's are
// taken into the node's space by the node's global transform at that frame's time, posed from the
// record's node animations (which the file keeps), so the node's own motion moves the leaf and the
// targets hold what the node's transform does not (a skin's deformation). Node animations,
// cameras, materials and the asset are the record's.
#include <algorithm>
#include <map>

#include "io/gltf_glb_builder.h"
#include "io/gltf_import_internal.h"

namespace dmc::io_internal {
namespace {

using glb::FrameNormals;
using glb::ModelBuilder;
using glb::NormalSteps;
using glb::PositionGrid;
using glb::QuantizeNormals;
using gltf::IntMember;
using gltf::Member;

struct RecordInstance {
  int node = -1, mesh = -1, primitive = -1, first_vertex = 0, vertex_count = 0;
};

struct Record {
  std::vector<int32_t> vertex_map;
  std::vector<RecordInstance> instances;
  std::vector<ClipInfo> clips;
};

StatusOr<Record> ReadRecord(const tinygltf::Model& model, const MeshSequence& sequence) {
  DMC_ASSIGN_OR_RETURN(const tinygltf::Value* found, FindSceneRecord(model));
  const tinygltf::Value& record = *found;
  if (IntMember(record, "version") != 1) return UnsupportedError("scene record version");
  if (IntMember(record, "stream_vertices") != sequence.vertex_count()) {
    return ParseError("the scene record is for " +
                      std::to_string(IntMember(record, "stream_vertices")) +
                      " vertices, the stream has " + std::to_string(sequence.vertex_count()));
  }
  Record out;
  const int map_accessor = IntMember(record, "vertex_map");
  if (map_accessor < 0 || static_cast<size_t>(map_accessor) >= model.accessors.size() ||
      model.accessors[static_cast<size_t>(map_accessor)].type != TINYGLTF_TYPE_SCALAR ||
      model.accessors[static_cast<size_t>(map_accessor)].bufferView < 0) {
    return ParseError("the scene record's vertex map is not a SCALAR accessor with data");
  }
  DMC_ASSIGN_OR_RETURN(const std::vector<double> map,
                       gltf::ReadAccessor(model, map_accessor, "vertex map"));
  for (const double v : map) {
    if (!(v >= 0 && v < sequence.vertex_count())) {
      return ParseError("the scene's vertex map names a vertex the stream does not have");
    }
    out.vertex_map.push_back(static_cast<int32_t>(v));
  }
  const tinygltf::Value& instances = Member(record, "instances");
  for (size_t i = 0; instances.IsArray() && i < instances.ArrayLen(); ++i) {
    const tinygltf::Value& entry = instances.Get(static_cast<int>(i));
    RecordInstance instance{IntMember(entry, "node"), IntMember(entry, "mesh"),
                            IntMember(entry, "primitive"), IntMember(entry, "first_vertex"),
                            IntMember(entry, "vertex_count")};
    const bool valid =
        instance.node >= 0 && static_cast<size_t>(instance.node) < model.nodes.size() &&
        instance.mesh >= 0 && static_cast<size_t>(instance.mesh) < model.meshes.size() &&
        model.nodes[static_cast<size_t>(instance.node)].mesh == instance.mesh &&
        instance.primitive >= 0 &&
        static_cast<size_t>(instance.primitive) <
            model.meshes[static_cast<size_t>(instance.mesh)].primitives.size() &&
        instance.first_vertex >= 0 && instance.vertex_count >= 0 &&
        static_cast<size_t>(instance.first_vertex) + static_cast<size_t>(instance.vertex_count) <=
            out.vertex_map.size();
    if (!valid) return ParseError("scene record instance " + std::to_string(i) + " is invalid");
    out.instances.push_back(instance);
  }
  int next_frame = 0;  // clips follow each other without overlap
  const std::vector<ClipInfo> clips = RecordClips(record);
  for (size_t c = 0; c < clips.size(); ++c) {
    const ClipInfo& clip = clips[c];
    if (!std::isfinite(clip.start_time) || clip.first_frame < next_frame || clip.frame_count < 1 ||
        clip.first_frame > sequence.frame_count() - clip.frame_count || clip.animation < -1 ||
        clip.animation >= static_cast<int>(model.animations.size())) {
      return ParseError("scene record clip " + std::to_string(c) + " does not fit the stream's " +
                        std::to_string(sequence.frame_count()) + " frames");
    }
    next_frame = clip.first_frame + clip.frame_count;
    out.clips.push_back(clip);
  }
  return out;
}

// Per written frame, the global transforms of `nodes`: the clip's node animation at the frame's
// time (the rest pose for a clip with none).
StatusOr<std::vector<std::vector<gltf::Matrix4>>> FrameGlobals(const tinygltf::Model& model,
                                                               const std::vector<ClipInfo>& clips,
                                                               double frame_rate,
                                                               const std::vector<int>& nodes) {
  DMC_ASSIGN_OR_RETURN(const gltf::SceneOrder scene, gltf::OrderScene(model));
  const std::vector<gltf::PrimitiveInstance> no_instances;
  const std::vector<std::vector<gltf::Matrix4>> no_binds;
  std::vector<std::vector<gltf::Matrix4>> globals;
  for (const ClipInfo& clip : clips) {
    std::vector<gltf::Channel> channels;
    if (clip.animation >= 0) {
      DMC_ASSIGN_OR_RETURN(
          channels, gltf::LoadChannels(model, model.animations[static_cast<size_t>(clip.animation)],
                                       "animation " + std::to_string(clip.animation)));
    }
    gltf::ScenePoser poser(model, scene, no_instances, no_binds, channels);
    for (int k = 0; k < clip.frame_count; ++k) {
      const std::vector<gltf::Matrix4>& all = poser.NodeGlobals(clip.start_time + k / frame_rate);
      std::vector<gltf::Matrix4>& frame = globals.emplace_back();
      for (const int n : nodes) frame.push_back(all[static_cast<size_t>(n)]);
    }
  }
  return globals;
}

// The clips written (all, or the one named `clip_name`), with a frame standing in when the record
// has none.
StatusOr<std::vector<ClipInfo>> ChooseClips(const Record& record, int frame_count,
                                            const std::string& clip_name) {
  std::vector<ClipInfo> clips = record.clips;
  if (clips.empty()) clips.push_back({"frames", -1, 0.0, 0, frame_count});
  if (clip_name.empty()) return clips;
  const auto found = std::find_if(clips.begin(), clips.end(),
                                  [&](const ClipInfo& clip) { return clip.name == clip_name; });
  if (found == clips.end()) {
    std::string names;
    for (const ClipInfo& clip : clips) names += (names.empty() ? "" : ", ") + clip.name;
    return InvalidArgumentError("the stream has no clip named '" + clip_name + "' (it has " +
                                names + ")");
  }
  return std::vector<ClipInfo>{*found};
}

// What baking every node shares.
struct BakeInput {
  const MeshSequence& sequence;
  const Record& record;
  const std::vector<int>& frames;                  // stream frames written, in order
  const std::vector<std::vector<float>>& normals;  // per written frame, the stream's normals
  const PositionGrid& world_grid;
  bool compact = true;
};

// One node's imported primitives in its own space over the written frames.
struct NodeFrames {
  // [instance][written frame]: x, y, z per vertex.
  std::vector<std::vector<std::vector<double>>> positions;
  std::vector<std::vector<std::vector<float>>> normals;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  double local_scale = 1.0;  // of the first frame's world-to-node transform
};

NodeFrames LocalFrames(const BakeInput& input, const std::vector<const RecordInstance*>& instances,
                       const std::vector<gltf::Matrix4>& node_globals) {
  const size_t frame_count = input.frames.size();
  // World to the node's space, per written frame. A node scaled to nothing hides its mesh (a
  // common trick): any positions do then, and the previous frame's transform keeps them finite.
  std::vector<gltf::Matrix4> to_local(frame_count);
  std::vector<Eigen::Matrix3d> normal_to_local(frame_count);
  for (size_t j = 0; j < frame_count; ++j) {
    const gltf::Matrix4& global = node_globals[j];
    const double det = global.topLeftCorner<3, 3>().determinant();
    if (std::isfinite(det) && std::abs(det) > 1e-18 && global.allFinite()) {
      to_local[j] = global.inverse();
    } else {
      to_local[j] = j > 0 ? to_local[j - 1] : gltf::Matrix4::Identity();
    }
    normal_to_local[j] = to_local[j].topLeftCorner<3, 3>().inverse().transpose();
  }
  NodeFrames out;
  out.local_scale = std::cbrt(std::abs(to_local.front().topLeftCorner<3, 3>().determinant()));
  out.positions.resize(instances.size());
  out.normals.resize(instances.size());
  for (size_t i = 0; i < instances.size(); ++i) {
    const RecordInstance& instance = *instances[i];
    const size_t values = 3 * static_cast<size_t>(instance.vertex_count);
    for (size_t j = 0; j < frame_count; ++j) {
      const auto frame = input.sequence.frame(input.frames[j]);
      const std::vector<float>& world_normals = input.normals[j];
      std::vector<double> points(values);
      std::vector<float> frame_normals(values);
      for (int v = 0; v < instance.vertex_count; ++v) {
        const auto s = static_cast<size_t>(
            input.record.vertex_map[static_cast<size_t>(instance.first_vertex + v)]);
        const Eigen::Vector4d local =
            to_local[j] * Eigen::Vector4d(frame(static_cast<Eigen::Index>(s), 0),
                                          frame(static_cast<Eigen::Index>(s), 1),
                                          frame(static_cast<Eigen::Index>(s), 2), 1.0);
        Eigen::Vector3d n =
            normal_to_local[j] * Eigen::Vector3d(world_normals[3 * s], world_normals[3 * s + 1],
                                                 world_normals[3 * s + 2]);
        n = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d(0, 0, 1);
        const size_t at = 3 * static_cast<size_t>(v);
        for (int c = 0; c < 3; ++c) {
          points[at + static_cast<size_t>(c)] = local[c];
          frame_normals[at + static_cast<size_t>(c)] = static_cast<float>(n[c]);
        }
        out.lo = out.lo.cwiseMin(local.head<3>());
        out.hi = out.hi.cwiseMax(local.head<3>());
      }
      out.positions[i].push_back(std::move(points));
      out.normals[i].push_back(std::move(frame_normals));
    }
  }
  return out;
}

// POSITION and NORMAL of the first written frame and one target per later frame: steps from the
// previous frame on `grid` (compact), or float displacements from the first frame.
void AddMotion(glb::ModelBuilder& builder, const PositionGrid& grid, bool compact,
               const std::vector<std::vector<double>>& positions,
               const std::vector<std::vector<float>>& normals, tinygltf::Primitive& primitive) {
  primitive.targets.clear();
  primitive.attributes.erase(kSceneVertexAttribute);
  if (compact) {
    std::vector<int16_t> previous = grid.Quantize(positions[0]);
    const std::vector<int8_t> base_normals = QuantizeNormals(normals[0]);
    std::vector<int> normal_sum(base_normals.begin(), base_normals.end());
    primitive.attributes["POSITION"] = builder.AddPaddedVec3(previous, /*normalized=*/false);
    primitive.attributes["NORMAL"] = builder.AddPaddedVec3(base_normals, /*normalized=*/true);
    for (size_t j = 1; j < positions.size(); ++j) {
      std::vector<int16_t> current = grid.Quantize(positions[j]);
      std::vector<int16_t> steps(current.size());
      for (size_t k = 0; k < steps.size(); ++k) {
        steps[k] = static_cast<int16_t>(current[k] - previous[k]);
      }
      previous = std::move(current);
      primitive.targets.push_back(
          {{"POSITION", builder.AddPaddedVec3(steps, /*normalized=*/false)},
           {"NORMAL",
            builder.AddPaddedVec3(NormalSteps(normals[j], normal_sum), /*normalized=*/true)}});
    }
    return;
  }
  const std::vector<float> base(positions[0].begin(), positions[0].end());
  primitive.attributes["POSITION"] = builder.AddFloats(base, TINYGLTF_TYPE_VEC3);
  primitive.attributes["NORMAL"] = builder.AddFloats(normals[0], TINYGLTF_TYPE_VEC3);
  for (size_t j = 1; j < positions.size(); ++j) {
    std::vector<float> delta(positions[j].begin(), positions[j].end());
    std::vector<float> normal_delta = normals[j];
    for (size_t k = 0; k < delta.size(); ++k) {
      delta[k] -= base[k];
      normal_delta[k] -= normals[0][k];
    }
    primitive.targets.push_back({{"POSITION", builder.AddFloats(delta, TINYGLTF_TYPE_VEC3)},
                                 {"NORMAL", builder.AddFloats(normal_delta, TINYGLTF_TYPE_VEC3)}});
  }
}

// Bakes node `n`'s imported primitives into a new leaf node, first among its children; returns the
// leaf's index. Primitives the import skipped (points, lines) have no targets, which glTF forbids
// beside primitives that have them: they stay with the original node.
int BakeNode(glb::ModelBuilder& builder, const BakeInput& input, int n,
             const std::vector<const RecordInstance*>& instances,
             const std::vector<gltf::Matrix4>& node_globals) {
  tinygltf::Model& model = builder.model();
  const NodeFrames local = LocalFrames(input, instances, node_globals);
  // One precision for the whole scene: the grid the motion-only GLB uses over every frame,
  // scaled into this node's space, so small parts are not coded finer than large ones.
  const PositionGrid grid(local.lo, local.hi, input.world_grid.step() * local.local_scale);
  tinygltf::Mesh mesh = model.meshes[static_cast<size_t>(instances.front()->mesh)];
  std::vector<bool> imported(mesh.primitives.size(), false);
  for (size_t i = 0; i < instances.size(); ++i) {
    const auto p = static_cast<size_t>(instances[i]->primitive);
    imported[p] = true;
    AddMotion(builder, grid, input.compact, local.positions[i], local.normals[i],
              mesh.primitives[p]);
  }
  std::vector<tinygltf::Primitive> baked, kept;
  for (size_t p = 0; p < mesh.primitives.size(); ++p) {
    (imported[p] ? baked : kept).push_back(mesh.primitives[p]);
  }
  tinygltf::Node& original = model.nodes[static_cast<size_t>(n)];
  if (kept.empty()) {
    original.mesh = -1;
  } else {
    tinygltf::Mesh rest = mesh;
    rest.primitives = std::move(kept);
    rest.weights.clear();
    model.meshes.push_back(std::move(rest));
    original.mesh = static_cast<int>(model.meshes.size()) - 1;
  }
  mesh.primitives = std::move(baked);
  mesh.weights.assign(input.frames.size() - 1, 0.0);
  model.meshes.push_back(std::move(mesh));
  tinygltf::Node leaf;
  leaf.name = model.nodes[static_cast<size_t>(n)].name;
  leaf.mesh = static_cast<int>(model.meshes.size()) - 1;
  if (input.compact) grid.Apply(leaf);
  model.nodes.push_back(std::move(leaf));
  const int leaf_index = static_cast<int>(model.nodes.size()) - 1;
  std::vector<int>& children = model.nodes[static_cast<size_t>(n)].children;
  children.insert(children.begin(), leaf_index);
  return leaf_index;
}

// One animation per clip: the record's node channels and a weights channel per baked node.
// Compact targets are steps from the previous frame (cumulative weights), float ones are relative
// to the first written frame (one-hot); either way LINEAR blends two neighbouring frames.
std::vector<tinygltf::Animation> ClipAnimations(glb::ModelBuilder& builder,
                                                const std::vector<ClipInfo>& clips,
                                                const std::vector<int>& baked_nodes,
                                                size_t target_count, double frame_rate,
                                                bool compact) {
  tinygltf::Model& model = builder.model();
  std::vector<tinygltf::Animation> animations;
  size_t written = 0;  // written frames before the clip
  for (const ClipInfo& clip : clips) {
    tinygltf::Animation animation;
    if (clip.animation >= 0) animation = model.animations[static_cast<size_t>(clip.animation)];
    animation.name = clip.name;
    if (target_count > 0) {
      std::vector<float> times, weights;
      for (int k = 0; k < clip.frame_count; ++k) {
        times.push_back(static_cast<float>(clip.start_time + k / frame_rate));
        const size_t j = written + static_cast<size_t>(k);
        for (size_t t = 0; t < target_count; ++t) {
          weights.push_back(compact ? (t < j ? 1.0f : 0.0f) : (t + 1 == j ? 1.0f : 0.0f));
        }
      }
      const int input = builder.AddFloats(times, TINYGLTF_TYPE_SCALAR);
      const int output = builder.AddFloats(weights, TINYGLTF_TYPE_SCALAR);
      for (const int node : baked_nodes) {
        tinygltf::AnimationSampler sampler;
        sampler.input = input;
        sampler.output = output;
        sampler.interpolation = "LINEAR";
        animation.samplers.push_back(sampler);
        tinygltf::AnimationChannel channel;
        channel.sampler = static_cast<int>(animation.samplers.size()) - 1;
        channel.target_node = node;
        channel.target_path = "weights";
        animation.channels.push_back(channel);
      }
    }
    written += static_cast<size_t>(clip.frame_count);
    if (!animation.channels.empty()) animations.push_back(std::move(animation));
  }
  return animations;
}

// Keeps the meshes nodes show (the stripped originals go).
void DropUnusedMeshes(tinygltf::Model& model) {
  std::vector<int> mesh_map(model.meshes.size(), -1);
  std::vector<tinygltf::Mesh> meshes;
  for (tinygltf::Node& node : model.nodes) {
    if (node.mesh < 0 || static_cast<size_t>(node.mesh) >= mesh_map.size()) continue;
    int& mapped = mesh_map[static_cast<size_t>(node.mesh)];
    if (mapped < 0) {
      mapped = static_cast<int>(meshes.size());
      meshes.push_back(model.meshes[static_cast<size_t>(node.mesh)]);
    }
    node.mesh = mapped;
  }
  model.meshes = std::move(meshes);
}

}  // namespace

StatusOr<std::vector<uint8_t>> EncodeSceneGlb(const MeshSequence& sequence,
                                              std::span<const uint8_t> scene, GlbEncoding encoding,
                                              const std::string& clip_name) {
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  DMC_ASSIGN_OR_RETURN(tinygltf::Model record_model, LoadGlbBytes(scene, "the stream's scene"));
  DMC_ASSIGN_OR_RETURN(const Record record, ReadRecord(record_model, sequence));
  const double frame_rate = sequence.frame_rate > 0 && std::isfinite(sequence.frame_rate)
                                ? sequence.frame_rate
                                : glb::kDefaultFrameRate;
  const bool compact = encoding != GlbEncoding::kFloat;
  DMC_ASSIGN_OR_RETURN(const std::vector<ClipInfo> clips,
                       ChooseClips(record, sequence.frame_count(), clip_name));
  std::vector<int> frames;
  for (const ClipInfo& clip : clips) {
    for (int k = 0; k < clip.frame_count; ++k) frames.push_back(clip.first_frame + k);
  }
  // Each written frame is a morph target, and each clip's weights hold frames² values.
  constexpr size_t kMaxMorphFrames = 8192;
  if (frames.size() > kMaxMorphFrames) {
    return InvalidArgumentError(
        "a GLB of " + std::to_string(frames.size()) + " frames as morph targets is beyond the " +
        std::to_string(kMaxMorphFrames) + " dmc writes: choose a clip, or write a .pc2 cache");
  }
  std::vector<std::vector<float>> normals;
  for (const int f : frames) normals.push_back(FrameNormals(sequence, f));
  const PositionGrid world_grid(sequence);

  // Instances grouped by node, in record order.
  std::vector<int> node_order;
  std::map<int, std::vector<const RecordInstance*>> by_node;
  for (const RecordInstance& instance : record.instances) {
    if (by_node[instance.node].empty()) node_order.push_back(instance.node);
    by_node[instance.node].push_back(&instance);
  }
  DMC_ASSIGN_OR_RETURN(const auto frame_globals,
                       FrameGlobals(record_model, clips, frame_rate, node_order));
  ModelBuilder builder(std::move(record_model));
  tinygltf::Model& model = builder.model();
  const BakeInput input{sequence, record, frames, normals, world_grid, compact};
  std::vector<int> baked_nodes;
  for (size_t rank = 0; rank < node_order.size(); ++rank) {
    std::vector<gltf::Matrix4> node_globals;
    for (const auto& frame : frame_globals) node_globals.push_back(frame[rank]);
    baked_nodes.push_back(
        BakeNode(builder, input, node_order[rank], by_node[node_order[rank]], node_globals));
  }
  model.animations =
      ClipAnimations(builder, clips, baked_nodes, frames.size() - 1, frame_rate, compact);
  DropUnusedMeshes(model);
  std::vector<int> no_extra_accessors;
  DMC_RETURN_IF_ERROR(CompactBuffers(model, no_extra_accessors));

  // The asset is the input's (copyright, extras); dmc wrote the file and says what it holds.
  model.asset.generator = "dmc";
  tinygltf::Value::Object asset_extras = model.asset.extras.IsObject()
                                             ? model.asset.extras.Get<tinygltf::Value::Object>()
                                             : tinygltf::Value::Object();
  tinygltf::Value::Object dmc;
  dmc["layout"] = tinygltf::Value(std::string("morph"));
  dmc["frames"] = tinygltf::Value(static_cast<int>(frames.size()));
  dmc["vertices"] = tinygltf::Value(static_cast<int>(record.vertex_map.size()));
  dmc["frame_rate"] = tinygltf::Value(frame_rate);
  asset_extras["dmc"] = tinygltf::Value(dmc);
  model.asset.extras = tinygltf::Value(asset_extras);
  model.extras = tinygltf::Value();
  if (compact) {
    for (const char* name : {"KHR_mesh_quantization"}) {
      for (auto* list : {&model.extensionsUsed, &model.extensionsRequired}) {
        if (std::find(list->begin(), list->end(), name) == list->end()) list->push_back(name);
      }
    }
  }
  if (encoding == GlbEncoding::kCompact) return SerializeMeshoptGlb(std::move(model));
  return SerializeGlb(model);
}

}  // namespace dmc::io_internal
