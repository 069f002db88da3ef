// Internal: the steps of a glTF import (gltf_import.cpp drives them; the maths is summarised in
// gltf_format.h), one file each:
//  - gltf_accessors.cpp: accessors (strides, normalisation, sparse substitution) and triangles;
//  - gltf_animation.cpp: animation channels and their keyframe sampling;
//  - gltf_scene.cpp: node order, the triangle primitives with their morph targets and skins;
//  - gltf_posing.cpp: one frame's node transforms, morphing and skinning;
//  - gltf_weld.cpp: merging vertices whose trajectories coincide (seams);
//  - gltf_extensions.cpp: required extensions, meshopt- and Draco-compressed geometry.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/gltf_format.h"

namespace dmc::io_internal::gltf {

using Matrix4 = Eigen::Matrix4d;

// ----- JSON values -----------------------------------------------------------------------------

// `value[key]`, or a null value when `value` is not an object or has no such member (tinygltf's
// Value::Get asserts on non-objects).
inline const tinygltf::Value& Member(const tinygltf::Value& value, const char* key) {
  static const tinygltf::Value kNull;
  return value.IsObject() && value.Has(key) ? value.Get(key) : kNull;
}

// An integer member within ±2^30, else `fallback` (a scene record comes from a stream: any value
// may be there).
inline int IntMember(const tinygltf::Value& object, const char* key, int fallback = -1) {
  const tinygltf::Value& value = Member(object, key);
  if (!value.IsNumber() && !value.IsInt()) return fallback;
  const double number = value.GetNumberAsDouble();
  return std::abs(number) <= 0x1p30 && number == std::floor(number) ? static_cast<int>(number)
                                                                    : fallback;
}

// Whether `model` is a dmc "frames" export (asset.extras.dmc.layout), which holds one mesh per
// frame rather than a scene to pose.
inline bool IsDmcFramesExport(const tinygltf::Model& model) {
  const tinygltf::Value& layout = Member(Member(model.asset.extras, "dmc"), "layout");
  return layout.IsString() && layout.Get<std::string>() == "frames";
}

// ----- Accessors (gltf_accessors.cpp) ----------------------------------------------------------

// Accessor `index` as count × components doubles (sparse substitution applied); kParseError
// naming the accessor and `what` it is for when it does not fit its buffers.
StatusOr<std::vector<double>> ReadAccessor(const tinygltf::Model& model, int index,
                                           std::string_view what, int* components_out = nullptr);

// Points and lines are not imported.
bool IsTriangleMode(int mode);

// Appends the triangles of `primitive` (list, strip or fan) with vertex indices `indices` into a
// primitive of `vertex_count` vertices, shifted by `offset`. kParseError naming `label` for an
// index outside the primitive.
Status AppendTriangles(const tinygltf::Primitive& primitive, const std::vector<double>& indices,
                       int vertex_count, int offset, std::vector<int32_t>& triangles,
                       const std::string& label);

// A flat index list (3 per triangle) as a Triangles matrix.
Triangles ToTriangles(const std::vector<int32_t>& indices);

// ----- Animation (gltf_animation.cpp) ----------------------------------------------------------

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

  // The channel's value at time t: the first key's before it, the last key's after.
  std::vector<double> Sample(double t) const;
};

// The channels of `animation` that move nodes; kParseError naming `animation_label` and the
// channel at fault.
StatusOr<std::vector<Channel>> LoadChannels(const tinygltf::Model& model,
                                            const tinygltf::Animation& animation,
                                            const std::string& animation_label);

// The animation named (or numbered) `wanted`, the first when empty, -1 when the file has none.
// kInvalidArgument listing the file's animations when none matches.
StatusOr<int> FindAnimation(const tinygltf::Model& model, const std::string& wanted);

// ----- Scene (gltf_scene.cpp) ------------------------------------------------------------------

struct SceneOrder {
  std::vector<int> parent;  // per node, -1 for a root
  std::vector<int> order;   // depth-first from the scene roots: parents before children
};

// The default scene's nodes (else the first scene's, else every node that is nobody's child) in
// depth-first order. kParseError for a missing child, a node with two parents or reached twice.
StatusOr<SceneOrder> OrderScene(const tinygltf::Model& model);

struct NodePose {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  std::optional<Matrix4> matrix;  // a static `matrix` node (animated paths do not apply to it)
  std::vector<double> weights;

  Matrix4 Local() const;
};

NodePose StaticPose(const tinygltf::Node& node);

// One triangle primitive of one mesh node, with everything its vertices need per frame.
struct PrimitiveInstance {
  int node = -1;
  int mesh = -1;       // the node's mesh
  int primitive = -1;  // the primitive's index in it
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

struct ScenePrimitives {
  std::vector<PrimitiveInstance> instances;  // in import order
  std::vector<int32_t> triangles;            // 3 indices per triangle into all their vertices
  int vertex_total = 0;
};

// The triangle primitives of the mesh nodes in `order` (only those of the mesh or node named
// `mesh_name` when not empty); skipped primitives are reported in `warnings`. kInvalidArgument
// when no mesh or node has that name, kUnsupported when nothing is left to import, kParseError
// for inconsistent accessors, targets or skins.
StatusOr<ScenePrimitives> CollectPrimitives(const tinygltf::Model& model,
                                            const std::vector<int>& order,
                                            const std::string& mesh_name,
                                            std::vector<std::string>& warnings);

// Per skin, its joints' inverse bind matrices; empty for the skins no instance uses.
StatusOr<std::vector<std::vector<Matrix4>>> InverseBindMatrices(
    const tinygltf::Model& model, const std::vector<PrimitiveInstance>& instances);

// ----- Posing (gltf_posing.cpp) ----------------------------------------------------------------

// Poses the scene frame after frame: node transforms from the animation channels, then per
// instance morph targets and skinning (or the node's global transform). Holds references to its
// arguments, which must outlive it.
class ScenePoser {
 public:
  ScenePoser(const tinygltf::Model& model, const SceneOrder& scene,
             const std::vector<PrimitiveInstance>& instances,
             const std::vector<std::vector<Matrix4>>& inverse_binds,
             const std::vector<Channel>& channels);

  // Writes the positions of every instance at `time` into `frame` (all instances' vertices).
  // kInvalidSequence "vertex 12, coordinate y: the posed value 1e+300 is out of float32 range"
  // when transforms take a finite position beyond what a float holds.
  Status Pose(double time, Eigen::Map<FramePositions> frame);

  // Every scene node's global transform at `time` (identity for nodes outside the scene).
  const std::vector<Matrix4>& NodeGlobals(double time) {
    PoseNodes(time);
    return globals_;
  }

 private:
  // poses_, globals_ and joint_matrices_ at `time`.
  void PoseNodes(double time);
  Status PoseInstance(const PrimitiveInstance& instance, Eigen::Map<FramePositions>& frame) const;

  const tinygltf::Model& model_;
  const SceneOrder& scene_;
  const std::vector<PrimitiveInstance>& instances_;
  const std::vector<std::vector<Matrix4>>& inverse_binds_;
  const std::vector<Channel>& channels_;
  std::vector<NodePose> static_poses_;
  std::vector<NodePose> poses_;
  std::vector<Matrix4> globals_;
  std::vector<std::vector<Matrix4>> joint_matrices_;
};

// ----- Extensions (gltf_extensions.cpp) --------------------------------------------------------

// kUnsupported naming the first required extension that could change the geometry dmc reads and
// that dmc does not decode (materials, textures, lights and metadata may be required).
Status CheckRequiredExtensions(const tinygltf::Model& model);

// What tinygltf 2.7 cannot load as the compressed-geometry extensions lay it out, replaced in the
// JSON before loading and restored after:
//  - an EXT_meshopt_compression fallback buffer has no data, and tinygltf refuses a buffer
//    without data: it gets a one-byte stand-in until the decoded views fill it;
//  - a KHR_draco_mesh_compression primitive's index accessor has no buffer view, which tinygltf
//    refuses: the primitive's "indices" is held back.
struct FallbackBuffer {
  size_t index = 0;
  uint64_t byte_length = 0;  // as the file declares it
};
struct DracoIndices {
  size_t mesh = 0, primitive = 0;
  uint64_t accessor = 0;
};
struct CompressedGeometryStandIns {
  std::vector<FallbackBuffer> fallbacks;
  std::vector<DracoIndices> draco_indices;
};

// The glTF JSON with the stand-ins above, recorded in `stand_ins`; the text unchanged when there is
// nothing to replace (or when it is not JSON: tinygltf reports that).
StatusOr<std::string> PrepareCompressedGeometry(std::string_view json_text,
                                                CompressedGeometryStandIns& stand_ins);

// Restores the held-back indices and gives every fallback buffer its declared size (zeros),
// refusing sizes beyond what its views can decode to (a meshopt stream expands at most 64-fold).
Status RestoreCompressedGeometry(tinygltf::Model& model,
                                 const CompressedGeometryStandIns& stand_ins);

// Decodes every EXT_meshopt_compression buffer view (meshoptimizer, filters included) into its
// buffer and every KHR_draco_mesh_compression primitive (Draco) into new float32 / uint32
// accessors, then drops both extensions from the model. kParseError naming the view or
// primitive when its data is corrupt or does not match its accessors.
Status DecodeCompressedGeometry(tinygltf::Model& model);

// ----- Welding (gltf_weld.cpp) -----------------------------------------------------------------

// Merges the vertices of `result.sequence` whose trajectories coincide within 1e-6 of the
// bounding-box diagonal in every frame, drops the triangles that collapse, sets
// result.vertex_map and reports the merge in result.warnings. kUnsupported when every triangle
// collapses.
Status WeldImport(GltfImport& result, const std::vector<int32_t>& triangles);

}  // namespace dmc::io_internal::gltf
