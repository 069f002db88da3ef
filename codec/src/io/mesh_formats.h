// Internal: single-file mesh parsers and writers behind ReadSequence/WriteSequence.
//
// Parsers take the whole file content in memory and report errors as "line N: ..." (text formats)
// or a plain description (binary); ReadMeshFile prefixes the path. They are re-entrant and safe to
// call from several threads at once.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/status.h"

namespace dmc::io_internal {

enum class MeshFormat { kObj, kOff, kPly };

// One mesh file as read: vertices and triangles in file order.
struct MeshFileData {
  std::vector<float> positions;    // V x 3, row-major
  std::vector<int32_t> triangles;  // T x 3, row-major, 0-based, after fan triangulation
  int polygons_triangulated = 0;   // faces with more than 3 corners
  std::vector<std::string> notes;  // non-fatal findings, e.g. "3 'l' (line) elements ignored"
  double frame_rate = 0.0;         // from a "dmc frame_rate <fps>" comment; 0 when absent

  int vertex_count() const { return static_cast<int>(positions.size() / 3); }
  int triangle_count() const { return static_cast<int>(triangles.size() / 3); }
};

// Format from a path's extension (case-insensitive), or nullopt.
std::optional<MeshFormat> MeshFormatFromPath(const std::filesystem::path& path);
std::string_view MeshFormatExtension(MeshFormat format);  // "obj", "off", "ply"
// Parses "obj" | "off" | "ply" (case-insensitive).
std::optional<MeshFormat> MeshFormatFromName(std::string_view name);

// Adds one face's corners, fan-triangulated; corners.size() >= 3.
void AppendFan(std::span<const int32_t> corners, MeshFileData& mesh);

StatusOr<MeshFileData> ParseObj(std::string_view text);
StatusOr<MeshFileData> ParseOff(std::string_view text);
StatusOr<MeshFileData> ParsePly(std::string_view bytes);

// Reads and parses one file; errors are prefixed with the path ("<path>:<line>: ..." for text).
StatusOr<MeshFileData> ReadMeshFile(const std::filesystem::path& path);

// The whole content of a file (kIoError naming the path when it cannot be read).
StatusOr<std::string> ReadFileContent(const std::filesystem::path& path);

// Serialises one frame. `positions` is V x 3, `triangles` T x 3 (0-based). frame_rate > 0 is
// recorded as a "dmc frame_rate" comment.
void AppendMeshText(MeshFormat format, std::span<const float> positions,
                    std::span<const int32_t> triangles, double frame_rate, fmt::memory_buffer& out);

// The prefix "<path>:<line>: " used by text parse errors, as a Status context.
Status WithLineContext(const Status& status, const std::filesystem::path& path);

}  // namespace dmc::io_internal
