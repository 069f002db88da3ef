// `dmc synth` run as a user would: outputs on disk, summaries on stdout, exit codes
// (0, 10 + ErrorCode, CLI11's own for usage errors) and messages on stderr.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
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
using testing::ReadText;
using testing::RunDmc;

TEST(SynthCliTest, WritesAPointCacheWithItsMeshAndPrintsJson) {
  const auto dir = FreshTempDir("synth");
  const auto cache = dir / "walker.pc2";
  const auto result =
      RunDmc("synth walker -o " + Quoted(cache) + " --frames 5 --resolution 500 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["name"], "walker");
  EXPECT_EQ(json["frames"], 5);
  EXPECT_EQ(json["frame_rate"], 30.0);
  EXPECT_EQ(json["seed"], 1);
  EXPECT_EQ(json["output"], cache.string());
  const int vertices = json["vertices"];
  EXPECT_NEAR(vertices, 500, 75);
  EXPECT_GT(json["triangles"].get<int>(), vertices);
  // PC2: a 32-byte header, then frames × vertices × 3 float32.
  ASSERT_TRUE(std::filesystem::exists(cache));
  EXPECT_EQ(std::filesystem::file_size(cache), 32u + 5u * vertices * 12u);
  EXPECT_TRUE(std::filesystem::exists(dir / "walker.obj"));
}

TEST(SynthCliTest, WritesAFramesDirectoryAndPrintsASummaryLine) {
  const auto dir = FreshTempDir("synth");
  const auto frames = dir / "cloth_frames";
  const auto result = RunDmc("synth cloth -o " + Quoted(frames) + " --frames 3 --resolution 200");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("cloth: 3 frame(s) of "));
  EXPECT_THAT(result.out, HasSubstr("at 30 fps (seed 1) -> " + frames.string()));
  EXPECT_TRUE(std::filesystem::exists(frames / "frame_0000.obj"));
  EXPECT_TRUE(std::filesystem::exists(frames / "frame_0002.obj"));
  EXPECT_FALSE(std::filesystem::exists(frames / "frame_0003.obj"));
}

TEST(SynthCliTest, SameSeedWritesTheSameBytesAndAnotherSeedDoesNot) {
  const auto dir = FreshTempDir("synth");
  const std::string common = " --frames 4 --resolution 300";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(dir / "a.pc2") + common + " --seed 9").exit_code, 0);
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(dir / "b.pc2") + common + " --seed 9").exit_code, 0);
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(dir / "c.pc2") + common + " --seed 10").exit_code, 0);
  EXPECT_EQ(ReadText(dir / "a.pc2"), ReadText(dir / "b.pc2"));
  EXPECT_NE(ReadText(dir / "a.pc2"), ReadText(dir / "c.pc2"));
  // Connectivity does not depend on the seed; frame 0's positions in the mesh file do.
  EXPECT_EQ(std::filesystem::file_size(dir / "a.pc2"), std::filesystem::file_size(dir / "c.pc2"));
}

TEST(SynthCliTest, UnknownNameIsNotFoundAndListsTheGenerators) {
  const auto dir = FreshTempDir("synth");
  const auto result = RunDmc("synth teapot -o " + Quoted(dir / "t.pc2"));
  EXPECT_EQ(result.exit_code, ExitCodeFor(ErrorCode::kNotFound));
  EXPECT_THAT(result.err, HasSubstr("dmc synth: error: not-found: unknown synthetic sequence "
                                    "'teapot'; known: twist, cloth, walker, blob"));
  EXPECT_FALSE(std::filesystem::exists(dir / "t.pc2"));
}

TEST(SynthCliTest, ImpossibleOptionsAreInvalidArgumentsNamingTheOption) {
  const auto dir = FreshTempDir("synth");
  const auto output = Quoted(dir / "x.pc2");
  const auto no_frames = RunDmc("synth twist -o " + output + " --frames 0");
  EXPECT_EQ(no_frames.exit_code, ExitCodeFor(ErrorCode::kInvalidArgument));
  EXPECT_THAT(no_frames.err, HasSubstr("invalid-argument: frames must be in [1, 100000], got 0"));
  const auto coarse = RunDmc("synth twist -o " + output + " --resolution 5");
  EXPECT_EQ(coarse.exit_code, ExitCodeFor(ErrorCode::kInvalidArgument));
  EXPECT_THAT(coarse.err, HasSubstr("resolution must be in [100, 1000000] vertices, got 5"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x.pc2"));

  const auto json = RunDmc("synth twist -o " + output + " --frames 0 --json");
  EXPECT_EQ(json.exit_code, ExitCodeFor(ErrorCode::kInvalidArgument));
  EXPECT_EQ(nlohmann::json::parse(json.out)["error"]["name"], "invalid-argument");
}

TEST(SynthCliTest, UsageErrorsComeFromTheParser) {
  const auto missing_output = RunDmc("synth twist");
  EXPECT_EQ(missing_output.exit_code, 1);
  EXPECT_THAT(missing_output.err, HasSubstr("--output"));
  const auto not_a_number = RunDmc("synth twist -o x.pc2 --frames many");
  EXPECT_EQ(not_a_number.exit_code, 1);
  EXPECT_THAT(not_a_number.err, HasSubstr("--frames"));
}

TEST(SynthCliTest, HelpListsTheGenerators) {
  const auto result = RunDmc("synth --help");
  EXPECT_EQ(result.exit_code, 0);
  for (const char* name : {"twist", "cloth", "walker", "blob"}) {
    EXPECT_THAT(result.out, HasSubstr(std::string("\n  ") + name)) << name;
  }
}

}  // namespace
}  // namespace dmc
