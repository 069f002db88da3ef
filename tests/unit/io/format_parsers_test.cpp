// Parsing single OBJ, OFF and PLY files through ReadSequence: order kept exactly (including the
// cases OpenMesh's importer changes: isolated vertices, repeated corners, non-manifold edges),
// polygons fan-triangulated with a warning, and every malformed input rejected with its line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "dmc/io.h"
#include "io_test_util.h"

namespace dmc {
namespace {

using ::testing::HasSubstr;
using testing::ScratchDir;
using testing::WriteText;

// Writes `text` as `name` in the scratch directory and reads it as a 1-frame sequence.
StatusOr<MeshSequence> ReadText(const ScratchDir& dir, const std::string& name,
                                std::string_view text, ReadReport* report = nullptr) {
  WriteText(dir / name, text);
  return ReadSequence(dir / name, {}, report);
}

Triangles MakeTriangles(std::initializer_list<std::array<int32_t, 3>> rows) {
  Triangles triangles(static_cast<Eigen::Index>(rows.size()), 3);
  int r = 0;
  for (const auto& row : rows) triangles.row(r++) << row[0], row[1], row[2];
  return triangles;
}

// Vertex 4 is isolated, triangle 1 repeats a corner, edge (0,1) has three triangles: a halfedge
// importer would drop, duplicate or reorder here; the file order must come back unchanged.
constexpr std::string_view kAwkwardObj =
    "# awkward but legal\r\n"
    "o thing\r\n"
    "v 0 0 0\r\n"
    "v 1 0 0\r\n"
    "v 0 1 0\r\n"
    "v 0 0 1\r\n"
    "v 5 5 5\r\n"
    "v +1.5e-3 -2.25E+2 0.1\r\n"
    "vn 0 0 1\r\n"
    "vt 0.5 0.5\r\n"
    "g group\r\n"
    "s off\r\n"
    "usemtl none\r\n"
    "f 1 2 3\r\n"
    "f 1 1 2\r\n"
    "f 2/1/1 1/1/1 4/1/1\r\n"
    "f 1//1 2//1 6//1\r\n"
    "f -6 -5 -3\r\n";

TEST(ObjParserTest, KeepsVertexAndTriangleOrderExactly) {
  ScratchDir dir;
  ReadReport report;
  auto sequence = ReadText(dir, "awkward.obj", kAwkwardObj, &report);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  EXPECT_EQ(sequence->vertex_count(), 6);
  EXPECT_EQ(sequence->frame_count(), 1);
  EXPECT_EQ(sequence->triangles(),
            MakeTriangles({{0, 1, 2}, {0, 0, 1}, {1, 0, 3}, {0, 1, 5}, {0, 1, 3}}));
  const auto frame = sequence->frame(0);
  EXPECT_EQ(frame(4, 0), 5.0f);  // isolated vertex kept in place
  EXPECT_EQ(frame(5, 0), 1.5e-3f);
  EXPECT_EQ(frame(5, 1), -225.0f);
  EXPECT_EQ(frame(5, 2), 0.1f);  // correctly rounded to the nearest float
  EXPECT_EQ(sequence->name, "awkward");
  // The repeated-corner triangle is reported as degenerate, not dropped.
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_THAT(report.warnings[0], HasSubstr("1 degenerate triangle(s)"));
}

TEST(ObjParserTest, FanTriangulatesPolygonsWithAWarning) {
  ScratchDir dir;
  ReadReport report;
  auto sequence = ReadText(dir, "poly.obj",
                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\n"
                           "f 1 2 3 4\nf 1 4 5\nf 1 2 3 4 5\n",
                           &report);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  EXPECT_EQ(sequence->triangles(),
            MakeTriangles({{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 1, 2}, {0, 2, 3}, {0, 3, 4}}));
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_THAT(report.warnings[0], HasSubstr("poly.obj): 2 face(s) with more than 3 corners "
                                            "fan-triangulated (6 triangles in all)"));
}

struct BadInput {
  std::string text;
  ErrorCode code;
  std::string message;  // expected substring, after "<path>"
};
// Test names show the expected error rather than the struct's bytes.
void PrintTo(const BadInput& input, std::ostream* out) { *out << input.message; }

class ObjErrorTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(ObjErrorTest, NamesFileAndLine) {
  ScratchDir dir;
  auto sequence = ReadText(dir, "bad.obj", GetParam().text);
  ASSERT_FALSE(sequence.ok());
  EXPECT_EQ(sequence.status().code(), GetParam().code) << sequence.status().ToString();
  EXPECT_THAT(sequence.status().message(),
              HasSubstr((dir / "bad.obj").string() + GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, ObjErrorTest,
    ::testing::Values(
        BadInput{"v 0 0 0\nv 1 2\n", ErrorCode::kParseError,
                 ":2: vertex has 2 coordinate(s), expected 3"},
        BadInput{"v 0 0 0\nv 1 0 abc\n", ErrorCode::kParseError,
                 ":2: vertex 1, coordinate z: 'abc' is not a number"},
        // Well-formed but beyond float32: not "not a number" (issue 21).
        BadInput{"v 0 0 0\nv 1 1e300 0\n", ErrorCode::kParseError,
                 ":2: vertex 1, coordinate y: '1e300' is out of float32 range (at most "
                 "3.4028235e+38 in magnitude)"},
        BadInput{"v -3.5e38 0 0\n", ErrorCode::kParseError,
                 ":1: vertex 0, coordinate x: '-3.5e38' is out of float32 range"},
        BadInput{"v 0 0 0 1e39\n", ErrorCode::kParseError,
                 ":1: vertex 0: value 4, '1e39', is out of float32 range"},
        BadInput{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", ErrorCode::kParseError,
                 ":4: face refers to vertex 9 but the file defines 3"},
        BadInput{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 0 2\n", ErrorCode::kParseError,
                 ":4: face index 0 is invalid (OBJ counts from 1)"},
        BadInput{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n", ErrorCode::kParseError,
                 ":4: relative face index -4 reaches before the first vertex"},
        BadInput{"v 0 0 0\nv 1 0 0\nf 1 2\n", ErrorCode::kParseError,
                 ":3: face has 2 corner(s), at least 3 are needed"},
        BadInput{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/x 2 3\n", ErrorCode::kParseError,
                 ":4: face corner '1/x' is not an index"},
        BadInput{"v 0 0 0\nvv 1 2 3\n", ErrorCode::kParseError, ":2: unknown statement 'vv'"},
        BadInput{"v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n", ErrorCode::kInvalidSequence,
                 "), vertex 2: coordinate z is not finite"},
        BadInput{"# nothing\n", ErrorCode::kInvalidSequence, ": the sequence has no vertices"}));

TEST(OffParserTest, ReadsVariantsAndKeepsOrder) {
  ScratchDir dir;
  // Counts on the header line, comments, per-vertex colour (COFF), per-face colour, a quad.
  auto sequence = ReadText(dir, "mesh.off",
                           "COFF 5 3 0 # counts on the header line\n"
                           "# a comment line\n"
                           "0 0 0 255 0 0 255\n"
                           "1 0 0 255 0 0 255\n"
                           "\n"
                           "1 1 0 255 0 0 255\n"
                           "0 1 0 255 0 0 255\n"
                           "9 9 9 255 0 0 255\n"
                           "3 0 1 2 0.5 0.5 0.5\n"
                           "3 0 0 1\n"
                           "4 0 1 2 3\n");
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  EXPECT_EQ(sequence->vertex_count(), 5);
  EXPECT_EQ(sequence->triangles(), MakeTriangles({{0, 1, 2}, {0, 0, 1}, {0, 1, 2}, {0, 2, 3}}));
  EXPECT_EQ(sequence->frame(0)(4, 2), 9.0f);
}

class OffErrorTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(OffErrorTest, NamesFileAndLine) {
  ScratchDir dir;
  auto sequence = ReadText(dir, "bad.off", GetParam().text);
  ASSERT_FALSE(sequence.ok());
  EXPECT_EQ(sequence.status().code(), GetParam().code) << sequence.status().ToString();
  EXPECT_THAT(sequence.status().message(),
              HasSubstr((dir / "bad.off").string() + GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, OffErrorTest,
    ::testing::Values(
        BadInput{"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", ErrorCode::kParseError,
                 ": the file ends after 1 of 2 faces"},
        BadInput{"OFF\n3 1 0\n0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n", ErrorCode::kParseError,
                 ":4: vertex 1, coordinate z: 'x' is not a number"},
        BadInput{"OFF\n3 1 0\n0 0 0\n1 0 0\n0 -1e39 0\n3 0 1 2\n", ErrorCode::kParseError,
                 ":5: vertex 2, coordinate y: '-1e39' is out of float32 range"},
        BadInput{"OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", ErrorCode::kParseError,
                 ":4: vertex has 2 coordinate(s), expected 3"},
        BadInput{"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", ErrorCode::kParseError,
                 ":6: face index 7 is outside [0, 3)"},
        BadInput{"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", ErrorCode::kParseError,
                 ":6: face declares 4 corners but lists 3"},
        BadInput{"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n", ErrorCode::kParseError,
                 ":7: unexpected content after the last declared face"},
        BadInput{"OFF\nthree 1 0\n", ErrorCode::kParseError,
                 ":2: expected 'vertices faces [edges]' counts"},
        BadInput{"PLY\n", ErrorCode::kParseError, ":1: expected an OFF header, found 'PLY'"},
        BadInput{"4OFF\n1 0 0\n0 0 0 0\n", ErrorCode::kUnsupported,
                 ":1: 4OFF (not 3D) is not supported"},
        BadInput{"OFF BINARY\n", ErrorCode::kUnsupported, ": binary OFF is not supported"}));

constexpr std::string_view kPlyHeaderAndVertices =
    "ply\n"
    "format ascii 1.0\n"
    "comment extra properties and elements must be skipped\n"
    "element vertex 4\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property uchar red\n"
    "property list uchar float extra\n"
    "element face 2\n"
    "property list uchar int vertex_index\n"
    "property float quality\n"
    "element edge 1\n"
    "property int vertex1\n"
    "property int vertex2\n"
    "end_header\n"
    "0 0 0 255 0\n"
    "1 0 0 255 2 0.5 0.5\n"
    "1 1 0 255 0\n"
    "0 1 0.25 255 1 7\n";

TEST(PlyParserTest, ReadsAsciiWithExtraPropertiesAndElements) {
  ScratchDir dir;
  ReadReport report;
  auto sequence =
      ReadText(dir, "mesh.ply",
               std::string(kPlyHeaderAndVertices) + "4 0 1 2 3 1.0\n3 3 2 1 0.5\n0 1\n", &report);
  ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
  EXPECT_EQ(sequence->triangles(), MakeTriangles({{0, 1, 2}, {0, 2, 3}, {3, 2, 1}}));
  EXPECT_EQ(sequence->frame(0)(3, 2), 0.25f);
  EXPECT_EQ(sequence->frame(0)(1, 0), 1.0f);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_THAT(report.warnings[0], HasSubstr("1 face(s) with more than 3 corners"));
}

class PlyErrorTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(PlyErrorTest, NamesFileAndLine) {
  ScratchDir dir;
  auto sequence = ReadText(dir, "bad.ply", GetParam().text);
  ASSERT_FALSE(sequence.ok());
  EXPECT_EQ(sequence.status().code(), GetParam().code) << sequence.status().ToString();
  EXPECT_THAT(sequence.status().message(),
              HasSubstr((dir / "bad.ply").string() + GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, PlyErrorTest,
    ::testing::Values(
        // OpenMesh's ASCII reader accepts both of these and invents values.
        BadInput{std::string(kPlyHeaderAndVertices) + "3 0 1 2 1.0\n", ErrorCode::kParseError,
                 ": the body ends inside element 'face' 1 of 2"},
        BadInput{std::string(kPlyHeaderAndVertices) + "3 0 1 abc 1.0\n3 0 1 2 0\n0 1\n",
                 ErrorCode::kParseError,
                 ":21: value 'abc' of property 'vertex_index' is not an integer"},
        BadInput{std::string(kPlyHeaderAndVertices) + "3 0 1 4 1.0\n3 0 1 2 0\n0 1\n",
                 ErrorCode::kParseError, ":21: face index 4 is outside [0, 4)"},
        BadInput{std::string(kPlyHeaderAndVertices) + "3 0 1 2 1.0\n3 0 1 2 0\n0 1\n5\n",
                 ErrorCode::kParseError, ":24: unexpected content after the last declared element"},
        BadInput{"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
                 ErrorCode::kParseError, ": the 'vertex' element has no scalar property 'y'"},
        BadInput{"ply\nformat ascii 2.0\nend_header\n", ErrorCode::kParseError,
                 ":2: expected 'format <encoding> 1.0'"},
        BadInput{"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
                 ErrorCode::kParseError, ": the header has no 'end_header' line"},
        BadInput{"solid stl\n", ErrorCode::kParseError, ":1: expected the PLY magic 'ply'"},
        BadInput{"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                 "property double z\nend_header\n0 0 1e300\n",
                 ErrorCode::kParseError,
                 ":8: vertex 0, coordinate z: '1e300' is out of float32 range"}));

// A binary PLY with double coordinates, an ignored uchar and a quad, built by hand.
std::string BinaryPly(bool big_endian, bool truncate) {
  std::string out = std::string("ply\nformat ") +
                    (big_endian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                    "property double z\nproperty uchar red\nelement face 2\n"
                    "property list uchar int vertex_indices\nend_header\n";
  auto put = [&](auto value) {
    char bytes[sizeof(value)];
    std::memcpy(bytes, &value, sizeof(value));
    if (big_endian) std::reverse(bytes, bytes + sizeof(value));
    out.append(bytes, sizeof(value));
  };
  const double coordinates[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0.1, 1, -2.5}};
  for (const auto& vertex : coordinates) {
    for (double c : vertex) put(c);
    put(uint8_t{200});
  }
  put(uint8_t{4});
  for (int32_t index : {0, 1, 2, 3}) put(index);
  put(uint8_t{3});
  for (int32_t index : {3, 2, 0}) put(index);
  if (truncate) out.resize(out.size() - 5);
  return out;
}

TEST(PlyParserTest, ReadsBinaryLittleAndBigEndian) {
  for (bool big_endian : {false, true}) {
    ScratchDir dir;
    auto sequence = ReadText(dir, "binary.ply", BinaryPly(big_endian, false));
    ASSERT_TRUE(sequence.ok()) << sequence.status().ToString();
    EXPECT_EQ(sequence->triangles(), MakeTriangles({{0, 1, 2}, {0, 2, 3}, {3, 2, 0}}));
    EXPECT_EQ(sequence->frame(0)(3, 0), 0.1f);  // double rounded to the nearest float
    EXPECT_EQ(sequence->frame(0)(3, 2), -2.5f);
  }
}

TEST(PlyParserTest, NamesABinaryDoubleBeyondFloat32) {
  for (bool big_endian : {false, true}) {
    ScratchDir dir;
    std::string text = BinaryPly(big_endian, false);
    // Vertex 2's y: each vertex is three doubles and a uchar.
    const size_t at = text.find("end_header\n") + 11 + 2 * 25 + 8;
    char bytes[8];
    const double huge = -1e300;
    std::memcpy(bytes, &huge, sizeof bytes);
    if (big_endian) std::reverse(bytes, bytes + 8);
    text.replace(at, 8, bytes, 8);
    auto sequence = ReadText(dir, "huge.ply", text);
    ASSERT_FALSE(sequence.ok());
    EXPECT_EQ(sequence.status().code(), ErrorCode::kParseError);
    EXPECT_THAT(sequence.status().message(),
                HasSubstr("huge.ply: vertex 2, coordinate y: -1e+300 is out of float32 range"));
  }
}

TEST(TextParsersTest, NumbersTooSmallForFloat32RoundToZero) {
  // As strtof rounds them: a zero of the number's sign, not an error.
  ScratchDir dir;
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"tiny.obj", "v 0 0 0\nv 1 0 0\nv 0 1 -1e-300\nf 1 2 3\n"},
           {"tiny.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 -1e-300\n3 0 1 2\n"},
           {"tiny.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 -1e-300\n3 0 1 2\n"}}) {
    auto sequence = ReadText(dir, name, text);
    ASSERT_TRUE(sequence.ok()) << name << ": " << sequence.status().ToString();
    EXPECT_EQ(sequence->frame(0)(2, 2), 0.0f) << name;
    EXPECT_TRUE(std::signbit(sequence->frame(0)(2, 2))) << name;
  }
}

TEST(GltfReaderTest, NamesAPosedPositionBeyondFloat32) {
  // One triangle whose node translation takes it beyond float32 (the accessor itself is float).
  ScratchDir dir;
  auto sequence = ReadText(dir, "far.gltf",
                           R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
          "nodes": [{"mesh": 0, "translation": [0, 1e300, 0]}],
          "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
          "buffers": [{"byteLength": 44, "uri":
            "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
          "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
          "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})");
  ASSERT_FALSE(sequence.ok());
  EXPECT_EQ(sequence.status().code(), ErrorCode::kInvalidSequence);
  EXPECT_THAT(sequence.status().message(),
              HasSubstr("far.gltf: frame 0: vertex 0, coordinate y: the posed value 1e+300 is "
                        "out of float32 range"));
}

TEST(PlyParserTest, RejectsTruncatedBinary) {
  ScratchDir dir;
  auto sequence = ReadText(dir, "cut.ply", BinaryPly(false, true));
  ASSERT_FALSE(sequence.ok());
  EXPECT_EQ(sequence.status().code(), ErrorCode::kParseError);
  EXPECT_THAT(sequence.status().message(),
              HasSubstr("cut.ply: the binary PLY body ends inside element 'face' 1 of 2"));
}

// Hostile binary headers: each declares more than the body holds, or something that no layout
// can hold, and must be refused before anything is allocated for it, with an error naming it.
struct HostileBinaryPly {
  std::string header_and_body;
  std::string expected_message;
};
void PrintTo(const HostileBinaryPly& input, std::ostream* out) { *out << input.expected_message; }

class PlyBinaryLayoutTest : public ::testing::TestWithParam<HostileBinaryPly> {};

TEST_P(PlyBinaryLayoutTest, IsRefusedWithANamedError) {
  ScratchDir dir;
  auto sequence = ReadText(dir, "hostile.ply", GetParam().header_and_body);
  ASSERT_FALSE(sequence.ok());
  EXPECT_EQ(sequence.status().code(), ErrorCode::kParseError);
  EXPECT_THAT(sequence.status().message(), HasSubstr(GetParam().expected_message));
}

const std::string kBinaryVertexHeader =
    "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
    "property float y\nproperty float z\n";

INSTANTIATE_TEST_SUITE_P(
    Hostile, PlyBinaryLayoutTest,
    ::testing::Values(
        // 700 million vertices declared, twelve bytes given.
        HostileBinaryPly{"ply\nformat binary_little_endian 1.0\nelement vertex 700000000\n"
                         "property float x\nproperty float y\nproperty float z\nend_header\n" +
                             std::string(12, '\0'),
                         "ends inside element 'vertex' 1 of 700000000"},
        // A face list claiming 2^31 - 1 corners.
        HostileBinaryPly{kBinaryVertexHeader +
                             "element face 1\nproperty list int int vertex_indices\nend_header\n" +
                             std::string(12, '\0') + std::string("\xff\xff\xff\x7f", 4),
                         "ends inside element 'face' 0 of 1 (property 'vertex_indices')"},
        HostileBinaryPly{kBinaryVertexHeader +
                             "element face 1\nproperty list int int vertex_indices\nend_header\n" +
                             std::string(12, '\0') + std::string("\xff\xff\xff\xff", 4),
                         "list 'vertex_indices' has a negative length -1"},
        // Entries without properties occupy no bytes, so nothing bounds their count.
        HostileBinaryPly{
            kBinaryVertexHeader + "element face 600000000\nend_header\n" + std::string(12, '\0'),
            "element 'face' declares 600000000 entries but no properties"},
        HostileBinaryPly{kBinaryVertexHeader + "end_header\n" + std::string(13, '\0'),
                         "1 byte(s) after the last declared element"},
        HostileBinaryPly{
            kBinaryVertexHeader +
                "element face 1\nproperty list uchar uint vertex_indices\nend_header\n" +
                std::string(12, '\0') + std::string("\x03\0\0\0\0\0\0\0\0\xff\xff\xff\xff", 13),
            "face 0 refers to vertex 4294967295, outside [0, 1)"},
        HostileBinaryPly{
            kBinaryVertexHeader +
                "element face 1\nproperty list uchar float vertex_indices\nend_header\n" +
                std::string(12, '\0') + std::string("\x03", 1) + std::string(12, '\0'),
            "face 0: the corner list 'vertex_indices' has a real type"},
        HostileBinaryPly{
            kBinaryVertexHeader +
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                std::string(12, '\0') + std::string("\x02", 1) + std::string(8, '\0'),
            "face 0 has 2 corner(s), at least 3 are needed"},
        // Two vertex elements: which one the faces index is anybody's guess.
        HostileBinaryPly{kBinaryVertexHeader + "element vertex 1\nproperty float x\nend_header\n" +
                             std::string(16, '\0'),
                         "the header declares element 'vertex' more than once"}));

// Every PLY scalar type as a coordinate, both byte orders: integers are converted exactly, a
// signed byte keeps its sign, float is taken as is.
TEST(PlyParserTest, ReadsEveryScalarTypeAsACoordinate) {
  struct Case {
    std::string type;
    std::string little_endian_bytes;
    float expected;
  };
  const std::vector<Case> cases = {
      {"char", "\xfe", -2.0f},
      {"uchar", "\xfe", 254.0f},
      {"short", std::string("\x00\x80", 2), -32768.0f},
      {"ushort", std::string("\x00\x80", 2), 32768.0f},
      {"int", std::string("\xff\xff\xff\xff", 4), -1.0f},
      {"uint32", std::string("\xff\xff\xff\xff", 4), 4294967295.0f},
      {"float32", std::string("\x00\x00\xc0\x3f", 4), 1.5f},
      {"float64", std::string("\x00\x00\x00\x00\x00\x00\x04\xc0", 8), -2.5f},
  };
  for (const Case& c : cases) {
    for (bool big_endian : {false, true}) {
      std::string value = c.little_endian_bytes;
      if (big_endian) std::reverse(value.begin(), value.end());
      const std::string ply = std::string("ply\nformat ") +
                              (big_endian ? "binary_big_endian" : "binary_little_endian") +
                              " 1.0\nelement vertex 1\nproperty " + c.type + " x\nproperty " +
                              c.type + " y\nproperty " + c.type +
                              " z\nelement face 1\nproperty list uchar int vertex_indices\n"
                              "end_header\n" +
                              value + value + value + "\x03" + std::string(12, '\0');
      ScratchDir dir;
      auto sequence = ReadText(dir, "types.ply", ply);
      ASSERT_TRUE(sequence.ok()) << c.type << ": " << sequence.status().ToString();
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_EQ(sequence->frame(0)(0, axis), c.expected) << c.type << " big " << big_endian;
      }
    }
  }
}

}  // namespace
}  // namespace dmc
