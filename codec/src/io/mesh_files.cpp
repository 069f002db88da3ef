// Format dispatch, file reading and the text writers shared by the per-format parsers.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <iterator>

#include "io/mesh_formats.h"

namespace dmc::io_internal {

namespace {

std::string Lowercase(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

}  // namespace

std::optional<MeshFormat> MeshFormatFromName(std::string_view name) {
  const std::string lower = Lowercase(name);
  if (lower == "obj") return MeshFormat::kObj;
  if (lower == "off") return MeshFormat::kOff;
  if (lower == "ply") return MeshFormat::kPly;
  return std::nullopt;
}

std::optional<MeshFormat> MeshFormatFromPath(const std::filesystem::path& path) {
  const std::string extension = path.extension().string();
  if (extension.size() < 2) return std::nullopt;
  return MeshFormatFromName(std::string_view(extension).substr(1));
}

std::string_view MeshFormatExtension(MeshFormat format) {
  switch (format) {
    case MeshFormat::kObj:
      return "obj";
    case MeshFormat::kOff:
      return "off";
    case MeshFormat::kPly:
      return "ply";
  }
  return "obj";
}

void AppendFan(std::span<const int32_t> corners, MeshFileData& mesh) {
  for (size_t k = 1; k + 1 < corners.size(); ++k) {
    mesh.triangles.insert(mesh.triangles.end(), {corners[0], corners[k], corners[k + 1]});
  }
}

StatusOr<std::string> ReadFileContent(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return IoError("cannot open " + path.string() + ": " + std::strerror(errno));
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    const int error = S_ISDIR(info.st_mode) ? EISDIR : errno;
    ::close(fd);
    return IoError("cannot read " + path.string() + ": " +
                   (error != 0 ? std::strerror(error) : "not a regular file"));
  }
  std::string content(static_cast<size_t>(info.st_size), '\0');
  size_t done = 0;
  while (done < content.size()) {
    const ssize_t got = ::read(fd, content.data() + done, content.size() - done);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) {
      const std::string reason = got < 0 ? std::strerror(errno) : "the file shrank while read";
      ::close(fd);
      return IoError("cannot read " + path.string() + ": " + reason);
    }
    done += static_cast<size_t>(got);
  }
  ::close(fd);
  return content;
}

Status WithLineContext(const Status& status, const std::filesystem::path& path) {
  if (status.ok()) return status;
  const std::string& message = status.message();
  constexpr std::string_view kLine = "line ";
  if (message.compare(0, kLine.size(), kLine) == 0) {
    const size_t colon = message.find(':');
    if (colon != std::string::npos) {
      return Status(status.code(), path.string() + ":" +
                                       message.substr(kLine.size(), colon - kLine.size()) +
                                       message.substr(colon));
    }
  }
  return status.WithContext(path.string());
}

StatusOr<MeshFileData> ReadMeshFile(const std::filesystem::path& path) {
  const std::optional<MeshFormat> format = MeshFormatFromPath(path);
  if (!format) {
    return UnsupportedError(path.string() +
                            ": unknown mesh extension (expected .obj, .off or .ply)");
  }
  DMC_ASSIGN_OR_RETURN(const std::string content, ReadFileContent(path));
  StatusOr<MeshFileData> mesh = *format == MeshFormat::kObj   ? ParseObj(content)
                                : *format == MeshFormat::kOff ? ParseOff(content)
                                                              : ParsePly(content);
  if (!mesh.ok()) return WithLineContext(mesh.status(), path);
  return mesh;
}

void AppendMeshText(MeshFormat format, std::span<const float> positions,
                    std::span<const int32_t> triangles, double frame_rate,
                    fmt::memory_buffer& out) {
  const size_t vertex_count = positions.size() / 3;
  const size_t triangle_count = triangles.size() / 3;
  auto sink = std::back_inserter(out);
  // fmt's "{}" prints a float in the shortest form that parses back to the same float.
  switch (format) {
    case MeshFormat::kObj:
      fmt::format_to(sink, "# dmc: {} vertices, {} triangles\n", vertex_count, triangle_count);
      if (frame_rate > 0.0) fmt::format_to(sink, "# dmc frame_rate {}\n", frame_rate);
      for (size_t v = 0; v < vertex_count; ++v) {
        fmt::format_to(sink, "v {} {} {}\n", positions[3 * v], positions[3 * v + 1],
                       positions[3 * v + 2]);
      }
      for (size_t t = 0; t < triangle_count; ++t) {
        fmt::format_to(sink, "f {} {} {}\n", triangles[3 * t] + 1, triangles[3 * t + 1] + 1,
                       triangles[3 * t + 2] + 1);
      }
      break;
    case MeshFormat::kOff:
      fmt::format_to(sink, "OFF\n");
      if (frame_rate > 0.0) fmt::format_to(sink, "# dmc frame_rate {}\n", frame_rate);
      fmt::format_to(sink, "{} {} 0\n", vertex_count, triangle_count);
      for (size_t v = 0; v < vertex_count; ++v) {
        fmt::format_to(sink, "{} {} {}\n", positions[3 * v], positions[3 * v + 1],
                       positions[3 * v + 2]);
      }
      for (size_t t = 0; t < triangle_count; ++t) {
        fmt::format_to(sink, "3 {} {} {}\n", triangles[3 * t], triangles[3 * t + 1],
                       triangles[3 * t + 2]);
      }
      break;
    case MeshFormat::kPly:
      fmt::format_to(sink, "ply\nformat ascii 1.0\ncomment written by dmc\n");
      if (frame_rate > 0.0) fmt::format_to(sink, "comment dmc frame_rate {}\n", frame_rate);
      fmt::format_to(sink,
                     "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
                     vertex_count, triangle_count);
      for (size_t v = 0; v < vertex_count; ++v) {
        fmt::format_to(sink, "{} {} {}\n", positions[3 * v], positions[3 * v + 1],
                       positions[3 * v + 2]);
      }
      for (size_t t = 0; t < triangle_count; ++t) {
        fmt::format_to(sink, "3 {} {} {}\n", triangles[3 * t], triangles[3 * t + 1],
                       triangles[3 * t + 2]);
      }
      break;
  }
}

}  // namespace dmc::io_internal
