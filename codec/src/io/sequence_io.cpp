// ReadSequence / WriteSequence: resolving the input (directory, glob, file, PC2), reading frames
// and checking them against frame 0, and writing files or directories atomically.
#include <fnmatch.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>

#include "core/allocation_guard.h"
#include "dmc/io.h"
#include "io/file_ops.h"
#include "io/gltf_format.h"
#include "io/mesh_formats.h"
#include "io/pc2_format.h"
#include "io/pc2_stream.h"

namespace dmc {

bool NaturalLess(std::string_view a, std::string_view b) {
  auto is_digit = [](char c) { return c >= '0' && c <= '9'; };
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      size_t a_end = i, b_end = j;
      while (a_end < a.size() && is_digit(a[a_end])) ++a_end;
      while (b_end < b.size() && is_digit(b[b_end])) ++b_end;
      // Leading zeros do not change the value; keep at least one digit.
      while (i + 1 < a_end && a[i] == '0') ++i;
      while (j + 1 < b_end && b[j] == '0') ++j;
      const size_t a_digits = a_end - i, b_digits = b_end - j;
      if (a_digits != b_digits) return a_digits < b_digits;
      const int order = a.substr(i, a_digits).compare(b.substr(j, b_digits));
      if (order != 0) return order < 0;
      i = a_end;
      j = b_end;
    } else {
      if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
      ++i;
      ++j;
    }
  }
  const bool a_done = i == a.size(), b_done = j == b.size();
  if (a_done != b_done) return a_done;
  return a < b;  // naturally equal ("007" vs "7"): byte order keeps the order total
}

namespace {

using io_internal::MeshFileData;
using io_internal::MeshFormat;

std::string FrameLabel(int frame, const std::filesystem::path& path) {
  return "frame " + std::to_string(frame) + " (" + path.string() + ")";
}

// "dir/" has no file name; its name is the last real component.
std::filesystem::path WithoutTrailingSeparator(const std::filesystem::path& path) {
  return path.has_filename() ? path : path.parent_path();
}

// The name of a directory as a user would say it: "samba" for "data/samba/", "." or "".
std::string DirectoryName(const std::filesystem::path& directory) {
  std::error_code error;
  const std::filesystem::path absolute =
      std::filesystem::absolute(directory.empty() ? "." : directory, error);
  if (error) return directory.string();
  return WithoutTrailingSeparator(absolute.lexically_normal()).filename().string();
}

// Regular files of `directory` whose names satisfy `keep`, in natural order.
template <typename Keep>
StatusOr<std::vector<std::filesystem::path>> ListFiles(const std::filesystem::path& directory,
                                                       Keep keep) {
  std::error_code error;
  std::filesystem::directory_iterator it(directory, error);
  if (error) return IoError("cannot list " + directory.string() + ": " + error.message());
  std::vector<std::filesystem::path> files;
  for (; it != std::filesystem::directory_iterator(); it.increment(error)) {
    if (error) return IoError("cannot list " + directory.string() + ": " + error.message());
    std::error_code type_error;
    if (!it->is_regular_file(type_error)) continue;
    const std::string name = it->path().filename().string();
    if (keep(name)) files.push_back(directory / name);
  }
  if (error) return IoError("cannot list " + directory.string() + ": " + error.message());
  std::sort(files.begin(), files.end(), [](const auto& x, const auto& y) {
    return NaturalLess(x.filename().string(), y.filename().string());
  });
  return files;
}

// Frame files must share one format: a directory with both a.obj and a.ply is ambiguous.
Status CheckOneFormat(const std::vector<std::filesystem::path>& files, const std::string& where) {
  for (const auto& file : files) {
    if (io_internal::MeshFormatFromPath(file) != io_internal::MeshFormatFromPath(files.front())) {
      return InvalidArgumentError(
          where + " mixes mesh formats (" + files.front().filename().string() + ", " +
          file.filename().string() + "); select one with a pattern such as dir/*.obj");
    }
  }
  return Status::Ok();
}

StatusOr<std::vector<std::filesystem::path>> FramesOfDirectory(const std::filesystem::path& dir) {
  // Hidden files (".name") are skipped: editors' and other tools' droppings, not frames.
  DMC_ASSIGN_OR_RETURN(auto files, ListFiles(dir, [](const std::string& name) {
                         return name.front() != '.' &&
                                io_internal::MeshFormatFromPath(name).has_value();
                       }));
  if (files.empty()) {
    return InvalidSequenceError(dir.string() + " holds no .obj, .off or .ply frame files");
  }
  DMC_RETURN_IF_ERROR(CheckOneFormat(files, dir.string()));
  return files;
}

StatusOr<std::vector<std::filesystem::path>> FramesOfPattern(const std::filesystem::path& input) {
  const std::filesystem::path parent = input.parent_path();
  if (parent.string().find_first_of("*?[") != std::string::npos) {
    return InvalidArgumentError(input.string() +
                                ": wildcards are only supported in the last path component");
  }
  const std::filesystem::path directory = parent.empty() ? "." : parent;
  const std::string pattern = input.filename().string();
  DMC_ASSIGN_OR_RETURN(auto matches, ListFiles(directory, [&](const std::string& name) {
                         return ::fnmatch(pattern.c_str(), name.c_str(), FNM_PERIOD) == 0;
                       }));
  if (matches.empty()) return IoError("no file matches " + input.string());
  for (const auto& file : matches) {
    if (!io_internal::MeshFormatFromPath(file)) {
      return UnsupportedError(file.string() + " (matched by " + input.string() +
                              ") is not an .obj, .off or .ply file");
    }
  }
  DMC_RETURN_IF_ERROR(CheckOneFormat(matches, input.string()));
  // Written as frames/f_*.obj, the files keep their directory prefix as given.
  if (parent.empty()) {
    for (auto& file : matches) file = file.filename();
  }
  return matches;
}

Status CheckFinite(const float* positions, int vertex_count, const std::string& label) {
  for (int v = 0; v < vertex_count; ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(positions[3 * v + axis])) {
        return InvalidSequenceError(label + ", vertex " + std::to_string(v) + ": coordinate " +
                                    "xyz"[axis] + " is not finite");
      }
    }
  }
  return Status::Ok();
}

// A later frame must repeat frame 0's vertex count and triangle list exactly.
Status CheckAgainstFirstFrame(const MeshFileData& mesh, const MeshFileData& first,
                              const std::string& label) {
  if (mesh.vertex_count() != first.vertex_count()) {
    return MismatchError(label + ": " + std::to_string(mesh.vertex_count()) +
                         " vertices, expected " + std::to_string(first.vertex_count()) +
                         " (as in frame 0)");
  }
  if (mesh.triangle_count() != first.triangle_count()) {
    return MismatchError(label + ": " + std::to_string(mesh.triangle_count()) +
                         " triangles, expected " + std::to_string(first.triangle_count()) +
                         " (as in frame 0)");
  }
  if (mesh.triangles != first.triangles) {
    const auto [here, there] =
        std::mismatch(mesh.triangles.begin(), mesh.triangles.end(), first.triangles.begin());
    const size_t t = static_cast<size_t>(here - mesh.triangles.begin()) / 3;
    auto corners = [t](const std::vector<int32_t>& tris) {
      return "(" + std::to_string(tris[3 * t]) + ", " + std::to_string(tris[3 * t + 1]) + ", " +
             std::to_string(tris[3 * t + 2]) + ")";
    };
    return MismatchError(label + ": triangle " + std::to_string(t) + " is " +
                         corners(mesh.triangles) + ", frame 0 has " + corners(first.triangles));
  }
  return Status::Ok();
}

Triangles ToTriangles(const std::vector<int32_t>& flat) {
  Triangles triangles(static_cast<Eigen::Index>(flat.size() / 3), 3);
  std::copy(flat.begin(), flat.end(), triangles.data());
  return triangles;
}

void ReportMeshNotes(const MeshFileData& mesh, const std::string& label,
                     std::vector<std::string>& warnings) {
  if (mesh.polygons_triangulated > 0) {
    warnings.push_back(label + ": " + std::to_string(mesh.polygons_triangulated) +
                       " face(s) with more than 3 corners fan-triangulated (" +
                       std::to_string(mesh.triangle_count()) + " triangles in all)");
  }
  for (const std::string& note : mesh.notes) warnings.push_back(label + ": " + note);
}

StatusOr<MeshSequence> ReadFrameFiles(const std::vector<std::filesystem::path>& files,
                                      const ReadOptions& options,
                                      std::vector<std::string>& warnings) {
  const int frame_count = static_cast<int>(files.size());
  StatusOr<MeshFileData> first_read = io_internal::ReadMeshFile(files[0]);
  if (!first_read.ok()) return first_read.status();
  const MeshFileData first = std::move(first_read).value();
  const std::string first_label = FrameLabel(0, files[0]);
  DMC_RETURN_IF_ERROR(CheckFinite(first.positions.data(), first.vertex_count(), first_label));
  ReportMeshNotes(first, first_label, warnings);

  MeshSequence sequence(first.vertex_count(), ToTriangles(first.triangles), frame_count);
  sequence.frame_rate = first.frame_rate;
  std::copy(first.positions.begin(), first.positions.end(), sequence.data());

  // Frames 1.. are parsed concurrently (parsing is CPU-bound: ~6 ms per 10k-vertex OBJ frame).
  // Workers claim frames in increasing order and stop claiming past the first failure, so every
  // frame before it is read and the error reported is always the lowest failing frame's.
  std::vector<Status> results(static_cast<size_t>(frame_count));
  std::atomic<int> next_frame{1};
  std::atomic<int> first_failure{frame_count};
  std::mutex progress_mutex;
  int frames_done = 1;
  if (options.progress) options.progress(1, frame_count);
  auto worker = [&] {
    for (int f = next_frame++; f < frame_count && f < first_failure.load(); f = next_frame++) {
      Status status = [&]() -> Status {
        DMC_ASSIGN_OR_RETURN(const MeshFileData mesh, io_internal::ReadMeshFile(files[f]));
        const std::string label = FrameLabel(f, files[f]);
        DMC_RETURN_IF_ERROR(CheckAgainstFirstFrame(mesh, first, label));
        DMC_RETURN_IF_ERROR(CheckFinite(mesh.positions.data(), mesh.vertex_count(), label));
        std::copy(mesh.positions.begin(), mesh.positions.end(), sequence.frame(f).data());
        return Status::Ok();
      }();
      if (!status.ok()) {
        int current = first_failure.load();
        while (f < current && !first_failure.compare_exchange_weak(current, f)) {
        }
        results[static_cast<size_t>(f)] = std::move(status);
      } else if (options.progress) {
        const std::lock_guard<std::mutex> lock(progress_mutex);
        options.progress(++frames_done, frame_count);
      }
    }
  };
  if (frame_count > 1) {
    const int wanted = options.threads > 0 ? options.threads
                                           : static_cast<int>(std::thread::hardware_concurrency());
    const int thread_count = std::clamp(wanted, 1, frame_count - 1);
    std::vector<std::jthread> helpers;
    try {
      for (int t = 1; t < thread_count; ++t) helpers.emplace_back(worker);
    } catch (const std::system_error&) {
      // No more threads available: the ones started (and this one) still read every frame.
    }
    worker();
  }  // the helpers join here
  if (first_failure.load() < frame_count) {
    return results[static_cast<size_t>(first_failure.load())];
  }
  return sequence;
}

StatusOr<MeshSequence> ReadPc2(const std::filesystem::path& cache, const ReadOptions& options,
                               std::vector<std::string>& warnings) {
  DMC_ASSIGN_OR_RETURN(const io_internal::Pc2FrameReader reader,
                       io_internal::Pc2FrameReader::Open(cache));
  const io_internal::Pc2Header& header = reader.header();
  std::filesystem::path connectivity = options.connectivity;
  if (connectivity.empty()) {
    DMC_ASSIGN_OR_RETURN(connectivity, FindPc2Connectivity(cache));
  }
  DMC_ASSIGN_OR_RETURN(const MeshFileData mesh, io_internal::ReadMeshFile(connectivity));
  if (mesh.vertex_count() != header.point_count) {
    return MismatchError(cache.string() + ": " + std::to_string(header.point_count) +
                         " points, but the connectivity mesh " + connectivity.string() + " has " +
                         std::to_string(mesh.vertex_count()) + " vertices");
  }
  ReportMeshNotes(mesh, "connectivity (" + connectivity.string() + ")", warnings);
  int frame_count = header.sample_count;
  if (options.max_frames > 0) frame_count = std::min(frame_count, options.max_frames);
  MeshSequence sequence(header.point_count, ToTriangles(mesh.triangles), frame_count);
  DMC_RETURN_IF_ERROR(reader.ReadFrames(0, frame_count, sequence.data()));
  for (int f = 0; f < frame_count; ++f) {
    DMC_RETURN_IF_ERROR(
        CheckFinite(sequence.frame(f).data(), sequence.vertex_count(), FrameLabel(f, cache)));
  }
  // sampleRate is the spacing of samples in scene frames, so seconds need the scene's frame rate,
  // which PC2 does not store; the connectivity mesh carries it when dmc wrote the pair.
  if (mesh.frame_rate > 0.0 && std::isfinite(header.sample_rate) && header.sample_rate > 0.0f) {
    sequence.frame_rate = mesh.frame_rate / static_cast<double>(header.sample_rate);
  }
  if (options.progress) options.progress(frame_count, frame_count);
  return sequence;
}

}  // namespace

std::string LowercaseExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

namespace {

StatusOr<MeshSequence> ReadSequenceUnguarded(const std::filesystem::path& input,
                                             const ReadOptions& options, ReadReport* report) {
  if (options.max_frames < 0) {
    return InvalidArgumentError("max_frames must be 0 (all) or positive, got " +
                                std::to_string(options.max_frames));
  }
  if (options.threads < 0) {
    return InvalidArgumentError("threads must be 0 (automatic) or positive, got " +
                                std::to_string(options.threads));
  }
  if (input.empty()) return InvalidArgumentError("no input path given");
  std::vector<std::string> warnings;
  std::error_code error;
  const auto status = std::filesystem::status(input, error);
  std::string name;
  StatusOr<MeshSequence> sequence = InternalError("unreachable");

  if (std::filesystem::is_directory(status)) {
    DMC_ASSIGN_OR_RETURN(auto files, FramesOfDirectory(input));
    if (options.max_frames > 0 && static_cast<int>(files.size()) > options.max_frames) {
      files.resize(static_cast<size_t>(options.max_frames));
    }
    name = DirectoryName(input);
    sequence = ReadFrameFiles(files, options, warnings);
  } else if (!std::filesystem::exists(status) &&
             input.filename().string().find_first_of("*?[") != std::string::npos) {
    DMC_ASSIGN_OR_RETURN(auto files, FramesOfPattern(input));
    if (options.max_frames > 0 && static_cast<int>(files.size()) > options.max_frames) {
      files.resize(static_cast<size_t>(options.max_frames));
    }
    name = DirectoryName(input.parent_path());
    sequence = ReadFrameFiles(files, options, warnings);
  } else if (!std::filesystem::exists(status)) {
    return IoError("cannot open " + input.string() + ": no such file or directory");
  } else if (LowercaseExtension(input) == ".pc2") {
    name = input.stem().string();
    sequence = ReadPc2(input, options, warnings);
  } else if (io_internal::MeshFormatFromPath(input)) {
    name = input.stem().string();
    sequence = ReadFrameFiles({input}, options, warnings);
  } else if (const std::string ext = LowercaseExtension(input); ext == ".glb" || ext == ".gltf") {
    name = input.stem().string();
    auto imported = io_internal::ReadGltf(input, options.gltf, options.max_frames);
    if (!imported.ok()) return imported.status();
    warnings.insert(warnings.end(), imported->warnings.begin(), imported->warnings.end());
    if (report != nullptr) {
      report->vertex_map = std::move(imported->vertex_map);
      report->clips = std::move(imported->clips);
    }
    sequence = std::move(imported->sequence);
    if (options.progress) options.progress(sequence->frame_count(), sequence->frame_count());
  } else {
    return UnsupportedError(input.string() +
                            ": unknown input format (expected a directory, a glob pattern, "
                            ".obj, .off, .ply, .pc2, .glb or .gltf)");
  }
  if (!sequence.ok()) return sequence.status();
  sequence->name = name;
  ValidationReport validation;
  DMC_RETURN_IF_ERROR(ValidateSequence(*sequence, &validation).WithContext(input.string()));
  for (const std::string& warning : validation.warnings) warnings.push_back(warning);
  if (report != nullptr) {
    report->warnings.insert(report->warnings.end(), warnings.begin(), warnings.end());
  }
  return sequence;
}

}  // namespace

StatusOr<MeshSequence> ReadSequence(const std::filesystem::path& input, const ReadOptions& options,
                                    ReadReport* report) {
  return core_internal::GuardAllocation(
      "reading " + input.string(), [&] { return ReadSequenceUnguarded(input, options, report); });
}

namespace {

std::span<const uint8_t> AsBytes(const fmt::memory_buffer& buffer) {
  return {reinterpret_cast<const uint8_t*>(buffer.data()), buffer.size()};
}
std::span<const uint8_t> AsBytes(const std::string& text) {
  return {reinterpret_cast<const uint8_t*>(text.data()), text.size()};
}

fmt::memory_buffer FrameText(const MeshSequence& sequence, int frame, MeshFormat format) {
  fmt::memory_buffer out;
  const auto positions = sequence.frame(frame);
  io_internal::AppendMeshText(
      format, {positions.data(), static_cast<size_t>(positions.size())},
      {sequence.triangles().data(), static_cast<size_t>(sequence.triangles().size())},
      sequence.frame_rate, out);
  return out;
}

// "frame_0012.obj" and the like: the only files an existing output directory may hold.
bool IsFrameFileName(const std::string& name) {
  constexpr std::string_view kPrefix = "frame_";
  if (name.compare(0, kPrefix.size(), kPrefix) != 0) return false;
  const size_t dot = name.rfind('.');
  if (dot == std::string::npos || dot == kPrefix.size()) return false;
  for (size_t i = kPrefix.size(); i < dot; ++i) {
    if (name[i] < '0' || name[i] > '9') return false;
  }
  return io_internal::MeshFormatFromName(std::string_view(name).substr(dot + 1)).has_value();
}

Status CheckReplaceableDirectory(const std::filesystem::path& directory) {
  std::error_code error;
  for (std::filesystem::directory_iterator it(directory, error), end; !error && it != end;
       it.increment(error)) {
    const std::string name = it->path().filename().string();
    std::error_code type_error;
    if (!it->is_regular_file(type_error) || !IsFrameFileName(name)) {
      return InvalidArgumentError("refusing to replace " + directory.string() + ": it holds " +
                                  name + ", which is not a frame_NNNN.<obj|off|ply> file");
    }
  }
  if (error) return IoError("cannot list " + directory.string() + ": " + error.message());
  return Status::Ok();
}

Status WriteFrameDirectory(const MeshSequence& sequence, const std::filesystem::path& output,
                           MeshFormat format, const WriteOptions& options) {
  std::error_code error;
  const auto existing = std::filesystem::status(output, error);
  const bool replacing = std::filesystem::exists(existing);
  if (replacing && !std::filesystem::is_directory(existing)) {
    return InvalidArgumentError(output.string() +
                                " exists and is not a directory (frames are written to a "
                                "directory unless the output ends in .obj, .off, .ply or .pc2)");
  }
  if (replacing) DMC_RETURN_IF_ERROR(CheckReplaceableDirectory(output));

  using io_internal::TemporaryPath;
  TemporaryPath staging_path(output, TemporaryPath::Kind::kDirectory);
  const std::filesystem::path& staging = staging_path.path();
  if (::mkdir(staging.c_str(), 0777) != 0) {
    const int mkdir_error = errno;
    staging_path.Release();  // not created by this call
    return io_internal::IoErrorFromErrno("cannot create", staging, mkdir_error);
  }
  // Every return below that has not renamed the staging directory into place removes it
  // (~TemporaryPath), and puts a moved-aside old output back.
  const int frame_count = sequence.frame_count();
  const int digits = std::max<int>(4, static_cast<int>(std::to_string(frame_count - 1).size()));
  const std::string extension(io_internal::MeshFormatExtension(format));
  for (int f = 0; f < frame_count; ++f) {
    const std::filesystem::path file =
        staging / fmt::format("frame_{:0{}}.{}", f, digits, extension);
    // Per-frame fsync is skipped: the directory only becomes visible by the final rename.
    const Status written =
        io_internal::WriteNewFile(file, AsBytes(FrameText(sequence, f, format)), /*sync=*/false);
    if (!written.ok()) return written;
    if (options.progress) options.progress(f + 1, frame_count);
  }

  if (!replacing) {
    std::filesystem::rename(staging, output, error);
    if (error)
      return IoError("cannot rename " + staging.string() + " to " + output.string() + ": " +
                     error.message());
    staging_path.Release();
    return Status::Ok();
  }
  // Swap: old output aside, new one in, old one deleted. Until the new one is in, the old one is
  // put back by any failure or a signal (TemporaryPath::Kind::kMovedAside).
  TemporaryPath previous(output, TemporaryPath::Kind::kMovedAside);
  std::filesystem::rename(output, previous.path(), error);
  if (error)
    return IoError("cannot move the existing " + output.string() + " aside: " + error.message());
  std::filesystem::rename(staging, output, error);
  if (error)
    return IoError("cannot rename " + staging.string() + " to " + output.string() + ": " +
                   error.message());
  staging_path.Release();
  previous.RemoveInsteadOfRestoring();
  previous.Abandon();
  return Status::Ok();
}

Status WritePc2Pair(const MeshSequence& sequence, const std::filesystem::path& output,
                    const WriteOptions& options) {
  std::filesystem::path mesh_path = output;
  mesh_path.replace_extension(".obj");
  using io_internal::TemporaryPath;
  // Either temporary left unrenamed by a failure is removed by its destructor.
  TemporaryPath cache_staging(output, TemporaryPath::Kind::kFile);
  TemporaryPath mesh_staging(mesh_path, TemporaryPath::Kind::kFile);
  DMC_RETURN_IF_ERROR(io_internal::WriteNewFile(
      cache_staging.path(), AsBytes(io_internal::EncodePc2(sequence)), /*sync=*/true));
  DMC_RETURN_IF_ERROR(io_internal::WriteNewFile(
      mesh_staging.path(), AsBytes(FrameText(sequence, 0, MeshFormat::kObj)), /*sync=*/true));
  // Each file is replaced atomically; the mesh goes first so that a cache never appears next to
  // a stale mesh of another vertex count.
  DMC_RETURN_IF_ERROR(io_internal::RenameIntoPlace(mesh_staging.path(), mesh_path));
  mesh_staging.Release();
  DMC_RETURN_IF_ERROR(io_internal::RenameIntoPlace(cache_staging.path(), output));
  cache_staging.Release();
  if (options.progress) options.progress(sequence.frame_count(), sequence.frame_count());
  return Status::Ok();
}

}  // namespace

namespace {

Status WriteSequenceUnguarded(const MeshSequence& sequence,
                              const std::filesystem::path& output_path,
                              const WriteOptions& options) {
  const std::optional<MeshFormat> frame_format =
      io_internal::MeshFormatFromName(options.frame_format);
  if (!frame_format) {
    return InvalidArgumentError("unknown frame format '" + options.frame_format +
                                "' (expected obj, off or ply)");
  }
  if (output_path.empty()) return InvalidArgumentError("no output path given");
  DMC_RETURN_IF_ERROR(
      ValidateSequence(sequence).WithContext("cannot write " + output_path.string()));
  const std::filesystem::path output = WithoutTrailingSeparator(output_path);
  DMC_RETURN_IF_ERROR(io_internal::CheckParentDirectory(output));
  const std::string extension = LowercaseExtension(output);

  if (extension == ".pc2") return WritePc2Pair(sequence, output, options);
  if (extension == ".glb") {
    io_internal::GlbLayout layout = io_internal::GlbLayout::kAuto;
    if (options.glb_layout == "basis") {
      layout = io_internal::GlbLayout::kBasis;
    } else if (options.glb_layout == "morph") {
      layout = io_internal::GlbLayout::kMorph;
    } else if (options.glb_layout == "frames") {
      layout = io_internal::GlbLayout::kFrames;
    } else if (options.glb_layout != "auto") {
      return InvalidArgumentError("unknown GLB layout '" + options.glb_layout +
                                  "' (expected auto, basis, morph or frames)");
    }
    io_internal::GlbEncoding encoding = io_internal::GlbEncoding::kCompact;
    if (options.glb_encoding == "quantized") {
      encoding = io_internal::GlbEncoding::kQuantized;
    } else if (options.glb_encoding == "float") {
      encoding = io_internal::GlbEncoding::kFloat;
    } else if (options.glb_encoding != "compact") {
      return InvalidArgumentError("unknown GLB encoding '" + options.glb_encoding +
                                  "' (expected compact, quantized or float)");
    }
    if (!options.clip.empty() && options.scene.empty()) {
      return InvalidArgumentError("a clip can be chosen only with a scene (the stream has none)");
    }
    DMC_ASSIGN_OR_RETURN(
        const std::vector<uint8_t> glb,
        options.scene.empty()
            ? io_internal::EncodeGlb(sequence, layout, encoding, options.motion_blocks)
            : io_internal::EncodeSceneGlb(sequence, options.scene, layout, encoding, options.clip,
                                          options.motion_blocks));
    DMC_RETURN_IF_ERROR(WriteFileAtomically(output, glb));
    if (options.progress) options.progress(sequence.frame_count(), sequence.frame_count());
    return Status::Ok();
  }
  if (const auto single = io_internal::MeshFormatFromPath(output);
      single && output_path.has_filename()) {
    if (sequence.frame_count() != 1) {
      return InvalidArgumentError(output.string() + " is a single mesh file but the sequence has " +
                                  std::to_string(sequence.frame_count()) +
                                  " frames; write a directory or a .pc2 instead");
    }
    DMC_RETURN_IF_ERROR(WriteFileAtomically(output, AsBytes(FrameText(sequence, 0, *single))));
    if (options.progress) options.progress(1, 1);
    return Status::Ok();
  }
  return WriteFrameDirectory(sequence, output, *frame_format, options);
}

}  // namespace

Status CheckSequenceOutputPath(const std::filesystem::path& output_path) {
  if (output_path.empty()) return InvalidArgumentError("no output path given");
  const std::filesystem::path output = WithoutTrailingSeparator(output_path);
  const std::string extension = LowercaseExtension(output);
  if (extension.empty() || !output_path.has_filename() || extension == ".pc2" ||
      extension == ".glb" || io_internal::MeshFormatFromPath(output)) {
    return Status::Ok();
  }
  // "out.fbx" is not silently a directory.
  std::error_code error;
  if (std::filesystem::is_directory(output, error)) return Status::Ok();
  return InvalidArgumentError(
      "cannot write " + output.string() + ": unknown output extension '" + extension +
      "' (expected .pc2, .glb, .obj, .off or .ply; a directory of frames is a path without an "
      "extension or ending in '/')");
}

Status WriteSequence(const MeshSequence& sequence, const std::filesystem::path& output_path,
                     const WriteOptions& options) {
  DMC_RETURN_IF_ERROR(CheckSequenceOutputPath(output_path));
  return core_internal::GuardAllocation("writing " + output_path.string(), [&] {
    return WriteSequenceUnguarded(sequence, output_path, options);
  });
}

StatusOr<std::vector<uint8_t>> BuildGltfScene(const std::filesystem::path& input,
                                              const ReadOptions& options, const ReadReport& report,
                                              int stream_vertices) {
  const std::string extension = LowercaseExtension(input);
  if (extension != ".glb" && extension != ".gltf") {
    return InvalidArgumentError(input.string() + " is not a glTF file: it has no scene to keep");
  }
  return io_internal::ReadSceneRecord(input, options.gltf, report.vertex_map, report.clips,
                                      stream_vertices);
}

StatusOr<std::vector<ClipInfo>> SceneClips(std::span<const uint8_t> scene) {
  return io_internal::ReadSceneClips(scene);
}

}  // namespace dmc
