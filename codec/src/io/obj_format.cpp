// Strict Wavefront OBJ parser: v and f statements, every other statement of the specification
// skipped, anything else an error with its line number.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/mesh_formats.h"
#include "io/text_scanner.h"

namespace dmc::io_internal {
namespace {

// Statements of the OBJ specification that carry nothing a mesh sequence keeps (texture and
// normal data, groups, materials, free-form geometry and its parameters).
constexpr std::array<std::string_view, 35> kSkippedStatements = {
    "vt",       "vn",         "vp",        "o",     "g",     "s",      "mg",
    "usemtl",   "mtllib",     "usemap",    "maps",  "lod",   "bevel",  "c_interp",
    "d_interp", "shadow_obj", "trace_obj", "ctech", "stech", "cstype", "deg",
    "bmat",     "step",       "curv",      "curv2", "surf",  "parm",   "trim",
    "hole",     "scrv",       "sp",        "end",   "con",   "call",   "csh"};

bool IsSkippedStatement(std::string_view keyword) {
  return std::find(kSkippedStatements.begin(), kSkippedStatements.end(), keyword) !=
         kSkippedStatements.end();
}

Status LineError(int line, const std::string& what) {
  return ParseError("line " + std::to_string(line) + ": " + what);
}

// "# dmc frame_rate 25" (written by WriteSequence); anything else is an ordinary comment.
void ReadFrameRateComment(std::string_view comment, double& frame_rate) {
  TokenReader tokens(comment.substr(1));
  std::string_view word, key, value;
  double parsed = 0.0;
  if (tokens.Next(word) && word == "dmc" && tokens.Next(key) && key == "frame_rate" &&
      tokens.Next(value) && ParseNumber(value, parsed) && parsed > 0.0) {
    frame_rate = parsed;
  }
}

// The vertex part of a face corner "v", "v/vt", "v//vn" or "v/vt/vn"; the texture and normal
// parts must be integers or empty but are otherwise unused.
bool ParseCornerVertex(std::string_view corner, int64_t& vertex) {
  const size_t slash = corner.find('/');
  if (!ParseNumber(corner.substr(0, slash), vertex)) return false;
  if (slash == std::string_view::npos) return true;
  std::string_view rest = corner.substr(slash + 1);
  for (int part = 0; part < 2; ++part) {
    const size_t next = rest.find('/');
    const std::string_view field = rest.substr(0, next);
    int64_t unused = 0;
    if (!field.empty() && !ParseNumber(field, unused)) return false;
    if (next == std::string_view::npos) return true;
    rest = rest.substr(next + 1);
  }
  return false;  // more than three parts
}

// A "v" statement: x y z kept; a 4th (w) or 4th-6th (colour) value is syntax-checked and dropped.
Status ParseObjVertex(TokenReader& tokens, int line_number, MeshFileData& mesh) {
  std::string_view token;
  int count = 0;
  const int64_t vertex = static_cast<int64_t>(mesh.positions.size() / 3);
  while (tokens.Next(token)) {
    float value = 0.0f;
    if (const NumberParse parsed = ParseNumberChecked(token, value); parsed != NumberParse::kOk) {
      if (count < 3) return LineError(line_number, CoordinateProblem(token, parsed, vertex, count));
      return LineError(line_number,
                       "vertex " + std::to_string(vertex) + ": value " + std::to_string(count + 1) +
                           ", " + Quote(token) +
                           (parsed == NumberParse::kOutOfRange ? ", is out of float32 range"
                                                               : ", is not a number"));
    }
    if (count < 3) mesh.positions.push_back(value);
    ++count;
  }
  if (count < 3) {
    return LineError(line_number,
                     "vertex has " + std::to_string(count) + " coordinate(s), expected 3");
  }
  return Status::Ok();
}

// Positive indices may refer to vertices defined later in the file; the largest such index is
// checked once every vertex is known.
struct ForwardReference {
  int64_t largest_index = -1;
  int line = 0;
};

// An "f" statement, appended as a fan of triangles.
Status ParseObjFace(TokenReader& tokens, int line_number, std::vector<int32_t>& corners,
                    ForwardReference& forward, MeshFileData& mesh) {
  corners.clear();
  const int64_t defined = mesh.vertex_count();
  std::string_view token;
  while (tokens.Next(token)) {
    int64_t index = 0;
    if (!ParseCornerVertex(token, index)) {
      return LineError(line_number, "face corner " + Quote(token) +
                                        " is not an index, index/index or index/index/index");
    }
    if (index == 0) return LineError(line_number, "face index 0 is invalid (OBJ counts from 1)");
    int64_t zero_based = index > 0 ? index - 1 : defined + index;
    if (zero_based < 0) {
      return LineError(line_number, "relative face index " + std::to_string(index) +
                                        " reaches before the first vertex");
    }
    if (zero_based > INT32_MAX) {
      return LineError(line_number, "face index " + std::to_string(index) + " is too large");
    }
    if (zero_based >= defined && zero_based > forward.largest_index) {
      forward.largest_index = zero_based;
      forward.line = line_number;
    }
    corners.push_back(static_cast<int32_t>(zero_based));
  }
  if (corners.size() < 3) {
    return LineError(line_number, "face has " + std::to_string(corners.size()) +
                                      " corner(s), at least 3 are needed");
  }
  if (corners.size() > 3) ++mesh.polygons_triangulated;
  AppendFan(corners, mesh);
  return Status::Ok();
}

}  // namespace

StatusOr<MeshFileData> ParseObj(std::string_view text) {
  MeshFileData mesh;
  LineReader lines(text);
  std::string_view line;
  std::vector<int32_t> corners;
  int points_and_lines = 0;
  ForwardReference forward;
  while (lines.Next(line)) {
    line = TrimLeft(line);
    if (line.empty()) continue;
    if (line.front() == '#') {
      ReadFrameRateComment(line, mesh.frame_rate);
      continue;
    }
    TokenReader tokens(line);
    std::string_view keyword;
    tokens.Next(keyword);
    if (keyword == "v") {
      DMC_RETURN_IF_ERROR(ParseObjVertex(tokens, lines.line_number(), mesh));
    } else if (keyword == "f") {
      DMC_RETURN_IF_ERROR(ParseObjFace(tokens, lines.line_number(), corners, forward, mesh));
    } else if (keyword == "l" || keyword == "p") {
      ++points_and_lines;
    } else if (!IsSkippedStatement(keyword)) {
      return LineError(lines.line_number(), "unknown statement " + Quote(keyword));
    }
  }
  if (forward.largest_index >= mesh.vertex_count()) {
    return LineError(forward.line,
                     "face refers to vertex " + std::to_string(forward.largest_index + 1) +
                         " but the file defines " + std::to_string(mesh.vertex_count()));
  }
  if (points_and_lines > 0) {
    mesh.notes.push_back(std::to_string(points_and_lines) +
                         " point ('p') and line ('l') element(s) ignored");
  }
  return mesh;
}

}  // namespace dmc::io_internal
