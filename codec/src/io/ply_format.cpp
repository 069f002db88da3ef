// PLY: the header is parsed here (it decides the path and gives the declared counts), and so are
// the bodies, ASCII and binary (little or big endian), strictly and with the header's layout.
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "io/mesh_formats.h"
#include "io/text_scanner.h"

namespace dmc::io_internal {
namespace {

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
enum class PlyNumber { kInteger, kReal, kUnknown };

// A PLY scalar type: what it holds and how a binary body stores it.
struct PlyType {
  PlyNumber kind = PlyNumber::kUnknown;
  int bytes = 0;
  bool is_signed = false;
};

struct PlyProperty {
  std::string name;
  PlyType value_type = {PlyNumber::kReal, 4, true};
  bool is_list = false;  // the count of a list is always an integer
  PlyType count_type;    // only for lists
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;  // first byte after the "end_header" line
  int body_first_line = 0;
  double frame_rate = 0.0;
};

PlyType TypeOf(std::string_view name) {
  struct Entry {
    std::string_view name;
    PlyType type;
  };
  static constexpr Entry kTypes[] = {
      {"char", {PlyNumber::kInteger, 1, true}},    {"int8", {PlyNumber::kInteger, 1, true}},
      {"uchar", {PlyNumber::kInteger, 1, false}},  {"uint8", {PlyNumber::kInteger, 1, false}},
      {"short", {PlyNumber::kInteger, 2, true}},   {"int16", {PlyNumber::kInteger, 2, true}},
      {"ushort", {PlyNumber::kInteger, 2, false}}, {"uint16", {PlyNumber::kInteger, 2, false}},
      {"int", {PlyNumber::kInteger, 4, true}},     {"int32", {PlyNumber::kInteger, 4, true}},
      {"uint", {PlyNumber::kInteger, 4, false}},   {"uint32", {PlyNumber::kInteger, 4, false}},
      {"float", {PlyNumber::kReal, 4, true}},      {"float32", {PlyNumber::kReal, 4, true}},
      {"double", {PlyNumber::kReal, 8, true}},     {"float64", {PlyNumber::kReal, 8, true}},
  };
  for (const Entry& entry : kTypes) {
    if (entry.name == name) return entry.type;
  }
  return {};
}

Status LineError(int line, const std::string& what) {
  return ParseError("line " + std::to_string(line) + ": " + what);
}

// "format <encoding> 1.0".
Status ParseFormatLine(TokenReader& tokens, int line_number, PlyHeader& header) {
  std::string_view encoding, version;
  if (!tokens.Next(encoding) || !tokens.Next(version) || version != "1.0") {
    return LineError(line_number, "expected 'format <encoding> 1.0'");
  }
  if (encoding == "ascii") {
    header.encoding = PlyEncoding::kAscii;
  } else if (encoding == "binary_little_endian") {
    header.encoding = PlyEncoding::kBinaryLittleEndian;
  } else if (encoding == "binary_big_endian") {
    header.encoding = PlyEncoding::kBinaryBigEndian;
  } else {
    return LineError(line_number, "unknown PLY encoding " + Quote(encoding));
  }
  return Status::Ok();
}

// "element <name> <count>".
Status ParseElementLine(TokenReader& tokens, int line_number, PlyHeader& header) {
  PlyElement element;
  std::string_view name, token;
  if (!tokens.Next(name) || !tokens.Next(token) || !ParseNumber(token, element.count) ||
      element.count < 0 || element.count > INT32_MAX / 3) {
    return LineError(line_number, "expected 'element <name> <count>'");
  }
  element.name = std::string(name);
  header.elements.push_back(std::move(element));
  return Status::Ok();
}

// "property <type> <name>" or "property list <count type> <type> <name>", of the last element.
Status ParsePropertyLine(TokenReader& tokens, int line_number, PlyHeader& header) {
  if (header.elements.empty()) return LineError(line_number, "property before any element");
  PlyProperty property;
  std::string_view type, name;
  if (!tokens.Next(type)) return LineError(line_number, "property without a type");
  if (type == "list") {
    std::string_view count_type;
    property.is_list = true;
    if (tokens.Next(count_type)) property.count_type = TypeOf(count_type);
    if (property.count_type.kind != PlyNumber::kInteger || !tokens.Next(type)) {
      return LineError(line_number, "expected 'property list <integer type> <type> <name>'");
    }
  }
  property.value_type = TypeOf(type);
  if (property.value_type.kind == PlyNumber::kUnknown || !tokens.Next(name)) {
    return LineError(line_number, "expected 'property <type> <name>' with a PLY type");
  }
  property.name = std::string(name);
  header.elements.back().properties.push_back(std::move(property));
  return Status::Ok();
}

// "comment dmc frame_rate 25" (written by WriteSequence); other comments are ignored.
void ReadFrameRateComment(TokenReader& tokens, PlyHeader& header) {
  std::string_view word, value;
  double parsed = 0.0;
  if (tokens.Next(word) && word == "dmc" && tokens.Next(word) && word == "frame_rate" &&
      tokens.Next(value) && ParseNumber(value, parsed) && parsed > 0.0) {
    header.frame_rate = parsed;
  }
}

StatusOr<PlyHeader> ParsePlyHeader(std::string_view bytes) {
  PlyHeader header;
  LineReader lines(bytes);
  std::string_view line;
  if (!lines.Next(line) || line != "ply") {
    return ParseError("line 1: expected the PLY magic 'ply'");
  }
  bool have_format = false;
  while (true) {
    if (!lines.Next(line)) return ParseError("the header has no 'end_header' line");
    // Control characters inside a header line (a stray '\r', say) are rejected: other readers
    // tokenise them differently (OpenMesh's as white space), so the file means different things
    // to different programs.
    for (const char c : line) {
      if (static_cast<unsigned char>(c) < 0x20 && c != '\t') {
        return LineError(lines.line_number(), "control character in the PLY header");
      }
    }
    TokenReader tokens(line);
    std::string_view keyword;
    if (!tokens.Next(keyword)) continue;
    if (keyword == "end_header") break;
    if (keyword == "comment") {
      ReadFrameRateComment(tokens, header);
    } else if (keyword == "obj_info") {
      continue;
    } else if (keyword == "format") {
      DMC_RETURN_IF_ERROR(ParseFormatLine(tokens, lines.line_number(), header));
      have_format = true;
    } else if (keyword == "element") {
      DMC_RETURN_IF_ERROR(ParseElementLine(tokens, lines.line_number(), header));
    } else if (keyword == "property") {
      DMC_RETURN_IF_ERROR(ParsePropertyLine(tokens, lines.line_number(), header));
    } else {
      return LineError(lines.line_number(), "unknown header line " + Quote(keyword));
    }
  }
  if (!have_format) return ParseError("the header has no 'format' line");
  for (const std::string_view name : {"vertex", "face"}) {
    if (std::count_if(header.elements.begin(), header.elements.end(),
                      [&](const PlyElement& element) { return element.name == name; }) > 1) {
      return ParseError("the header declares element '" + std::string(name) + "' more than once");
    }
  }
  for (const PlyElement& element : header.elements) {
    // Such an element occupies no bytes, so its count is not bounded by the file's size.
    if (element.count > 0 && element.properties.empty()) {
      return ParseError("element '" + element.name + "' declares " + std::to_string(element.count) +
                        " entries but no properties");
    }
  }
  header.body_offset = lines.position();
  header.body_first_line = lines.line_number() + 1;
  return header;
}

// What both body parsers take from a property: the vertex coordinate it holds (0, 1, 2 for x, y,
// z; -1 for none), or whether it is a face's corner list.
int CoordinateAxis(const PlyElement& element, const PlyProperty& property) {
  if (element.name != "vertex" || property.is_list || property.name.size() != 1) return -1;
  const size_t found = std::string_view("xyz").find(property.name[0]);
  return found == std::string_view::npos ? -1 : static_cast<int>(found);
}
bool IsCornerList(const PlyElement& element, const PlyProperty& property) {
  return element.name == "face" && property.is_list &&
         (property.name == "vertex_indices" || property.name == "vertex_index");
}
int64_t DeclaredVertexCount(const PlyHeader& header) {
  int64_t count = 0;
  for (const PlyElement& element : header.elements) {
    if (element.name == "vertex") count = element.count;
  }
  return count;
}

// Tokens of an ASCII body, across lines, with the line each came from.
class BodyTokens {
 public:
  BodyTokens(std::string_view body, int first_line)
      : lines_(body), first_line_(first_line), tokens_("") {}

  bool Next(std::string_view& token) {
    while (!tokens_.Next(token)) {
      std::string_view line;
      if (!lines_.Next(line)) return false;
      tokens_ = TokenReader(line);
    }
    return true;
  }
  int line() const { return first_line_ + std::max(lines_.line_number() - 1, 0); }

 private:
  LineReader lines_;
  int first_line_;
  TokenReader tokens_;
};

// The values of one property of entry `index` of `element`: vertex coordinates into
// mesh.positions, a face's corner list fanned into mesh.triangles, anything else checked and
// dropped.
Status ParseAsciiProperty(BodyTokens& tokens, const PlyElement& element, int64_t index,
                          const PlyProperty& property, int64_t vertex_count,
                          std::vector<int32_t>& corners, MeshFileData& mesh) {
  std::string_view token;
  int64_t values = 1;
  if (property.is_list) {
    if (!tokens.Next(token)) {
      return ParseError("the body ends inside element '" + element.name + "' " +
                        std::to_string(index) + " of " + std::to_string(element.count));
    }
    if (!ParseNumber(token, values) || values < 0) {
      return LineError(tokens.line(), "list count " + Quote(token) + " of property '" +
                                          property.name + "' is not a non-negative integer");
    }
  }
  const bool is_corner_list = IsCornerList(element, property);
  const int axis = CoordinateAxis(element, property);
  for (int64_t k = 0; k < values; ++k) {
    if (!tokens.Next(token)) {
      return ParseError("the body ends inside element '" + element.name + "' " +
                        std::to_string(index) + " of " + std::to_string(element.count));
    }
    bool ok = false;
    if (axis >= 0) {
      const NumberParse parsed = ParseNumberChecked(
          token, mesh.positions[static_cast<size_t>(index) * 3 + static_cast<size_t>(axis)]);
      if (parsed != NumberParse::kOk) {
        return LineError(tokens.line(), CoordinateProblem(token, parsed, index, axis));
      }
      ok = true;
    } else if (property.value_type.kind == PlyNumber::kInteger) {
      int64_t value = 0;
      ok = ParseNumber(token, value);
      if (ok && is_corner_list) {
        if (value < 0 || value >= vertex_count) {
          return LineError(tokens.line(),
                           "face index " + std::to_string(value) + " is outside [0, " +
                               std::to_string(std::max<int64_t>(vertex_count, 0)) + ")");
        }
        corners.push_back(static_cast<int32_t>(value));
      }
    } else {
      double value = 0.0;
      ok = ParseNumber(token, value);
    }
    if (!ok) {
      return LineError(
          tokens.line(),
          "value " + Quote(token) + " of property '" + property.name + "' is not " +
              (property.value_type.kind == PlyNumber::kInteger ? "an integer" : "a number"));
    }
  }
  if (is_corner_list) {
    if (corners.size() < 3) {
      return LineError(tokens.line(), "face has " + std::to_string(corners.size()) +
                                          " corner(s), at least 3 are needed");
    }
    if (corners.size() > 3) ++mesh.polygons_triangulated;
    AppendFan(corners, mesh);
  }
  return Status::Ok();
}

StatusOr<MeshFileData> ParseAsciiBody(std::string_view body, const PlyHeader& header) {
  MeshFileData mesh;
  BodyTokens tokens(body, header.body_first_line);
  std::vector<int32_t> corners;
  const int64_t vertex_count = DeclaredVertexCount(header);
  // Coordinates come from the file: grow with what is actually read rather than trusting the
  // declared count with one big allocation.
  mesh.positions.reserve(std::min<size_t>(static_cast<size_t>(vertex_count) * 3, size_t{1} << 22));
  for (const PlyElement& element : header.elements) {
    for (int64_t i = 0; i < element.count; ++i) {
      corners.clear();
      if (element.name == "vertex") mesh.positions.resize(mesh.positions.size() + 3, 0.0f);
      for (const PlyProperty& property : element.properties) {
        DMC_RETURN_IF_ERROR(
            ParseAsciiProperty(tokens, element, i, property, vertex_count, corners, mesh));
      }
    }
  }
  std::string_view extra;
  if (tokens.Next(extra)) {
    return LineError(tokens.line(), "unexpected content after the last declared element");
  }
  return mesh;
}

// A binary PLY body, read front to back with the header's byte order. Every read is preceded by
// a check of what is left, so nothing is read past the end.
class BinaryBody {
 public:
  BinaryBody(std::string_view body, bool big_endian) : body_(body), big_endian_(big_endian) {}

  size_t remaining() const { return body_.size() - at_; }
  void Skip(size_t bytes) { at_ += bytes; }

  // The scalar of `type` at the cursor, as a double; the caller checked that it is there.
  // Integers are exact: no PLY integer type is wider than 32 bits.
  double Value(const PlyType& type) {
    const int bytes = type.bytes;
    const uint64_t raw = Raw(bytes);
    if (type.kind == PlyNumber::kReal) {
      return bytes == 8 ? std::bit_cast<double>(raw)
                        : static_cast<double>(std::bit_cast<float>(static_cast<uint32_t>(raw)));
    }
    if (type.is_signed && (raw >> (bytes * 8 - 1)) != 0) {
      return static_cast<double>(static_cast<int64_t>(raw) - (int64_t{1} << (bytes * 8)));
    }
    return static_cast<double>(raw);
  }
  int64_t Integer(const PlyType& type) { return static_cast<int64_t>(Value(type)); }

 private:
  uint64_t Raw(int bytes) {
    uint64_t raw = 0;
    for (int i = 0; i < bytes; ++i) {
      const int byte_index = big_endian_ ? i : bytes - 1 - i;
      raw = (raw << 8) | static_cast<unsigned char>(body_[at_ + static_cast<size_t>(byte_index)]);
    }
    at_ += static_cast<size_t>(bytes);
    return raw;
  }

  std::string_view body_;
  size_t at_ = 0;
  bool big_endian_;
};

// The binary body, with the header's layout: vertex coordinates into mesh.positions (any PLY
// type, rounded to float), face corner lists fanned into mesh.triangles, everything else skipped.
// The body must hold exactly the declared elements. This is dmc's own reader rather than
// OpenMesh's: OpenMesh's does not stop at the end of its input (with a short body it keeps adding
// the declared vertices, and lists of whatever length the bytes past the end decode to) and
// tokenises the header its own way, so any header the two read differently handed it a layout
// nobody had checked (ply_fuzz ran it out of memory that way). One reader means one reading of
// the header. OpenMesh stays the oracle of the tests on well-formed files.
StatusOr<MeshFileData> ParseBinaryBody(std::string_view bytes, const PlyHeader& header) {
  BinaryBody body(bytes.substr(header.body_offset),
                  header.encoding == PlyEncoding::kBinaryBigEndian);
  MeshFileData mesh;
  const int64_t vertex_count = DeclaredVertexCount(header);
  // Grow with what is read rather than trusting the declared count with one big allocation.
  mesh.positions.reserve(std::min<size_t>(static_cast<size_t>(vertex_count) * 3, size_t{1} << 22));
  std::vector<int32_t> corners;
  for (const PlyElement& element : header.elements) {
    const bool is_vertex = element.name == "vertex";
    for (int64_t i = 0; i < element.count; ++i) {
      if (is_vertex) mesh.positions.resize(mesh.positions.size() + 3, 0.0f);
      for (const PlyProperty& property : element.properties) {
        const auto truncated = [&] {
          return ParseError("the binary PLY body ends inside element '" + element.name + "' " +
                            std::to_string(i) + " of " + std::to_string(element.count) +
                            " (property '" + property.name + "')");
        };
        uint64_t values = 1;
        if (property.is_list) {
          if (body.remaining() < static_cast<size_t>(property.count_type.bytes)) return truncated();
          const int64_t count = body.Integer(property.count_type);
          if (count < 0) {
            return ParseError("element '" + element.name + "' " + std::to_string(i) + ": list '" +
                              property.name + "' has a negative length " + std::to_string(count));
          }
          values = static_cast<uint64_t>(count);
        }
        const size_t value_bytes = static_cast<size_t>(property.value_type.bytes);
        if (values > body.remaining() / value_bytes) return truncated();

        const int axis = CoordinateAxis(element, property);
        if (axis >= 0) {
          const double value = body.Value(property.value_type);
          // Rounded to float below, a double beyond float32 would become infinite (and be
          // reported as "not finite"); it is named as what it is.
          if (std::isfinite(value) && std::fabs(value) > std::numeric_limits<float>::max()) {
            return ParseError(fmt::format(
                "vertex {}, coordinate {}: {} is out of float32 range (at most 3.4028235e+38 in "
                "magnitude)",
                i, property.name, value));
          }
          mesh.positions[static_cast<size_t>(i) * 3 + static_cast<size_t>(axis)] =
              static_cast<float>(value);
        } else if (IsCornerList(element, property)) {
          if (property.value_type.kind != PlyNumber::kInteger) {
            return ParseError("face " + std::to_string(i) + ": the corner list '" + property.name +
                              "' has a real type, vertex indices are integers");
          }
          corners.clear();
          for (uint64_t k = 0; k < values; ++k) {
            const double index = body.Value(property.value_type);
            if (index < 0 || index >= static_cast<double>(vertex_count)) {
              return ParseError(fmt::format("face {} refers to vertex {}, outside [0, {})", i,
                                            index, vertex_count));
            }
            corners.push_back(static_cast<int32_t>(index));
          }
          if (corners.size() < 3) {
            return ParseError("face " + std::to_string(i) + " has " +
                              std::to_string(corners.size()) + " corner(s), at least 3 are needed");
          }
          if (corners.size() > 3) ++mesh.polygons_triangulated;
          AppendFan(corners, mesh);
        } else {
          body.Skip(static_cast<size_t>(values) * value_bytes);
        }
      }
    }
  }
  if (body.remaining() != 0) {
    return ParseError("the binary PLY body has " + std::to_string(body.remaining()) +
                      " byte(s) after the last declared element");
  }
  return mesh;
}

}  // namespace

StatusOr<MeshFileData> ParsePly(std::string_view bytes) {
  DMC_ASSIGN_OR_RETURN(const PlyHeader header, ParsePlyHeader(bytes));
  const PlyElement* vertices = nullptr;
  for (const PlyElement& element : header.elements) {
    if (element.name == "vertex") vertices = &element;
  }
  if (vertices == nullptr) return ParseError("the header declares no 'vertex' element");
  for (char axis : {'x', 'y', 'z'}) {
    const bool found = std::any_of(
        vertices->properties.begin(), vertices->properties.end(),
        [&](const PlyProperty& p) { return !p.is_list && p.name == std::string(1, axis); });
    if (!found) {
      return ParseError(std::string("the 'vertex' element has no scalar property '") + axis + "'");
    }
  }
  StatusOr<MeshFileData> mesh = header.encoding == PlyEncoding::kAscii
                                    ? ParseAsciiBody(bytes.substr(header.body_offset), header)
                                    : ParseBinaryBody(bytes, header);
  if (mesh.ok()) mesh->frame_rate = header.frame_rate;
  return mesh;
}

}  // namespace dmc::io_internal
