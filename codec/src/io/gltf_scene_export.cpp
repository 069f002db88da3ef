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
#include "io/gltf_motion_basis.h"

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
  const std::vector<std::vector<float>>& normals;  // morph layout: per written frame, the stream's
  const PositionGrid& world_grid;
  bool compact = true;
  std::span<const glb::FrameBlock> blocks;  // of the written frames, for the basis layout
};

using glb::WeightTable;

// World to a node's space at each written frame. A node scaled to nothing hides its mesh (a
// common trick): any positions do then, and the previous frame's transform keeps them finite.
struct NodeSpace {
  std::vector<gltf::Matrix4> to_local;
  std::vector<Eigen::Matrix3d> normal_to_local;
  double local_scale = 1.0;  // of the first frame's world-to-node transform

  explicit NodeSpace(const std::vector<gltf::Matrix4>& node_globals) {
    for (size_t j = 0; j < node_globals.size(); ++j) {
      const gltf::Matrix4& global = node_globals[j];
      const double det = global.topLeftCorner<3, 3>().determinant();
      if (std::isfinite(det) && std::abs(det) > 1e-18 && global.allFinite()) {
        to_local.push_back(global.inverse());
      } else {
        to_local.push_back(j > 0 ? to_local[j - 1] : gltf::Matrix4::Identity());
      }
      normal_to_local.push_back(to_local[j].topLeftCorner<3, 3>().inverse().transpose());
    }
    local_scale = std::cbrt(std::abs(to_local.front().topLeftCorner<3, 3>().determinant()));
  }

  // The same transform at every written frame.
  bool Static() const {
    for (const gltf::Matrix4& m : to_local) {
      if ((m - to_local.front()).cwiseAbs().maxCoeff() >
          1e-12 * (1 + to_local.front().cwiseAbs().maxCoeff())) {
        return false;
      }
    }
    return true;
  }

  Eigen::Vector3d Point(const MeshSequence& sequence, int frame, size_t j, size_t s) const {
    const auto row = sequence.frame(frame).row(static_cast<Eigen::Index>(s));
    return (to_local[j] * Eigen::Vector4d(row(0), row(1), row(2), 1.0)).head<3>();
  }
  // Unit normal in the node's space of the world normal at `world` (x, y, z).
  Eigen::Vector3d Normal(size_t j, const float* world) const {
    const Eigen::Vector3d n = normal_to_local[j] * Eigen::Vector3d(world[0], world[1], world[2]);
    return n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d(0, 0, 1);
  }
};

// One precision for the whole scene: the grid the motion-only GLB uses over every frame, scaled
// into the node's space, so small parts are not coded finer than large ones.
PositionGrid NodeGrid(const BakeInput& input, const std::vector<const RecordInstance*>& instances,
                      const NodeSpace& space) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (size_t j = 0; j < input.frames.size(); ++j) {
    for (const RecordInstance* instance : instances) {
      for (int v = 0; v < instance->vertex_count; ++v) {
        const auto s = static_cast<size_t>(
            input.record.vertex_map[static_cast<size_t>(instance->first_vertex + v)]);
        const Eigen::Vector3d local = space.Point(input.sequence, input.frames[j], j, s);
        lo = lo.cwiseMin(local);
        hi = hi.cwiseMax(local);
      }
    }
  }
  return PositionGrid(lo, hi, input.world_grid.step() * space.local_scale);
}

// One node's imported primitives in its own space over the written frames (the morph layout).
struct NodeFrames {
  // [instance][written frame]: x, y, z per vertex.
  std::vector<std::vector<std::vector<double>>> positions;
  std::vector<std::vector<std::vector<float>>> normals;
};

NodeFrames LocalFrames(const BakeInput& input, const std::vector<const RecordInstance*>& instances,
                       const NodeSpace& space) {
  NodeFrames out;
  out.positions.resize(instances.size());
  out.normals.resize(instances.size());
  for (size_t i = 0; i < instances.size(); ++i) {
    const RecordInstance& instance = *instances[i];
    const size_t values = 3 * static_cast<size_t>(instance.vertex_count);
    for (size_t j = 0; j < input.frames.size(); ++j) {
      std::vector<double> points(values);
      std::vector<float> frame_normals(values);
      for (int v = 0; v < instance.vertex_count; ++v) {
        const auto s = static_cast<size_t>(
            input.record.vertex_map[static_cast<size_t>(instance.first_vertex + v)]);
        const Eigen::Vector3d local = space.Point(input.sequence, input.frames[j], j, s);
        const Eigen::Vector3d n = space.Normal(j, &input.normals[j][3 * s]);
        const size_t at = 3 * static_cast<size_t>(v);
        for (int c = 0; c < 3; ++c) {
          points[at + static_cast<size_t>(c)] = local[c];
          frame_normals[at + static_cast<size_t>(c)] = static_cast<float>(n[c]);
        }
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

// The baked nodes: per node its imported instances, space and grid.
struct BakedNode {
  int node = -1;
  std::vector<const RecordInstance*> instances;
  NodeSpace space;
  PositionGrid grid;
};

// The basis layout (gltf_motion_basis.h) of every baked node, fitted together over their stacked
// vertices (each in its node's space and grid), so that every node shares one weight table: the
// targets, and the first written frame as the base.
struct SceneBasis {
  std::vector<size_t> first;  // per node and instance, in order: its first stacked vertex
  std::vector<int16_t> base_positions;
  std::vector<int8_t> base_normals;
  std::vector<glb::BlockTarget> positions, normals;
  WeightTable weights;
};

SceneBasis FitSceneBasis(const BakeInput& input, const std::vector<BakedNode>& nodes) {
  SceneBasis out;
  size_t stacked = 0;
  for (const BakedNode& node : nodes) {
    for (const RecordInstance* instance : node.instances) {
      out.first.push_back(stacked);
      stacked += static_cast<size_t>(instance->vertex_count);
    }
  }
  // Calls `visit(node, stream vertex, stacked vertex)` for every stacked vertex.
  const auto each_vertex = [&](const auto& visit) {
    size_t at = 0;
    for (const BakedNode& node : nodes) {
      for (const RecordInstance* instance : node.instances) {
        for (int v = 0; v < instance->vertex_count; ++v, ++at) {
          visit(node,
                static_cast<size_t>(
                    input.record.vertex_map[static_cast<size_t>(instance->first_vertex + v)]),
                at);
        }
      }
    }
  };
  const auto positions = [&](int j, std::vector<double>& values) {
    const auto uj = static_cast<size_t>(j);
    each_vertex([&](const BakedNode& node, size_t s, size_t at) {
      const Eigen::Vector3d local = node.space.Point(input.sequence, input.frames[uj], uj, s);
      for (int c = 0; c < 3; ++c)
        values[3 * at + static_cast<size_t>(c)] = node.grid.ToGrid(local[c], c);
    });
  };
  const auto normals = [&](int j, std::vector<double>& values) {
    const auto uj = static_cast<size_t>(j);
    const std::vector<float> world = FrameNormals(input.sequence, input.frames[uj]);
    each_vertex([&](const BakedNode& node, size_t s, size_t at) {
      const Eigen::Vector3d n = node.space.Normal(uj, &world[3 * s]);
      for (int c = 0; c < 3; ++c) values[3 * at + static_cast<size_t>(c)] = 32767.0 * n[c];
    });
  };
  std::vector<double> first_frame(3 * stacked);
  positions(0, first_frame);
  for (const double value : first_frame) {
    out.base_positions.push_back(static_cast<int16_t>(
        std::clamp(std::round(value), -PositionGrid::kHalfRange, PositionGrid::kHalfRange)));
  }
  normals(0, first_frame);
  for (const double value : first_frame) {
    out.base_normals.push_back(
        static_cast<int8_t>(std::clamp(std::round(value * 127.0 / 32767.0), -127.0, 127.0)));
  }
  const std::vector<double> position_base(out.base_positions.begin(), out.base_positions.end());
  std::vector<double> normal_base(out.base_normals.size());
  for (size_t k = 0; k < normal_base.size(); ++k) {
    normal_base[k] = 32767.0 / 127.0 * out.base_normals[k];
  }
  out.positions =
      glb::FitBlockTargets(positions, position_base, input.blocks, glb::kBasisPositionTolerance);
  out.normals =
      glb::FitBlockTargets(normals, normal_base, input.blocks, glb::kBasisNormalTolerance);
  out.weights = glb::BasisWeights(out.positions, out.normals, input.blocks,
                                  static_cast<int>(input.frames.size()));
  return out;
}

// Moves node `node.node`'s imported primitives, once `add_motion(instance, primitive)` has given
// each its motion, into a new leaf node first among its children; returns the leaf's index.
// Primitives the import skipped (points, lines) have no targets, which glTF forbids beside
// primitives that have them: they stay with the original node.
template <typename AddMotionToPrimitive>
int BakeNode(glb::ModelBuilder& builder, const BakedNode& node, bool compact,
             const AddMotionToPrimitive& add_motion) {
  tinygltf::Model& model = builder.model();
  tinygltf::Mesh mesh = model.meshes[static_cast<size_t>(node.instances.front()->mesh)];
  std::vector<bool> imported(mesh.primitives.size(), false);
  for (size_t i = 0; i < node.instances.size(); ++i) {
    const auto p = static_cast<size_t>(node.instances[i]->primitive);
    imported[p] = true;
    tinygltf::Primitive& primitive = mesh.primitives[p];
    primitive.targets.clear();
    primitive.attributes.erase(kSceneVertexAttribute);
    add_motion(i, primitive);
  }
  const size_t target_count =
      mesh.primitives[static_cast<size_t>(node.instances[0]->primitive)].targets.size();
  std::vector<tinygltf::Primitive> baked, kept;
  for (size_t p = 0; p < mesh.primitives.size(); ++p) {
    (imported[p] ? baked : kept).push_back(mesh.primitives[p]);
  }
  tinygltf::Node& original = model.nodes[static_cast<size_t>(node.node)];
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
  mesh.weights.assign(target_count, 0.0);
  model.meshes.push_back(std::move(mesh));
  tinygltf::Node leaf;
  leaf.name = model.nodes[static_cast<size_t>(node.node)].name;
  leaf.mesh = static_cast<int>(model.meshes.size()) - 1;
  if (compact) node.grid.Apply(leaf);
  model.nodes.push_back(std::move(leaf));
  const int leaf_index = static_cast<int>(model.nodes.size()) - 1;
  std::vector<int>& children = model.nodes[static_cast<size_t>(node.node)].children;
  children.insert(children.begin(), leaf_index);
  return leaf_index;
}

// The morph layout's weights: compact targets are steps from the previous frame (cumulative
// weights), float ones are relative to the first written frame (one-hot); either way LINEAR blends
// two neighbouring frames.
WeightTable MorphWeights(size_t frame_count, bool compact) {
  WeightTable weights(frame_count, std::vector<float>(frame_count - 1, 0.0f));
  for (size_t j = 0; j < frame_count; ++j) {
    for (size_t t = 0; t + 1 < frame_count; ++t) {
      weights[j][t] = compact ? (t < j ? 1.0f : 0.0f) : (t + 1 == j ? 1.0f : 0.0f);
    }
  }
  return weights;
}

// One animation per clip: the record's node channels and a weights channel per baked node, from
// the node's weight table (nodes sharing a table share the sampler's output).
std::vector<tinygltf::Animation> ClipAnimations(glb::ModelBuilder& builder,
                                                const std::vector<ClipInfo>& clips,
                                                const std::vector<int>& baked_nodes,
                                                const std::vector<const WeightTable*>& tables,
                                                double frame_rate) {
  tinygltf::Model& model = builder.model();
  std::vector<tinygltf::Animation> animations;
  size_t written = 0;  // written frames before the clip
  for (const ClipInfo& clip : clips) {
    tinygltf::Animation animation;
    if (clip.animation >= 0) animation = model.animations[static_cast<size_t>(clip.animation)];
    animation.name = clip.name;
    std::vector<float> times;
    for (int k = 0; k < clip.frame_count; ++k) {
      times.push_back(static_cast<float>(clip.start_time + k / frame_rate));
    }
    int input = -1;
    std::map<const WeightTable*, int> outputs;
    for (size_t b = 0; b < baked_nodes.size(); ++b) {
      const WeightTable& table = *tables[b];
      if (table.empty() || table[0].empty()) continue;  // a node without targets
      if (input < 0) input = builder.AddFloats(times, TINYGLTF_TYPE_SCALAR);
      auto [output, added] = outputs.try_emplace(&table, -1);
      if (added) {
        std::vector<float> weights;
        for (int k = 0; k < clip.frame_count; ++k) {
          const std::vector<float>& frame = table[written + static_cast<size_t>(k)];
          weights.insert(weights.end(), frame.begin(), frame.end());
        }
        output->second = builder.AddFloats(weights, TINYGLTF_TYPE_SCALAR);
      }
      tinygltf::AnimationSampler sampler;
      sampler.input = input;
      sampler.output = output->second;
      sampler.interpolation = "LINEAR";
      animation.samplers.push_back(sampler);
      tinygltf::AnimationChannel channel;
      channel.sampler = static_cast<int>(animation.samplers.size()) - 1;
      channel.target_node = baked_nodes[b];
      channel.target_path = "weights";
      animation.channels.push_back(channel);
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
                                              std::span<const uint8_t> scene, GlbLayout layout,
                                              GlbEncoding encoding, const std::string& clip_name,
                                              const std::vector<int>& block_starts) {
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  DMC_ASSIGN_OR_RETURN(tinygltf::Model record_model, LoadGlbBytes(scene, "the stream's scene"));
  DMC_ASSIGN_OR_RETURN(const Record record, ReadRecord(record_model, sequence));
  const double frame_rate = sequence.frame_rate > 0 && std::isfinite(sequence.frame_rate)
                                ? sequence.frame_rate
                                : glb::kDefaultFrameRate;
  const bool compact = encoding != GlbEncoding::kFloat;
  if (layout == GlbLayout::kFrames) {
    return InvalidArgumentError(
        "the frames layout cannot hold a scene: use the basis or morph layout, or leave the scene "
        "out");
  }
  if (layout == GlbLayout::kBasis && !compact) {
    return InvalidArgumentError(
        "the basis layout stores quantised targets: use the compact or quantized encoding");
  }
  DMC_ASSIGN_OR_RETURN(const std::vector<ClipInfo> clips,
                       ChooseClips(record, sequence.frame_count(), clip_name));
  std::vector<int> frames;
  std::vector<int> block_firsts;  // written frames where a stream segment starts
  for (const ClipInfo& clip : clips) {
    for (int k = 0; k < clip.frame_count; ++k) {
      const int f = clip.first_frame + k;
      // A segment's frames are low rank together across clips, so only segments (and a
      // discontinuity in the frames written) start blocks.
      const bool follows = !frames.empty() && frames.back() + 1 == f;
      if (!follows ||
          std::find(block_starts.begin(), block_starts.end(), f) != block_starts.end()) {
        block_firsts.push_back(static_cast<int>(frames.size()));
      }
      frames.push_back(f);
    }
  }
  const std::vector<glb::FrameBlock> blocks =
      glb::SplitBlocks(static_cast<int>(frames.size()), block_firsts);
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

  const auto write = [&](GlbLayout layout,
                         tinygltf::Model base_model) -> StatusOr<std::vector<uint8_t>> {
    // In the morph layout each written frame is a target, and each clip's weights hold frames²
    // values.
    constexpr size_t kMaxMorphFrames = 8192;
    if (layout == GlbLayout::kMorph && frames.size() > kMaxMorphFrames) {
      return InvalidArgumentError(
          "a GLB of " + std::to_string(frames.size()) + " frames as morph targets is beyond the " +
          std::to_string(kMaxMorphFrames) + " dmc writes: choose a clip, or write a .pc2 cache");
    }
    // The morph layout's normals of every written frame (the basis layout computes them per frame).
    std::vector<std::vector<float>> normals;
    if (layout == GlbLayout::kMorph) {
      for (const int f : frames) normals.push_back(FrameNormals(sequence, f));
    }
    ModelBuilder builder(std::move(base_model));
    tinygltf::Model& model = builder.model();
    const BakeInput input{sequence, record, frames, normals, world_grid, compact, blocks};
    std::vector<BakedNode> nodes;
    for (size_t rank = 0; rank < node_order.size(); ++rank) {
      std::vector<gltf::Matrix4> node_globals;
      for (const auto& frame : frame_globals) node_globals.push_back(frame[rank]);
      NodeSpace space(node_globals);
      const std::vector<const RecordInstance*>& instances = by_node[node_order[rank]];
      PositionGrid grid = NodeGrid(input, instances, space);
      nodes.push_back({node_order[rank], instances, std::move(space), grid});
    }
    std::vector<int> baked_nodes;
    std::vector<const WeightTable*> tables;
    std::vector<SceneBasis> bases;
    WeightTable morph_weights;
    if (layout == GlbLayout::kBasis) {
      // Nodes that stay put share their targets and weights (their motion is the stream's, low
      // rank together); one that moves holds what its transform leaves over, which is its own.
      std::vector<std::vector<BakedNode>> groups(1);
      for (BakedNode& node : nodes) {
        if (node.space.Static()) {
          groups[0].push_back(std::move(node));
        } else {
          groups.push_back({std::move(node)});
        }
      }
      bases.reserve(groups.size());
      for (const std::vector<BakedNode>& group : groups) {
        if (group.empty()) continue;
        const SceneBasis& basis = bases.emplace_back(FitSceneBasis(input, group));
        size_t slot = 0;  // node and instance, in order
        for (const BakedNode& node : group) {
          tables.push_back(&basis.weights);
          baked_nodes.push_back(
              BakeNode(builder, node, compact, [&](size_t, tinygltf::Primitive& primitive) {
                const size_t first = basis.first[slot++];
                const size_t vertices = slot < basis.first.size()
                                            ? basis.first[slot] - first
                                            : basis.base_normals.size() / 3 - first;
                const auto at = [](size_t vertex) { return static_cast<long>(3 * vertex); };
                primitive.attributes["POSITION"] = builder.AddPaddedVec3(
                    std::vector<int16_t>(basis.base_positions.begin() + at(first),
                                         basis.base_positions.begin() + at(first + vertices)),
                    /*normalized=*/false);
                primitive.attributes["NORMAL"] = builder.AddPaddedVec3(
                    std::vector<int8_t>(basis.base_normals.begin() + at(first),
                                        basis.base_normals.begin() + at(first + vertices)),
                    /*normalized=*/true);
                glb::AddBasisTargets(builder, basis.positions, basis.normals, first, vertices,
                                     primitive);
              }));
        }
      }
    } else {
      morph_weights = MorphWeights(frames.size(), compact);
      for (const BakedNode& node : nodes) {
        const NodeFrames local = LocalFrames(input, node.instances, node.space);
        baked_nodes.push_back(
            BakeNode(builder, node, compact, [&](size_t i, tinygltf::Primitive& primitive) {
              AddMotion(builder, node.grid, compact, local.positions[i], local.normals[i],
                        primitive);
            }));
        tables.push_back(&morph_weights);
      }
    }
    model.animations = ClipAnimations(builder, clips, baked_nodes, tables, frame_rate);
    DropUnusedMeshes(model);
    std::vector<int> no_extra_accessors;
    DMC_RETURN_IF_ERROR(CompactBuffers(model, no_extra_accessors));

    // The asset is the input's (copyright, extras); dmc wrote the file and says what it holds.
    model.asset.generator = "dmc";
    tinygltf::Value::Object asset_extras = model.asset.extras.IsObject()
                                               ? model.asset.extras.Get<tinygltf::Value::Object>()
                                               : tinygltf::Value::Object();
    tinygltf::Value::Object dmc;
    dmc["layout"] = tinygltf::Value(std::string(layout == GlbLayout::kBasis ? "basis" : "morph"));
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
  };

  // Auto: basis in the compact files (three.js), morph otherwise. The quantized encoding is for
  // importers without a meshopt decoder, Blender's above all, whose glTF importer (3.4) clamps
  // shape-key values to [0, 1]: the morph layout's weights are 0 or 1, the basis layout's are
  // any real (−0.8 … 2.3 on CesiumMan).
  if (layout == GlbLayout::kAuto) {
    layout = encoding == GlbEncoding::kCompact ? GlbLayout::kBasis : GlbLayout::kMorph;
  }
  return write(layout, std::move(record_model));
}

}  // namespace dmc::io_internal
