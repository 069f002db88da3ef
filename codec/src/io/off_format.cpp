// Strict ASCII OFF parser (OFF, COFF, NOFF, CNOFF, STOFF and combinations: extra per-vertex and
// per-face values are syntax-checked and dropped). 4OFF/nOFF (other dimensions) and binary OFF are
// rejected as unsupported.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

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

struct OffCounts {
  int64_t vertices = -1;
  int64_t faces = -1;
};

// The header keyword and the counts after it (on the same line or the next content line).
StatusOr<OffCounts> ParseOffHeader(LineReader& lines, MeshFileData& mesh) {
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
  OffCounts result;
  int64_t edge_count = 0;
  if (!counts.Next(token) || !ParseNumber(token, result.vertices) || !counts.Next(token) ||
      !ParseNumber(token, result.faces) ||
      (counts.Next(token) && !ParseNumber(token, edge_count)) || !counts.AtEnd() ||
      result.vertices < 0 || result.faces < 0 || result.vertices > INT32_MAX / 3 ||
      result.faces > INT32_MAX / 3) {
    return LineError(lines.line_number(),
                     "expected 'vertices faces [edges]' counts, found " + Quote(line));
  }
  return result;
}

// A vertex line: three coordinates, then numbers (colours, normals, ...) that are dropped.
Status ParseOffVertex(std::string_view line, int line_number, MeshFileData& mesh) {
  TokenReader tokens(line);
  std::string_view token;
  for (int axis = 0; axis < 3; ++axis) {
    float value = 0.0f;
    if (!tokens.Next(token)) {
      return LineError(line_number,
                       "vertex has " + std::to_string(axis) + " coordinate(s), expected 3");
    }
    if (const NumberParse parsed = ParseNumberChecked(token, value); parsed != NumberParse::kOk) {
      return LineError(
          line_number,
          CoordinateProblem(token, parsed, static_cast<int64_t>(mesh.positions.size() / 3), axis));
    }
    mesh.positions.push_back(value);
  }
  std::string_view bad;
  if (!RestAreNumbers(tokens, bad)) {
    return LineError(line_number, "vertex line holds " + Quote(bad) + ", which is not a number");
  }
  return Status::Ok();
}

// A face line: the corner count, the corners, then numbers that are dropped; appended as a fan.
Status ParseOffFace(std::string_view line, int line_number, int64_t vertex_count,
                    std::vector<int32_t>& corners, MeshFileData& mesh) {
  TokenReader tokens(line);
  std::string_view token;
  int64_t corner_count = 0;
  if (!tokens.Next(token) || !ParseNumber(token, corner_count)) {
    return LineError(line_number, "face corner count " + Quote(token) + " is not an integer");
  }
  if (corner_count < 3) {
    return LineError(line_number, "face has " + std::to_string(corner_count) +
                                      " corner(s), at least 3 are needed");
  }
  corners.clear();
  for (int64_t k = 0; k < corner_count; ++k) {
    int64_t index = 0;
    if (!tokens.Next(token)) {
      return LineError(line_number, "face declares " + std::to_string(corner_count) +
                                        " corners but lists " + std::to_string(k));
    }
    if (!ParseNumber(token, index)) {
      return LineError(line_number, "face index " + Quote(token) + " is not an integer");
    }
    if (index < 0 || index >= vertex_count) {
      return LineError(line_number, "face index " + std::to_string(index) + " is outside [0, " +
                                        std::to_string(vertex_count) + ")");
    }
    corners.push_back(static_cast<int32_t>(index));
  }
  std::string_view bad;
  if (!RestAreNumbers(tokens, bad)) {
    return LineError(line_number, "face line holds " + Quote(bad) + ", which is not a number");
  }
  if (corner_count > 3) ++mesh.polygons_triangulated;
  AppendFan(corners, mesh);
  return Status::Ok();
}

}  // namespace

StatusOr<MeshFileData> ParseOff(std::string_view text) {
  MeshFileData mesh;
  LineReader lines(text);
  DMC_ASSIGN_OR_RETURN(const OffCounts counts, ParseOffHeader(lines, mesh));
  // Counts come from the file: cap the reservation so a corrupt header cannot exhaust memory.
  const size_t kMaxReserve = size_t{1} << 22;
  mesh.positions.reserve(std::min(static_cast<size_t>(counts.vertices) * 3, kMaxReserve));
  mesh.triangles.reserve(std::min(static_cast<size_t>(counts.faces) * 3, kMaxReserve));
  std::string_view line;
  for (int64_t v = 0; v < counts.vertices; ++v) {
    if (!NextContentLine(lines, line, mesh.frame_rate)) {
      return ParseError("the file ends after " + std::to_string(v) + " of " +
                        std::to_string(counts.vertices) + " vertices");
    }
    DMC_RETURN_IF_ERROR(ParseOffVertex(line, lines.line_number(), mesh));
  }
  std::vector<int32_t> corners;
  for (int64_t f = 0; f < counts.faces; ++f) {
    if (!NextContentLine(lines, line, mesh.frame_rate)) {
      return ParseError("the file ends after " + std::to_string(f) + " of " +
                        std::to_string(counts.faces) + " faces");
    }
    DMC_RETURN_IF_ERROR(ParseOffFace(line, lines.line_number(), counts.vertices, corners, mesh));
  }
  if (NextContentLine(lines, line, mesh.frame_rate)) {
    return LineError(lines.line_number(), "unexpected content after the last declared face");
  }
  return mesh;
}

}  // namespace dmc::io_internal
