// Strict ASCII OFF parser (OFF, COFF, NOFF, CNOFF, STOFF and combinations: extra per-vertex and
// per-face values are syntax-checked and dropped). 4OFF/nOFF (other dimensions) and binary OFF are
// rejected as unsupported.
#include <algorithm>
#include <cstdint>
#include <string>

#include "io/mesh_formats.h"
#include "io/text_scanner.h"

namespace dmc::io_internal {
namespace {

Status LineError(int line, const std::string& what) {
  return ParseError("line " + std::to_string(line) + ": " + what);
}

// The next line holding something other than blanks or a comment. Comments start with '#'
// anywhere on a line; the "dmc frame_rate" comment is picked up on the way.
bool NextContentLine(LineReader& lines, std::string_view& content, double& frame_rate) {
  std::string_view line;
  while (lines.Next(line)) {
    const size_t hash = line.find('#');
    if (hash != std::string_view::npos) {
      TokenReader comment(line.substr(hash + 1));
      std::string_view word, key, value;
      double parsed = 0.0;
      if (comment.Next(word) && word == "dmc" && comment.Next(key) && key == "frame_rate" &&
          comment.Next(value) && ParseNumber(value, parsed) && parsed > 0.0) {
        frame_rate = parsed;
      }
      line = line.substr(0, hash);
    }
    line = TrimLeft(line);
    if (!line.empty()) {
      content = line;
      return true;
    }
  }
  return false;
}

// Checks that every remaining token on the line is a number (colours, normals, texture data).
bool RestAreNumbers(TokenReader& tokens, std::string_view& bad) {
  std::string_view token;
  while (tokens.Next(token)) {
    double unused = 0.0;
    if (!ParseNumber(token, unused)) {
      bad = token;
      return false;
    }
  }
  return true;
}

}  // namespace

StatusOr<MeshFileData> ParseOff(std::string_view text) {
  MeshFileData mesh;
  LineReader lines(text);
  std::string_view line;
  if (!NextContentLine(lines, line, mesh.frame_rate)) {
    return ParseError("the file is empty (expected an OFF header)");
  }
  TokenReader header(line);
  std::string_view keyword;
  header.Next(keyword);
  const bool is_off = keyword.size() >= 3 && keyword.substr(keyword.size() - 3) == "OFF";
  const std::string_view prefix = is_off ? keyword.substr(0, keyword.size() - 3) : "";
  if (!is_off || prefix.find_first_not_of("STCN4n") != std::string_view::npos) {
    return LineError(lines.line_number(), "expected an OFF header, found " + Quote(keyword));
  }
  if (prefix.find_first_of("4n") != std::string_view::npos) {
    return UnsupportedError("line " + std::to_string(lines.line_number()) + ": " +
                            std::string(keyword) + " (not 3D) is not supported");
  }
  std::string_view token;
  TokenReader counts = header;
  if (counts.AtEnd()) {
    if (!NextContentLine(lines, line, mesh.frame_rate)) {
      return ParseError("the file ends before the vertex and face counts");
    }
    counts = TokenReader(line);
  } else if (TokenReader probe = counts; probe.Next(token) && token == "BINARY") {
    return UnsupportedError("binary OFF is not supported; convert it to ASCII OFF, OBJ or PLY");
  }
  int64_t vertex_count = -1, face_count = -1, edge_count = 0;
  if (!counts.Next(token) || !ParseNumber(token, vertex_count) || !counts.Next(token) ||
      !ParseNumber(token, face_count) || (counts.Next(token) && !ParseNumber(token, edge_count)) ||
      !counts.AtEnd() || vertex_count < 0 || face_count < 0 || vertex_count > INT32_MAX / 3 ||
      face_count > INT32_MAX / 3) {
    return LineError(lines.line_number(),
                     "expected 'vertices faces [edges]' counts, found " + Quote(line));
  }

  // Counts come from the file: cap the reservation so a corrupt header cannot exhaust memory.
  const size_t kMaxReserve = size_t{1} << 22;
  mesh.positions.reserve(std::min(static_cast<size_t>(vertex_count) * 3, kMaxReserve));
  mesh.triangles.reserve(std::min(static_cast<size_t>(face_count) * 3, kMaxReserve));
  for (int64_t v = 0; v < vertex_count; ++v) {
    if (!NextContentLine(lines, line, mesh.frame_rate)) {
      return ParseError("the file ends after " + std::to_string(v) + " of " +
                        std::to_string(vertex_count) + " vertices");
    }
    TokenReader tokens(line);
    for (int axis = 0; axis < 3; ++axis) {
      float value = 0.0f;
      if (!tokens.Next(token)) {
        return LineError(lines.line_number(),
                         "vertex has " + std::to_string(axis) + " coordinate(s), expected 3");
      }
      if (!ParseNumber(token, value)) {
        return LineError(lines.line_number(),
                         "vertex coordinate " + Quote(token) + " is not a number");
      }
      mesh.positions.push_back(value);
    }
    std::string_view bad;
    if (!RestAreNumbers(tokens, bad)) {
      return LineError(lines.line_number(),
                       "vertex line holds " + Quote(bad) + ", which is not a number");
    }
  }

  std::vector<int32_t> corners;
  for (int64_t f = 0; f < face_count; ++f) {
    if (!NextContentLine(lines, line, mesh.frame_rate)) {
      return ParseError("the file ends after " + std::to_string(f) + " of " +
                        std::to_string(face_count) + " faces");
    }
    TokenReader tokens(line);
    int64_t corner_count = 0;
    if (!tokens.Next(token) || !ParseNumber(token, corner_count)) {
      return LineError(lines.line_number(),
                       "face corner count " + Quote(token) + " is not an integer");
    }
    if (corner_count < 3) {
      return LineError(lines.line_number(), "face has " + std::to_string(corner_count) +
                                                " corner(s), at least 3 are needed");
    }
    corners.clear();
    for (int64_t k = 0; k < corner_count; ++k) {
      int64_t index = 0;
      if (!tokens.Next(token)) {
        return LineError(lines.line_number(), "face declares " + std::to_string(corner_count) +
                                                  " corners but lists " + std::to_string(k));
      }
      if (!ParseNumber(token, index)) {
        return LineError(lines.line_number(), "face index " + Quote(token) + " is not an integer");
      }
      if (index < 0 || index >= vertex_count) {
        return LineError(lines.line_number(), "face index " + std::to_string(index) +
                                                  " is outside [0, " +
                                                  std::to_string(vertex_count) + ")");
      }
      corners.push_back(static_cast<int32_t>(index));
    }
    std::string_view bad;
    if (!RestAreNumbers(tokens, bad)) {
      return LineError(lines.line_number(),
                       "face line holds " + Quote(bad) + ", which is not a number");
    }
    if (corner_count > 3) ++mesh.polygons_triangulated;
    AppendFan(corners, mesh);
  }
  if (NextContentLine(lines, line, mesh.frame_rate)) {
    return LineError(lines.line_number(), "unexpected content after the last declared face");
  }
  return mesh;
}

}  // namespace dmc::io_internal
