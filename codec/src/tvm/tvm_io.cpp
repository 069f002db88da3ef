// Reading and writing time-varying meshes (directories of frame files with their own
// connectivity) and the centres text format documented in dmc/tvm.h.
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <span>
#include <string>
#include <system_error>

#include "dmc/io.h"
#include "dmc/tvm.h"
#include "io/mesh_formats.h"

namespace dmc::tvm {

namespace {

using io_internal::MeshFormat;

bool IsFrameFileName(const std::string& name) {
  return !name.empty() && name.front() != '.' && io_internal::MeshFormatFromPath(name).has_value();
}

// Files of a TVM directory that WriteTimeVaryingMesh may delete: the frame files and the centres
// file it writes itself, nothing else.
bool IsReplaceableFileName(const std::string& name) {
  return (name.rfind("frame_", 0) == 0 && IsFrameFileName(name)) || name == kCentresFileName;
}

std::span<const uint8_t> AsBytes(std::string_view text) {
  return {reinterpret_cast<const uint8_t*>(text.data()), text.size()};
}

Status ValidateFrame(const TvmFrame& frame, const std::string& label) {
  if (frame.vertex_count() == 0) return InvalidSequenceError(label + " has no vertices");
  if (frame.triangle_count() == 0) return InvalidSequenceError(label + " has no triangles");
  for (int v = 0; v < frame.vertex_count(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(frame.positions(v, axis))) {
        return InvalidSequenceError(label + ", vertex " + std::to_string(v) + ": coordinate " +
                                    "xyz"[axis] + " is not finite");
      }
    }
  }
  for (int t = 0; t < frame.triangle_count(); ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      const int32_t index = frame.triangles(t, corner);
      if (index < 0 || index >= frame.vertex_count()) {
        return InvalidSequenceError(label + ", triangle " + std::to_string(t) + ": index " +
                                    std::to_string(index) + " outside [0, " +
                                    std::to_string(frame.vertex_count()) + ")");
      }
    }
  }
  return Status::Ok();
}

// Splits the text into tokens with their line numbers, dropping '#' comments.
struct Token {
  std::string_view text;
  int line;
};

std::vector<Token> Tokenize(std::string_view text) {
  std::vector<Token> tokens;
  int line = 1;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == ' ' || c == '\t' || c == '\r') {
      ++i;
    } else if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else {
      const size_t start = i;
      while (i < text.size() && text[i] != ' ' && text[i] != '\t' && text[i] != '\r' &&
             text[i] != '\n' && text[i] != '#') {
        ++i;
      }
      tokens.push_back({text.substr(start, i - start), line});
    }
  }
  return tokens;
}

Status TokenError(const Token& token, const std::string& what) {
  return ParseError("line " + std::to_string(token.line) + ": " + what + ", got '" +
                    std::string(token.text) + "'");
}

template <typename Number>
StatusOr<Number> ParseNumber(const Token& token, const std::string& what) {
  Number value{};
  const char* end = token.text.data() + token.text.size();
  const auto [ptr, error] = std::from_chars(token.text.data(), end, value);
  if (error != std::errc() || ptr != end) return TokenError(token, "expected " + what);
  return value;
}

}  // namespace

Status ValidateTimeVaryingMesh(const TimeVaryingMesh& mesh) {
  if (mesh.frames.empty()) return InvalidSequenceError("the time-varying mesh has no frames");
  for (int f = 0; f < mesh.frame_count(); ++f) {
    DMC_RETURN_IF_ERROR(
        ValidateFrame(mesh.frames[static_cast<size_t>(f)], "frame " + std::to_string(f)));
  }
  return Status::Ok();
}

Status ValidateCentres(const CentreTrajectories& centres, int expected_frames) {
  if (centres.frame_count() == 0) return InvalidSequenceError("the centres have no frames");
  if (centres.centre_count() == 0) return InvalidSequenceError("there are no centres");
  for (int f = 0; f < centres.frame_count(); ++f) {
    const FramePositionsD& frame = centres.positions[static_cast<size_t>(f)];
    if (frame.rows() != centres.centre_count()) {
      return InvalidSequenceError("centres frame " + std::to_string(f) + " has " +
                                  std::to_string(frame.rows()) + " centres, frame 0 has " +
                                  std::to_string(centres.centre_count()));
    }
    for (int i = 0; i < frame.rows(); ++i) {
      if (!frame.row(i).allFinite()) {
        return InvalidSequenceError("centres frame " + std::to_string(f) + ", centre " +
                                    std::to_string(i) + ": a coordinate is not finite");
      }
    }
  }
  if (expected_frames > 0 && centres.frame_count() != expected_frames) {
    return MismatchError("the centres have " + std::to_string(centres.frame_count()) +
                         " frames, the mesh has " + std::to_string(expected_frames));
  }
  return Status::Ok();
}

StatusOr<TimeVaryingMesh> ReadTimeVaryingMesh(const std::filesystem::path& directory) {
  std::error_code error;
  if (!std::filesystem::is_directory(directory, error)) {
    return IoError("cannot read " + directory.string() +
                   ": a time-varying mesh is a directory of frame files");
  }
  std::vector<std::filesystem::path> files;
  std::filesystem::directory_iterator it(directory, error);
  if (error) return IoError("cannot list " + directory.string() + ": " + error.message());
  for (; it != std::filesystem::directory_iterator(); it.increment(error)) {
    if (error) return IoError("cannot list " + directory.string() + ": " + error.message());
    std::error_code type_error;
    if (!it->is_regular_file(type_error)) continue;
    const std::string name = it->path().filename().string();
    if (IsFrameFileName(name)) files.push_back(it->path());
  }
  if (files.empty()) {
    return InvalidSequenceError(directory.string() + " holds no .obj, .off or .ply frame files");
  }
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return NaturalLess(a.filename().string(), b.filename().string());
  });
  for (const auto& file : files) {
    if (io_internal::MeshFormatFromPath(file) != io_internal::MeshFormatFromPath(files.front())) {
      return InvalidArgumentError(directory.string() + " mixes mesh formats (" +
                                  files.front().filename().string() + ", " +
                                  file.filename().string() + ")");
    }
  }

  TimeVaryingMesh mesh;
  std::filesystem::path absolute = std::filesystem::absolute(directory, error).lexically_normal();
  if (!absolute.has_filename()) absolute = absolute.parent_path();
  mesh.name = absolute.filename().string();
  mesh.frames.resize(files.size());
  std::vector<Status> results(files.size());
  std::vector<double> frame_rates(files.size(), 0.0);
  // Frames are independent files; parsing is CPU-bound, so read them in parallel and report the
  // lowest failing frame.
  tbb::parallel_for(size_t{0}, files.size(), [&](size_t f) {
    results[f] = [&]() -> Status {
      DMC_ASSIGN_OR_RETURN(const io_internal::MeshFileData data,
                           io_internal::ReadMeshFile(files[f]));
      TvmFrame& frame = mesh.frames[f];
      frame.positions.resize(data.vertex_count(), 3);
      for (size_t k = 0; k < data.positions.size(); ++k) {
        frame.positions.data()[k] = static_cast<double>(data.positions[k]);
      }
      frame.triangles.resize(data.triangle_count(), 3);
      std::copy(data.triangles.begin(), data.triangles.end(), frame.triangles.data());
      frame_rates[f] = data.frame_rate;
      return ValidateFrame(frame, "frame " + std::to_string(f) + " (" + files[f].string() + ")");
    }();
  });
  for (const Status& status : results) DMC_RETURN_IF_ERROR(status);
  mesh.frame_rate = frame_rates.front();
  return mesh;
}

Status WriteTimeVaryingMesh(const TimeVaryingMesh& mesh, const std::filesystem::path& directory,
                            std::string_view frame_format) {
  const auto format = io_internal::MeshFormatFromName(frame_format);
  if (!format) {
    return InvalidArgumentError("frame format must be obj, off or ply, got '" +
                                std::string(frame_format) + "'");
  }
  DMC_RETURN_IF_ERROR(ValidateTimeVaryingMesh(mesh));
  std::error_code error;
  if (std::filesystem::exists(directory, error)) {
    if (!std::filesystem::is_directory(directory, error)) {
      return IoError("cannot write " + directory.string() + ": it exists and is not a directory");
    }
    std::vector<std::filesystem::path> stale;
    for (const auto& entry : std::filesystem::directory_iterator(directory, error)) {
      const std::string name = entry.path().filename().string();
      if (!IsReplaceableFileName(name)) {
        return IoError("cannot write " + directory.string() + ": it holds " + name +
                       ", which is neither a frame file nor a centres file");
      }
      stale.push_back(entry.path());
    }
    if (error) return IoError("cannot list " + directory.string() + ": " + error.message());
    for (const auto& path : stale) std::filesystem::remove(path, error);
  } else {
    const std::filesystem::path parent = directory.parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent, error)) {
      return IoError("cannot write " + directory.string() + ": the directory " + parent.string() +
                     " does not exist");
    }
    if (!std::filesystem::create_directory(directory, error) && error) {
      return IoError("cannot create " + directory.string() + ": " + error.message());
    }
  }

  const int digits = std::max(4, static_cast<int>(std::to_string(mesh.frame_count() - 1).size()));
  std::vector<Status> results(mesh.frames.size());
  tbb::parallel_for(size_t{0}, mesh.frames.size(), [&](size_t f) {
    const TvmFrame& frame = mesh.frames[f];
    std::vector<float> positions(static_cast<size_t>(frame.positions.size()));
    for (size_t k = 0; k < positions.size(); ++k) {
      positions[k] = static_cast<float>(frame.positions.data()[k]);
    }
    fmt::memory_buffer text;
    io_internal::AppendMeshText(
        *format, positions,
        std::span<const int32_t>(frame.triangles.data(),
                                 static_cast<size_t>(frame.triangles.size())),
        mesh.frame_rate, text);
    const std::string name =
        fmt::format("frame_{:0{}}.{}", f, digits, io_internal::MeshFormatExtension(*format));
    results[f] =
        WriteFileAtomically(directory / name, AsBytes(std::string_view(text.data(), text.size())));
  });
  for (const Status& status : results) DMC_RETURN_IF_ERROR(status);
  return Status::Ok();
}

StatusOr<CentreTrajectories> ParseCentres(std::string_view text) {
  const std::vector<Token> tokens = Tokenize(text);
  if (tokens.size() < 4) {
    return ParseError("line " + std::to_string(tokens.empty() ? 1 : tokens.back().line) +
                      ": expected the header 'dmc-centres 1' and '<centres> <frames>'");
  }
  if (tokens[0].text != "dmc-centres") {
    return TokenError(tokens[0], "expected the magic 'dmc-centres'");
  }
  if (tokens[1].text != "1") return TokenError(tokens[1], "expected format version 1");
  DMC_ASSIGN_OR_RETURN(const int64_t centre_count,
                       ParseNumber<int64_t>(tokens[2], "a positive centre count"));
  DMC_ASSIGN_OR_RETURN(const int64_t frame_count,
                       ParseNumber<int64_t>(tokens[3], "a positive frame count"));
  if (centre_count < 1 || centre_count > (int64_t{1} << 31) - 1) {
    return TokenError(tokens[2], "expected a positive centre count");
  }
  if (frame_count < 1 || frame_count > (int64_t{1} << 31) - 1) {
    return TokenError(tokens[3], "expected a positive frame count");
  }
  const uint64_t expected =
      3u * static_cast<uint64_t>(centre_count) * static_cast<uint64_t>(frame_count);
  const uint64_t present = tokens.size() - 4;
  if (present != expected) {
    return ParseError("line " + std::to_string(tokens.back().line) + ": " +
                      std::to_string(present) + " coordinates for " + std::to_string(centre_count) +
                      " centres x " + std::to_string(frame_count) + " frames, expected " +
                      std::to_string(expected));
  }
  CentreTrajectories centres;
  centres.positions.assign(static_cast<size_t>(frame_count),
                           FramePositionsD(static_cast<Eigen::Index>(centre_count), 3));
  size_t next = 4;
  for (int64_t i = 0; i < centre_count; ++i) {
    for (int64_t f = 0; f < frame_count; ++f) {
      for (int axis = 0; axis < 3; ++axis) {
        const Token& token = tokens[next++];
        DMC_ASSIGN_OR_RETURN(const double value, ParseNumber<double>(token, "a number"));
        if (!std::isfinite(value)) return TokenError(token, "expected a finite number");
        centres.positions[static_cast<size_t>(f)](i, axis) = value;
      }
    }
  }
  return centres;
}

StatusOr<CentreTrajectories> ReadCentres(const std::filesystem::path& path) {
  DMC_ASSIGN_OR_RETURN(const std::string text, io_internal::ReadFileContent(path));
  StatusOr<CentreTrajectories> centres = ParseCentres(text);
  if (!centres.ok()) return centres.status().WithContext(path.string());
  return centres;
}

Status WriteCentres(const CentreTrajectories& centres, const std::filesystem::path& path) {
  DMC_RETURN_IF_ERROR(ValidateCentres(centres));
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out),
                 "dmc-centres 1\n# {} centres x {} frames; one trajectory per line: x y z of "
                 "frame 0, frame 1, ...\n{} {}\n",
                 centres.centre_count(), centres.frame_count(), centres.centre_count(),
                 centres.frame_count());
  for (int i = 0; i < centres.centre_count(); ++i) {
    for (int f = 0; f < centres.frame_count(); ++f) {
      const FramePositionsD& frame = centres.positions[static_cast<size_t>(f)];
      // {} is the shortest decimal that reads back to the same double.
      fmt::format_to(std::back_inserter(out), "{}{} {} {}", f == 0 ? "" : "  ", frame(i, 0),
                     frame(i, 1), frame(i, 2));
    }
    out.push_back('\n');
  }
  return WriteFileAtomically(path, AsBytes(std::string_view(out.data(), out.size())));
}

}  // namespace dmc::tvm
