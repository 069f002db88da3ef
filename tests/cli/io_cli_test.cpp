// `dmc info` and `dmc convert` run as a user would: exit codes (0, 10 + ErrorCode, CLI11's for
// usage), messages on stderr, JSON on stdout.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_runner.h"
#include "dmc/status.h"
#include "test_support.h"

namespace dmc {
namespace {

using testing::FreshTempDir;
using ::testing::HasSubstr;
using testing::Quoted;
using testing::RunDmc;

void Write(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// Built with append, not operator+ or replace: GCC 12 reports a false -Wrestrict for those.
std::string TetrahedronFrame(int shift) {
  std::string text = "v ";
  text += std::to_string(shift);
  text += " 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  return text;
}

// Usage errors found by the argument parser exit 1 (status.h), apart from 0 and from the codes
// of dmc's error classes, 10 + ErrorCode.
bool IsUsageErrorExit(int code) { return code == 1; }

// Two frames of a closed tetrahedron in `dir`/frames.
std::filesystem::path MakeTetrahedronFrames(const std::filesystem::path& dir) {
  Write(dir / "frames" / "t_1.obj", TetrahedronFrame(0));
  Write(dir / "frames" / "t_2.obj", TetrahedronFrame(2));
  return dir / "frames";
}

TEST(InfoCliTest, DescribesASequenceAsJson) {
  const auto dir = FreshTempDir("io");
  const auto frames = MakeTetrahedronFrames(dir);
  const auto result = RunDmc("info " + Quoted(frames) + " --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["vertices"], 4);
  EXPECT_EQ(json["triangles"], 4);
  EXPECT_EQ(json["frames"], 2);
  EXPECT_EQ(json["edges"], 6);
  EXPECT_EQ(json["boundary_edges"], 0);
  EXPECT_EQ(json["boundary_loops"], 0);
  EXPECT_EQ(json["components"], 1);
  EXPECT_EQ(json["isolated_vertices"], 0);
  EXPECT_EQ(json["non_manifold_edges"], 0);
  EXPECT_EQ(json["manifold"], true);
  EXPECT_EQ(json["euler_characteristic"], 2);
  EXPECT_EQ(json["degenerate_triangles"], 0);
  EXPECT_TRUE(json["frame_rate"].is_null());
  EXPECT_EQ(json["bounding_box"]["min"], nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_EQ(json["bounding_box"]["max"], nlohmann::json({2.0, 1.0, 1.0}));
  EXPECT_DOUBLE_EQ(json["bounding_box"]["diagonal"].get<double>(), std::sqrt(6.0));
  EXPECT_EQ(json["warnings"], nlohmann::json::array());
}

TEST(InfoCliTest, PrintsTextWithWarnings) {
  const auto dir = FreshTempDir("io");
  // A quad (triangulated with a warning) and an isolated vertex.
  Write(dir / "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\n");
  const auto result = RunDmc("info " + Quoted(dir / "quad.obj"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("1 frame(s) of 5 vertices, 2 triangles"));
  EXPECT_THAT(result.out, HasSubstr("boundary              4 edge(s) in 1 loop(s)"));
  EXPECT_THAT(result.out, HasSubstr("components            2 (1 isolated vertices)"));
  EXPECT_THAT(result.err, HasSubstr("dmc info: warning: frame 0 (" + (dir / "quad.obj").string() +
                                    "): 1 face(s) with more than 3 corners fan-triangulated"));
}

TEST(InfoCliTest, ExitCodesNameTheErrorClass) {
  const auto dir = FreshTempDir("io");
  Write(dir / "bad.obj", "v 0 0 0\nv 1 0\n");
  Write(dir / "mixed" / "0.obj", TetrahedronFrame(0));
  Write(dir / "mixed" / "1.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");

  auto result = RunDmc("info " + Quoted(dir / "missing.obj"));
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kIoError));
  EXPECT_THAT(result.err, HasSubstr("dmc info: error: io-error: cannot open"));

  result = RunDmc("info " + Quoted(dir / "bad.obj"));
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kParseError));
  EXPECT_THAT(result.err, HasSubstr("parse-error: " + (dir / "bad.obj").string() +
                                    ":2: vertex has 2 coordinate(s), expected 3"));

  result = RunDmc("info " + Quoted(dir / "mixed"));
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kMismatch));
  EXPECT_THAT(result.err, HasSubstr("mismatch: frame 1 (" + (dir / "mixed" / "1.obj").string() +
                                    "): 3 vertices, expected 4"));

  result = RunDmc("info " + Quoted(dir / "bad.obj") + " --json");
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kParseError));
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["error"]["name"], "parse-error");
  EXPECT_EQ(json["error"]["code"], static_cast<int>(ErrorCode::kParseError));

  result = RunDmc("info");  // usage error from the argument parser
  EXPECT_TRUE(IsUsageErrorExit(result.exit_code)) << result.exit_code;
  EXPECT_THAT(result.err, HasSubstr("input is required"));
}

TEST(ConvertCliTest, ConvertsBetweenLayoutsLosslessly) {
  const auto dir = FreshTempDir("io");
  const auto frames = MakeTetrahedronFrames(dir);
  auto result = RunDmc("convert " + Quoted(frames) + " -o " + Quoted(dir / "anim.pc2"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("2 frame(s) of 4 vertices, 4 triangles"));
  EXPECT_TRUE(std::filesystem::exists(dir / "anim.pc2"));
  EXPECT_TRUE(std::filesystem::exists(dir / "anim.obj"));

  result = RunDmc("convert " + Quoted(dir / "anim.pc2") + " -o " + Quoted(dir / "plys") +
                  " --frame-format ply --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["frames"], 2);
  EXPECT_TRUE(std::filesystem::exists(dir / "plys" / "frame_0001.ply"));

  result = RunDmc("convert " + Quoted(dir / "plys") + " -o " + Quoted(dir / "last.off") +
                  " --max-frames 1");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  result = RunDmc("info " + Quoted(dir / "plys") + " --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(nlohmann::json::parse(result.out)["bounding_box"]["max"],
            nlohmann::json({2.0, 1.0, 1.0}));

  // A PC2 whose connectivity is elsewhere.
  std::filesystem::rename(dir / "anim.obj", dir / "mesh.obj");
  result = RunDmc("info " + Quoted(dir / "anim.pc2"));
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kIoError));
  EXPECT_THAT(result.err, HasSubstr("needs a connectivity mesh"));
  result = RunDmc("info " + Quoted(dir / "anim.pc2") + " --connectivity " +
                  Quoted(dir / "mesh.obj") + " --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(nlohmann::json::parse(result.out)["frames"], 2);
}

TEST(ConvertCliTest, RejectsImpossibleOutputs) {
  const auto dir = FreshTempDir("io");
  const auto frames = MakeTetrahedronFrames(dir);
  auto result = RunDmc("convert " + Quoted(frames) + " -o " + Quoted(dir / "one.obj"));
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kInvalidArgument));
  EXPECT_THAT(result.err, HasSubstr("is a single mesh file but the sequence has 2 frames"));
  EXPECT_FALSE(std::filesystem::exists(dir / "one.obj"));

  result = RunDmc("convert " + Quoted(frames) + " -o " + Quoted(dir / "x") + " --frame-format stl");
  EXPECT_TRUE(IsUsageErrorExit(result.exit_code)) << result.exit_code;
  EXPECT_FALSE(std::filesystem::exists(dir / "x"));

  result = RunDmc("convert " + Quoted(frames));
  EXPECT_TRUE(IsUsageErrorExit(result.exit_code)) << result.exit_code;
  EXPECT_THAT(result.err, HasSubstr("--output is required"));
}

TEST(ConvertCliTest, ConvertsRealData) {
  DMC_REQUIRE_SHARED_DATA(samba, "samba");
  const auto dir = FreshTempDir("io");
  auto result =
      RunDmc("convert " + Quoted(samba) + " -o " + Quoted(dir / "samba.pc2") + " --max-frames 3");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  result = RunDmc("info " + Quoted(dir / "samba.pc2") + " --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["vertices"], 9971);
  EXPECT_EQ(json["triangles"], 19938);
  EXPECT_EQ(json["frames"], 3);
  EXPECT_EQ(json["euler_characteristic"], 2);
}

}  // namespace
}  // namespace dmc
