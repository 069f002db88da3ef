// dmc.read_sequence, dmc.write_sequence, dmc.synth: mesh sequences from and to files, and the
// built-in synthetic animations.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "arrays.h"
#include "bindings.h"
#include "dmc/io.h"
#include "dmc/synth.h"
#include "errors.h"

namespace dmc::python {
namespace {

py::object ReadSequenceBinding(const std::filesystem::path& path,
                               const std::optional<std::filesystem::path>& connectivity,
                               int max_frames, int threads, double gltf_fps,
                               const std::string& gltf_mesh, const std::string& gltf_animation,
                               bool gltf_weld, bool metadata) {
  if (max_frames < 0) ThrowInvalidArgument("max_frames must be >= 0 (0 = all)");
  if (threads < 0) ThrowInvalidArgument("threads must be >= 0 (0 = one per hardware thread)");
  if (!(gltf_fps >= 0.0) || !std::isfinite(gltf_fps)) {
    ThrowInvalidArgument("gltf_fps must be a finite number >= 0 (0 = the file's rate, else 30)");
  }
  ReadOptions options;
  if (connectivity) options.connectivity = *connectivity;
  options.max_frames = max_frames;
  options.threads = threads;
  options.gltf.frame_rate = gltf_fps;
  options.gltf.mesh = gltf_mesh;
  options.gltf.animation = gltf_animation;
  options.gltf.weld = gltf_weld;
  ReadReport report;
  std::optional<MeshSequence> sequence;
  {
    py::gil_scoped_release release;
    sequence = ValueOrThrow(ReadSequence(path, options, &report));
  }
  std::string name = sequence->name;
  const double frame_rate = sequence->frame_rate;
  py::tuple arrays = SequenceToArrays(std::move(*sequence));
  if (!metadata) return arrays;
  py::dict info;
  info["name"] = name;
  info["frame_rate"] = frame_rate > 0.0 ? py::object(py::float_(frame_rate)) : py::none();
  info["warnings"] = report.warnings;
  info["vertex_map"] = report.vertex_map;
  return py::make_tuple(arrays[0], arrays[1], info);
}

void WriteSequenceBinding(const std::filesystem::path& path, const py::handle& frames,
                          const py::handle& faces, const std::string& frame_format,
                          double frame_rate, const std::string& name) {
  if (frame_format != "obj" && frame_format != "off" && frame_format != "ply") {
    ThrowInvalidArgument("frame_format must be \"obj\", \"off\" or \"ply\", got \"" + frame_format +
                         "\"");
  }
  MeshSequence sequence = SequenceFromArrays(frames, faces);
  sequence.frame_rate = frame_rate;
  sequence.name = name;
  WriteOptions options;
  options.frame_format = frame_format;
  py::gil_scoped_release release;
  ValidateOrThrow(sequence);
  ThrowIfError(WriteSequence(sequence, path, options));
}

py::tuple SynthBinding(const std::string& name, int frames, int resolution, uint64_t seed) {
  SynthOptions options;
  options.frames = frames;
  options.resolution = resolution;
  options.seed = seed;
  std::optional<MeshSequence> sequence;
  {
    py::gil_scoped_release release;
    sequence = ValueOrThrow(Synthesize(name, options));
  }
  return SequenceToArrays(std::move(*sequence));
}

constexpr const char* kReadDoc =
    R"(read_sequence(path, *, connectivity=None, max_frames=0, threads=0, gltf_fps=0.0, gltf_mesh="", gltf_animation="", gltf_weld=False, metadata=False) -> (frames, faces)

Reads a mesh sequence, exactly as the dmc CLI reads its inputs. `path` (str or os.PathLike) is
  - a directory of per-frame .obj, .off or .ply files, taken in natural order (2.obj before 10.obj);
  - a glob such as "dir/mesh_*.obj";
  - one .obj/.off/.ply file (one frame);
  - a .pc2 point cache, with triangles from `connectivity` (default: <stem>.obj/.off/.ply beside it);
  - a .glb/.gltf animation (skins, node animation, morph targets), posed at `gltf_fps`.
Vertex and triangle order are kept as in the files; faces with more than 3 corners are
fan-triangulated (with a warning).

Args:
    max_frames: read at most this many (first) frames; 0 = all.
    threads: frame files parsed concurrently; 0 = one per hardware thread, 1 = serial.
    gltf_fps: glTF only: sampling rate; 0 = the rate a dmc export recorded, else 30
        (frames = floor(clip length * fps) + 1), as `dmc ... --gltf-fps`.
    gltf_mesh: glTF only: only the mesh or node of this name (all its primitives); "" = all.
    gltf_animation: glTF only: animation name or index ("0", "1", ...); "" = the first.
    gltf_weld: glTF only: merge vertices split only by UV/normal seams.
    metadata: also return a dict with name (the input's stem), frame_rate (None when unknown),
        warnings (list of str) and vertex_map (glTF: for every file vertex the sequence vertex it
        became; empty otherwise).

Returns:
    (frames float32 (F, V, 3), faces int32 (T, 3)), or (frames, faces, metadata).

Raises:
    dmc.Error: IO_ERROR, PARSE_ERROR ("<path>:<line>: ..."), MISMATCH (a frame differs from frame
        0), INVALID_SEQUENCE.
)";

constexpr const char* kWriteDoc =
    R"(write_sequence(path, frames, faces, *, frame_format="obj", frame_rate=0.0, name="")

Writes a mesh sequence; coordinates are written so that reading them back is bit-exact. `path`'s
extension decides the format:
  - .pc2: a point cache plus <stem>.obj beside it (triangles and frame 0);
  - .obj/.off/.ply: one mesh file (the sequence must have exactly one frame);
  - .glb: a glTF animation;
  - a path without an extension, ending in '/', or an existing directory: a directory of
    frame_0000.<frame_format>, ... (an existing directory is only replaced when it holds nothing
    but frame files); any other extension raises dmc.Error (INVALID_ARGUMENT).
The write is atomic: a failure never leaves a half-written output.

Args:
    frames: float32 array (F, V, 3) or (V, 3).
    faces: int32 array (T, 3).
    frame_format: obj, off or ply: per-frame file format of a directory.
    frame_rate: > 0 is recorded so that read_sequence(..., metadata=True) returns it.
    name: the sequence's name (informational).

Raises:
    dmc.Error: IO_ERROR (parent directory missing, not writable), INVALID_SEQUENCE,
        INVALID_ARGUMENT.
)";

constexpr const char* kSynthDoc =
    R"(synth(name, *, frames=60, resolution=2000, seed=1) -> (frames, faces)

One of the built-in deterministic animations (the same as `dmc synth`): "twist" (a twisting,
bending tube), "cloth" (a waving flag), "walker" (a six-part walking figure), "blob" (a sphere
deformed by moving spherical harmonics). Frame f is the pose at f / 30 s.

Args:
    name: generator name (see dmc.synth_names()).
    frames: number of frames (1 .. 100000).
    resolution: approximate vertex count (100 .. 1000000).
    seed: selects the motion parameters (any non-negative integer).

Returns:
    (frames float32 (F, V, 3), faces int32 (T, 3)).

Raises:
    dmc.Error: NOT_FOUND (unknown name), INVALID_ARGUMENT (frames or resolution out of range).
)";

}  // namespace

void RegisterIo(py::module_& module) {
  module.def("read_sequence", &ReadSequenceBinding, WithTextSignature(kReadDoc).c_str(),
             py::arg("path"), py::kw_only(), py::arg("connectivity") = py::none(),
             py::arg("max_frames") = 0, py::arg("threads") = 0, py::arg("gltf_fps") = 0.0,
             py::arg("gltf_mesh") = "", py::arg("gltf_animation") = "",
             py::arg("gltf_weld") = false, py::arg("metadata") = false);
  module.def("write_sequence", &WriteSequenceBinding, WithTextSignature(kWriteDoc).c_str(),
             py::arg("path"), py::arg("frames"), py::arg("faces"), py::kw_only(),
             py::arg("frame_format") = "obj", py::arg("frame_rate") = 0.0, py::arg("name") = "");
  const SynthOptions defaults;
  module.def("synth", &SynthBinding,
             WithTextSignature("synth(name, *, frames=" + Repr(defaults.frames) + ", resolution=" +
                               Repr(defaults.resolution) + ", seed=" + Repr(defaults.seed) +
                               ") -> (frames, faces)" + AfterFirstLine(kSynthDoc))
                 .c_str(),
             py::arg("name"), py::kw_only(), py::arg("frames") = defaults.frames,
             py::arg("resolution") = defaults.resolution, py::arg("seed") = defaults.seed);
  module.def(
      "synth_names",
      [] {
        py::list names;
        for (const std::string_view name : SynthNames()) names.append(std::string(name));
        return names;
      },
      WithTextSignature(
          "synth_names() -> list[str]\n\nNames of the built-in animations dmc.synth() accepts.")
          .c_str());
}

}  // namespace dmc::python
