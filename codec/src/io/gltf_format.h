// glTF 2.0 import (posing skinned, node-animated and morph-target animations into a dynamic mesh)
// and GLB export (a decoded sequence as a GLB that plays in three.js, Blender, Khronos viewers).
//
// tinygltf (Debian's libtinygltf-dev) parses and serialises the files; its implementation is
// compiled once, in gltf_tinygltf.cpp, without image decoding (dmc never needs pixels: images are
// kept as opaque bytes or URIs), so the only dependency is nlohmann_json.
//
// Posing follows the glTF 2.0 specification, section 3.7 and 3.11:
//  - node local transform = `matrix`, or T·R·S from translation, rotation, scale, where animated
//    paths replace the static values; global = parent global · local, from the scene roots;
//  - morph targets first: p = POSITION + Σ_i w_i · target_i.POSITION, w from the node's animated
//    `weights`, else node.weights, else mesh.weights, else 0;
//  - skinned nodes (node.skin set): p' = Σ_k WEIGHTS_n[k] · (global(joint) · inverseBind(joint)) ·
//  p
//    over every JOINTS_n/WEIGHTS_n set; the mesh node's own transform is ignored, as the spec
//    requires; unskinned nodes: p' = global(node) · p;
//  - keyframes: STEP holds the previous key; LINEAR lerps (slerp on the shortest arc for
//    rotations); CUBICSPLINE is the Hermite spline of the spec with tangents scaled by the key
//    interval (rotations normalised afterwards). Before the first key the first value holds, after
//    the last key the last.
// Everything is computed in double and rounded to float32 once.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/io.h"
#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc::io_internal {

// The result of an import: the posed sequence plus what the caller may want to know.
struct GltfImport {
  MeshSequence sequence;
  // For every vertex of the file, in import order (scene nodes depth-first from the roots, then
  // primitives in order, then the primitive's vertices), the sequence vertex it became. Identity
  // unless welding merged vertices.
  std::vector<int32_t> vertex_map;
  std::vector<ClipInfo> clips;  // in frame order; empty without animation
  std::vector<std::string> warnings;
};

// Appends `size` bytes to `model.buffers[buffer]` (4-byte aligned first, as accessors need) as a
// new buffer view of `target` (0: none); returns the view's index.
inline int AppendBufferView(tinygltf::Model& model, size_t buffer, const void* bytes, size_t size,
                            int target = 0) {
  std::vector<unsigned char>& data = model.buffers[buffer].data;
  while (data.size() % 4 != 0) data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = static_cast<int>(buffer);
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const auto* begin = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), begin, begin + size);
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size()) - 1;
}

// Where a GLB's JSON chunk lies (gltf_import.cpp), after checking the container as the glTF 2.0
// spec (§4.4) defines it: the header's length is the file's, and every chunk fits. tinygltf 2.7
// checks less (a BIN chunk may reach 8 bytes past the file), so nothing reaches it unchecked.
struct GlbJsonChunk {
  size_t offset = 0;
  size_t length = 0;
};
StatusOr<GlbJsonChunk> CheckGlbContainer(std::string_view glb);

// The GLB with its JSON chunk (`chunk`, from CheckGlbContainer) replaced by `json`, padded with
// spaces as the spec asks, and the header's length updated.
std::string ReplaceGlbJson(std::string_view glb, const GlbJsonChunk& chunk, std::string json);

// Loads a .gltf (JSON with external or embedded buffers) or .glb file. kIoError when the file
// cannot be read, kParseError (with tinygltf's message) when it is not valid glTF.
StatusOr<tinygltf::Model> LoadGltfModel(const std::filesystem::path& path);

// A GLB held in memory (a stream's scene record), its container checked first; kParseError
// naming `label` otherwise.
StatusOr<tinygltf::Model> LoadGlbBytes(std::span<const uint8_t> bytes, const std::string& label);

// Poses the model's animation into a sequence (see the top of this file for the maths).
// `max_frames` > 0 keeps only the first frames. Errors:
//  - kInvalidArgument: frame_rate negative or not finite, no mesh or animation of that name;
// A dmc "frames" export (asset.extras.dmc.layout) is read back as its frames, not posed, unless a
// mesh is selected.
//  - kUnsupported: no triangle primitives to import (points/lines only, or no mesh at all);
//  - kParseError: accessors out of their buffers, joints or targets out of range, and other
//    inconsistencies of the file, naming the object at fault.
StatusOr<GltfImport> PoseGltfModel(const tinygltf::Model& model, const GltfReadOptions& options,
                                   int max_frames = 0);

// LoadGltfModel then BuildSceneRecord.
StatusOr<std::vector<uint8_t>> ReadSceneRecord(const std::filesystem::path& path,
                                               const GltfReadOptions& options,
                                               const std::vector<int32_t>& vertex_map,
                                               const std::vector<ClipInfo>& clips,
                                               int stream_vertices);

// LoadGltfModel then PoseGltfModel.
StatusOr<GltfImport> ReadGltf(const std::filesystem::path& path, const GltfReadOptions& options,
                              int max_frames = 0);

// Keeps only the accessors, buffer views and buffer bytes something still refers to (meshes,
// animations, skins, images), in one buffer. `extra_accessors` are referenced from where the walk
// cannot see (extras); they are kept and renumbered in place.
// kParseError when a buffer view lies outside its buffer or a reference names none.
Status CompactBuffers(tinygltf::Model& model, std::vector<int>& extra_accessors);

// The record object of a scene record's GLB (its root extras' kSceneRecordKey), kParseError when
// there is none.
StatusOr<const tinygltf::Value*> FindSceneRecord(const tinygltf::Model& model);
// The record's clips as listed, unchecked (fields that are missing or beyond ±2^30 read as -1).
std::vector<ClipInfo> RecordClips(const tinygltf::Value& record);
// The clips of a scene record (SceneClips in dmc/io.h).
StatusOr<std::vector<ClipInfo>> ReadSceneClips(std::span<const uint8_t> scene);

// The key of the scene record in its GLB's root extras (gltf_scene_record.cpp).
inline constexpr const char* kSceneRecordKey = "dmc_scene";
// The attribute a stripped primitive of the record keeps (glTF needs one): the vertex map.
inline constexpr const char* kSceneVertexAttribute = "_DMC_VERTEX";

// The scene record of `model` (loaded by LoadGltfModel, then posed with `options` into a sequence
// of `stream_vertices` vertices through `vertex_map`, in `clips`); see BuildGltfScene in
// dmc/io.h. Empty for a dmc frames export.
StatusOr<std::vector<uint8_t>> BuildSceneRecord(tinygltf::Model model,
                                                const GltfReadOptions& options,
                                                const std::vector<int32_t>& vertex_map,
                                                const std::vector<ClipInfo>& clips,
                                                int stream_vertices);

// How an exported GLB holds the frames.
enum class GlbLayout {
  kAuto,    // the smallest file of those the encoding allows
  kBasis,   // one mesh, frame 0 as base, a few single-axis morph targets per block of frames
            // (gltf_motion_basis.h) with per-frame weights; quantised encodings only
  kMorph,   // one mesh, frame 0 as base, frames 1.. as morph targets, a LINEAR weights animation
  kFrames,  // one mesh per frame under one parent node, shown in turn by a STEP scale animation
};

// The GLB bytes of a valid sequence: positions, per-frame area-weighted vertex normals, shared
// indices, and an animation playing the frames at sequence.frame_rate (30 fps when unknown).
// The asset's extras record {"dmc": {"layout": "morph"|"frames", "frames": F, "vertices": V,
// "frame_rate": fps}} so viewers can read the frames back without playing the animation.
// How an exported GLB stores vertex data.
enum class GlbEncoding {
  // KHR_mesh_quantization (positions on a 15-bit grid over every frame, dequantised by the mesh
  // node's transform, so within half a grid step, 1/32766 of the largest extent; 8-bit normals)
  // and EXT_meshopt_compression on every buffer view. Both extensions are required.
  kCompact,
  kQuantized,  // kCompact without EXT_meshopt_compression, for readers without a meshopt decoder
  kFloat,      // plain float32 positions and normals: positions exact
};

StatusOr<std::vector<uint8_t>> EncodeGlb(const MeshSequence& sequence,
                                         GlbLayout layout = GlbLayout::kAuto,
                                         GlbEncoding encoding = GlbEncoding::kCompact,
                                         const std::vector<int>& block_starts = {});

// The GLB of a decoded sequence within its scene record (gltf_scene_export.cpp): the record's
// nodes, materials, textures, kept attributes and node animations, the sequence's motion as morph
// targets in `layout` (kBasis or kMorph; kAuto: kBasis compact, kMorph otherwise), each clip (or
// only the
// one named `clip`) as an animation. `block_starts` (sequence frames, e.g. a stream's segment
// starts) begin new blocks of the basis layout, as every clip does. kParseError when the record
// does not fit the sequence, kInvalidArgument for an unknown clip or a layout the encoding or a
// scene cannot have.
StatusOr<std::vector<uint8_t>> EncodeSceneGlb(const MeshSequence& sequence,
                                              std::span<const uint8_t> scene, GlbLayout layout,
                                              GlbEncoding encoding, const std::string& clip,
                                              const std::vector<int>& block_starts = {});

// The model as a GLB, buffer 0 as its BIN chunk.
StatusOr<std::vector<uint8_t>> SerializeGlb(const tinygltf::Model& model);

// The model (one buffer) as a GLB with every buffer view compressed by EXT_meshopt_compression
// (gltf_meshopt_pack.cpp): index views by the triangle codec, the others by the vertex codec.
StatusOr<std::vector<uint8_t>> SerializeMeshoptGlb(tinygltf::Model model);

}  // namespace dmc::io_internal
