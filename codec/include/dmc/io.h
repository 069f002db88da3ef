// Reading and writing mesh sequences: per-frame OBJ/OFF/PLY files and PC2 point caches.
//
// Contracts shared by every function here:
//  - Vertex order and triangle order are kept exactly as they are in the file; nothing is merged,
//    dropped or reordered (isolated vertices stay, degenerate triangles stay and are reported by
//    ValidateSequence). Faces with more than three corners are fan-triangulated from their first
//    corner, (c0, c1, c2), (c0, c2, c3), ..., in file order, with a warning.
//  - Written coordinates use the shortest decimal form that reads back to the identical float, so
//    write-then-read is bit-exact.
//  - Errors name what is at fault: parse errors are "<path>:<line>: <what>" (kParseError); frames
//    that disagree with frame 0 are "frame 7 (<path>): 9970 vertices, expected 9971" (kMismatch);
//    non-finite coordinates are "frame 3 (<path>), vertex 12: coordinate y is not finite"
//    (kInvalidSequence); files that cannot be opened, read or written give kIoError.
//  - Writers never leave a half-written output and never destroy an existing output on failure:
//    they write to a temporary sibling and rename it into place.
//
// Why not OpenMesh's readers throughout: OpenMesh 9's OBJ, OFF and ASCII PLY readers return success
// on malformed files (an OBJ "v 1 2" line is silently dropped, shifting every later index; an OFF
// or ASCII PLY token "abc" or a truncated face list yields uninitialised or repeated values), and
// OpenMesh's default importer drops faces with a repeated corner and re-creates vertices of
// non-manifold faces at the end. Its binary PLY reader does not stop at the end of its input and
// tokenises the header differently from any strict parser, so a hostile file could make it
// allocate gigabytes. So every format is parsed by a small strict parser here, and OpenMesh is
// only the tests' oracle on well-formed files. The OBJ writer of OpenMesh prints fixed-point
// with 9 decimals, which loses small values, so the writers are ours too.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc {

// Called as frames are read or written: (frames done, frames in all). May be empty. Frames are
// read on several threads; the callback is invoked by one of them at a time, never concurrently.
using IoProgressCallback = std::function<void(int done, int total)>;

// glTF/GLB inputs only (see ReadSequence).
struct GltfReadOptions {
  // The animation is sampled at t0, t0 + 1/fps, ... up to its end. 0 = the rate a dmc export
  // records (asset.extras.dmc.frame_rate), else the rate the clip is keyed at when every key lies
  // on one grid of 12 to 240 per second (a baked animation: CesiumMan and Fox are keyed at 24),
  // else 30.
  double frame_rate = 0.0;
  // Empty: every mesh node of the default scene, all primitives, concatenated in scene order.
  // Otherwise only nodes whose mesh or node name equals this (all primitives of that mesh).
  std::string mesh;
  // Empty or "all": every animation, one after the other, each sampled from its own start
  // (ReadReport::clips says where each begins); otherwise the animation of that name, or of that
  // index ("0", "1", ...; a clip named "all" is chosen by its index).
  std::string animation;
  // Merge vertices split only by seams (same position in every frame within 1e-6 of the bounding
  // box diagonal, different UV/normal); ReadReport::vertex_map keeps file vertex -> merged vertex.
  // Triangles that collapse (two corners merged) are dropped, with a warning.
  bool weld = false;
};

struct ReadOptions {
  // PC2 only: the mesh file whose triangles (and vertex count) the cache uses. Empty means the
  // first of <stem>.obj, <stem>.off, <stem>.ply beside the cache that exists.
  std::filesystem::path connectivity;
  int max_frames = 0;  // read at most this many frames (the first ones); 0 = all
  int threads = 0;     // frame files parsed concurrently: 0 = one per hardware thread, 1 = serial
  IoProgressCallback progress;
  GltfReadOptions gltf;
};

// Non-fatal findings of a read, one sentence each, e.g.
// "frame 0 (x.obj): 752 faces with more than 3 corners were fan-triangulated into 1504 triangles".
// One animation clip of a glTF input within the sequence read from it.
struct ClipInfo {
  std::string name;         // the animation's name ("" when it has none)
  int animation = -1;       // its index in the file's animations
  double start_time = 0.0;  // seconds: frame first_frame + k is the clip at start_time + k / fps
  int first_frame = 0;
  int frame_count = 0;
};

struct ReadReport {
  std::vector<std::string> warnings;
  // glTF/GLB only: the clips in frame order; empty for a file without animation.
  std::vector<ClipInfo> clips;
  // glTF/GLB only: for every vertex of the file (scene order, primitive order), the sequence
  // vertex it became; the identity unless GltfReadOptions::weld merged vertices.
  std::vector<int32_t> vertex_map;
};

// The scene record of a glTF input (what it holds besides vertex motion) as a GLB, for the
// stream's scene chunk (StreamingEncodeOptions::scene in dmc/encoder.h), so that a decoder can
// write the input's scene back with the decoded motion (WriteOptions::scene). `options` and
// `report` are those of the ReadSequence call that read `input`, `stream_vertices` the vertex
// count of the sequence it gave. Kept: nodes (names, hierarchy, transforms, node animations),
// meshes with their primitives' indices and other attributes (TEXCOORD_n, COLOR_n, ...),
// materials, textures, samplers, images in the file, cameras, the asset (copyright, generator),
// extras. Taken out: the imported primitives' POSITION, NORMAL, TANGENT, JOINTS_n, WEIGHTS_n and
// morph targets, skins, and the weights animations of imported meshes: the stream carries the
// motion they made. The record's root extras "dmc_scene" maps the stream back (bitstream spec,
// Appendix C). Empty for a dmc "frames" export, which holds nothing but frames.
StatusOr<std::vector<uint8_t>> BuildGltfScene(const std::filesystem::path& input,
                                              const ReadOptions& options, const ReadReport& report,
                                              int stream_vertices);

// The clips a scene record lists (a stream's scene, dmc::DecodeScene), in frame order; empty for
// a scene without animation. kParseError when `scene` is not a dmc scene record.
StatusOr<std::vector<ClipInfo>> SceneClips(std::span<const uint8_t> scene);

// The extension of `path` in lower case, with its dot (".pc2"; "" when there is none): how every
// reader and writer of dmc, and the CLI, recognise a file's kind.
std::string LowercaseExtension(const std::filesystem::path& path);

// Reads a mesh sequence. INPUT is one of:
//  - a directory holding per-frame .obj, .off or .ply files (one format; other files are ignored),
//    taken in natural order (2.obj before 10.obj); hidden files (".name") are skipped;
//  - a glob pattern whose last component has wildcards (* ? [...]), e.g. "dir/mesh_*.obj",
//    matched files taken in natural order;
//  - a single .obj/.off/.ply file (a 1-frame sequence);
//  - a .pc2 point cache, with triangles from options.connectivity (see ReadOptions);
//  - a .glb/.gltf file: its animation posed at options.gltf.frame_rate (skins, node animation,
//    morph targets; see GltfReadOptions); a file without animation gives one frame.
// Extensions are matched case-insensitively. Every frame must have frame 0's vertex count and
// triangle list (kMismatch otherwise). The result has passed ValidateSequence; its degenerate
// triangle warning, if any, is added to `report`. `name` is the input's stem (or directory name).
// frame_rate comes from a "dmc frame_rate <fps>" comment that WriteSequence puts in frame files
// (0 when absent); for PC2 see ReadPc2's note in the implementation: the cache's sampleRate is the
// spacing of samples in scene frames, so fps = (connectivity file's frame_rate) / sampleRate when
// the former is known, else 0.
StatusOr<MeshSequence> ReadSequence(const std::filesystem::path& input,
                                    const ReadOptions& options = {}, ReadReport* report = nullptr);

struct WriteOptions {
  std::string frame_format = "obj";  // obj | off | ply: per-frame file format for directories
  // .glb only: how the frames are animated.
  //  - "basis": frame 0 plus a few morph targets per block of frames, each moving one coordinate
  //    axis, with per-frame weights (a decoded stream is low rank in time, so the file grows with
  //    the rank rather than the frame count); positions within one grid step of the sequence's
  //    (half a step on average), normals within 4/127; quantised encodings only;
  //  - "morph": frame 0 plus one morph target per later frame, weights animation;
  //  - "frames": one mesh per frame, stepped (not with a scene);
  //  - "auto": with a scene, basis when compact and morph otherwise; without one, the smallest of
  //    morph, frames and (compact only) basis. Quantized files are for importers without a meshopt
  //    decoder, Blender's above all, whose importer clamps shape-key values to [0, 1]: basis
  //    weights are any real, so Blender plays only the morph layout right.
  std::string glb_layout = "auto";
  // .glb basis layout only: sequence frames where the motion's low-rank structure restarts (a
  // stream's segment starts, which `dmc decode` passes): each begins a new block of targets.
  std::vector<int> motion_blocks;
  // .glb only: how vertex data is stored.
  //  - "compact": KHR_mesh_quantization (positions on a grid of 1/32766 of the largest
  //    bounding-box extent over all frames, so within half of that; 8-bit normals) and
  //    EXT_meshopt_compression buffers, both required by the file;
  //  - "quantized": the same without EXT_meshopt_compression (for readers without a meshopt
  //    decoder, e.g. Blender's importer);
  //  - "float": plain float32 positions and normals, positions exact.
  std::string glb_encoding = "compact";
  // .glb only: a scene record (BuildGltfScene; a stream's scene, dmc::DecodeScene) the sequence
  // belongs in: the GLB is then the recorded scene (nodes, materials, textures, UVs, node
  // animations, asset) with the sequence's motion, one animation per recorded clip, in the
  // "morph" layout. Empty: the motion alone.
  std::vector<uint8_t> scene;
  std::string clip;  // with a scene: only the clip of this name (its frames and animation)
  IoProgressCallback progress;
};

// Writes a sequence (which must pass ValidateSequence). OUTPUT is interpreted by its extension:
//  - .pc2: the point cache (startFrame 0, sampleRate 1: one sample per frame) plus <stem>.obj
//    beside it holding the triangles and frame 0;
//  - .obj/.off/.ply: a single mesh file; the sequence must have exactly one frame;
//  - .glb: a binary glTF 2.0 file playing the frames at frame_rate (30 fps when 0), with normals,
//    stored as options.glb_encoding says;
//  - a path without an extension, ending in a separator, or naming an existing directory: a
//    directory of frame_0000.<fmt>, frame_0001.<fmt>, ... (at least 4 digits,
//    more when there are 10000 frames or more). An existing directory is replaced only when it
//    holds nothing but frame files (so a typo cannot wipe an unrelated folder).
// Any other extension (.fbx, .usdz, ...) is kInvalidArgument, naming the accepted ones.
// frame_rate > 0 is recorded as a "dmc frame_rate" comment so ReadSequence gets it back. The
// output's parent directory must exist (kIoError otherwise); the output directory itself is
// created.
Status WriteSequence(const MeshSequence& sequence, const std::filesystem::path& output,
                     const WriteOptions& options = {});
// The check of WriteSequence's output path alone, before anything is decoded or read: Ok for
// the kinds above, kInvalidArgument for an empty path or an unknown extension.
Status CheckSequenceOutputPath(const std::filesystem::path& output);

// The connectivity mesh of a PC2 cache when none is named (ReadOptions::connectivity empty): the
// first of <stem>.obj, <stem>.off, <stem>.ply beside it that exists, the rule ReadSequence and
// the streaming encoder follow; kIoError suggesting --connectivity when none does.
StatusOr<std::filesystem::path> FindPc2Connectivity(const std::filesystem::path& cache);

// Natural order of file names: runs of digits compare by numeric value ("2" < "10"), everything
// else byte by byte; names that only differ in leading zeros ("007" vs "7") fall back to plain
// byte order. A strict total order on distinct strings, usable with std::sort.
bool NaturalLess(std::string_view a, std::string_view b);

// Writes `bytes` to `path` through a temporary file in the same directory that is flushed to disk
// and renamed over `path`. On any failure the temporary file is removed and an existing `path` is
// left untouched (kIoError naming the path and the system's reason).
Status WriteFileAtomically(const std::filesystem::path& path, std::span<const uint8_t> bytes);

// Temporary files. Every writer of dmc (WriteSequence, WriteFileAtomically, the streaming encoder
// and DecodeToPc2) writes its output under a hidden name beside it,
// ".<name>.dmc-tmp-<pid>-<n>" (a directory of frame files for directory outputs), and renames it
// into place when complete; every error path removes it. A process stopped by a signal cannot,
// unless it asks, with one of these two. The library itself installs no signal handler.

// Removes the temporaries of every write in progress in this process, and renames an output
// directory that was moved aside while being replaced back into place. Async-signal-safe (only
// system calls on paths recorded beforehand): meant for a signal handler, after which the process
// should end; writes still in progress then fail. Up to 64 temporaries alive at once are tracked
// (a process writes one to three per output); one beyond that, or with a path of PATH_MAX bytes or
// more, is still removed on error paths but not by this.
void RemoveTemporaryFiles() noexcept;

// Installs handlers for SIGINT, SIGTERM and SIGHUP that call RemoveTemporaryFiles, then restore
// the disposition the signal had before and raise it again, so the process ends as it would have
// without them (exit status: killed by that signal) or the previous handler runs. A signal that
// was ignored (SIG_IGN, as under nohup) stays ignored. Installing again does nothing. For a
// program with handlers of its own: call RemoveTemporaryFiles from them instead. kInternal when
// the system refuses (sigaction).
Status InstallTemporaryFileCleanupOnSignals();

}  // namespace dmc
