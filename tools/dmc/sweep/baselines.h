// The peers dmc is compared with in `dmc sweep`: what a user would otherwise do with an animated
// mesh, built on the real libraries and decoded back so the same metrics measure them.
//
//   draco    every frame compressed on its own by Draco's mesh encoder (edgebreaker, encoding and
//            decoding speed 0 = best compression, positions quantised to `bits` per coordinate
//            over that frame's bounding box, Draco's default parallelogram prediction). The
//            stream is the frame count and the Draco buffers, each preceded by its size.
//   meshopt  the glTF pipeline for vertex animation: the triangles reordered for the vertex
//            cache and the vertices for fetch locality (meshopt_optimizeVertexCache, then
//            meshopt_optimizeVertexFetchRemap, as gltfpack does), the index buffer coded once
//            with meshopt_encodeIndexBuffer, every frame's positions quantised to `bits` on one
//            grid for the whole sequence, stored as four uint16 per vertex (KHR_mesh_quantization
//            layout, the fourth is padding) and coded by meshopt_encodeVertexBuffer; the whole
//            stream then goes through zstd at its best level.
//   zstd     positions quantised to `bits` on the same sequence-wide grid, frame 0 as is and
//            every later frame as its difference to the previous one (exact: differences of
//            integers, so there is no drift), zigzag-mapped to the narrowest unsigned width that
//            holds them all and split into byte planes (all low bytes of x, then the next byte,
//            …, per axis and frame) so zstd sees runs of similar bytes; the triangles as int32.
//            One zstd frame at the best level (ZSTD_maxCLevel()).
//
// The sequence-wide grid (meshopt, zstd) is a cube: step = (largest extent of the bounding box
// over all frames) / (2^bits − 1), origin = the box's minimum corner, so every axis gets the same
// precision as glTF quantisation does.
//
// Vertex order. Draco and the meshopt pipeline renumber vertices; a user does not mind, but the
// metrics compare vertex by vertex. Each encoder therefore also returns `input_vertex`, the input
// vertex of every decoded vertex, taken from the encoder (Draco's own encoding data, meshopt's
// remap). It is a measurement aid that a real pipeline would not transmit, so it is NOT counted
// in the stream's bytes (this flatters the peers slightly, never dmc). RestoreInputOrder applies
// it. Draco's traversal depends on the connectivity only, so the permutation is the same for
// every frame; the encoder checks this and fails otherwise.
//
// Every decoder takes only the stream and checks sizes before it uses them: a damaged stream is
// kCorruptStream or kTruncatedStream, never a crash.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc::sweep {

enum class BaselineKind { kDraco, kMeshopt, kZstd };

// "draco", "meshopt", "zstd".
std::string_view BaselineName(BaselineKind kind);
// The kind of a name above; kInvalidArgument listing the known names otherwise.
StatusOr<BaselineKind> ParseBaseline(std::string_view name);
// Every baseline, in the order above.
std::vector<BaselineKind> AllBaselines();

// Position quantisation bits every baseline accepts (Draco allows up to 30, but the meshopt
// layout is uint16 and the comparison is meant on one scale).
inline constexpr int kMinBaselineBits = 4;
inline constexpr int kMaxBaselineBits = 16;

struct BaselineStream {
  std::vector<uint8_t> bytes;         // everything the decoder reads: the counted rate
  std::vector<int32_t> input_vertex;  // decoded vertex i is input vertex input_vertex[i]
};

// Compresses `sequence` (which must pass ValidateSequence) with `bits` of position quantisation.
// kInvalidArgument for bits outside [kMinBaselineBits, kMaxBaselineBits]; kUnsupported when the
// library cannot code the mesh (Draco splits non-manifold vertices, so its output would not map
// one to one onto the input).
StatusOr<BaselineStream> EncodeBaseline(BaselineKind kind, const MeshSequence& sequence, int bits);

// Decodes a stream of EncodeBaseline: frames in the codec's vertex order, with its triangles.
StatusOr<MeshSequence> DecodeBaseline(BaselineKind kind, std::span<const uint8_t> bytes);

// Renumbers `decoded` to input order: output vertex input_vertex[i] is decoded vertex i, and every
// triangle index is mapped the same way. `input_vertex` must be a permutation of
// [0, vertex_count) (kMismatch otherwise). An empty `input_vertex` means the identity.
StatusOr<MeshSequence> RestoreInputOrder(const MeshSequence& decoded,
                                         std::span<const int32_t> input_vertex);

}  // namespace dmc::sweep
