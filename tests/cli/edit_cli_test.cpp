// dmc edit through the built binary: generated method subcommands, outputs, exit codes.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cli/cli_runner.h"
#include "dmc/io.h"

namespace dmc::testing {
namespace {

// A small blob animation as a PC2 cache (plus its OBJ) in `dir`.
std::filesystem::path Blob(const std::filesystem::path& dir, int frames) {
  const auto input = dir / "blob.pc2";
  const CliResult synth = RunDmc("synth blob -o " + Quoted(input) + " --frames " +
                                 std::to_string(frames) + " --resolution 300");
  EXPECT_EQ(synth.exit_code, 0) << synth.err;
  return input;
}

TEST(EditCli, HelpListsEveryMethodAndItsDeclaredOptions) {
  const CliResult help = RunDmc("edit --help");
  ASSERT_EQ(help.exit_code, 0) << help.err;
  for (const char* method :
       {"laplacian-edit", "smooth-explicit", "smooth-taubin", "smooth-implicit",
        "param-barycentric", "morph", "ls-mesh", "curvature", "spectral-filter"}) {
    EXPECT_NE(help.out.find(method), std::string::npos) << method;
  }
  const CliResult taubin = RunDmc("edit smooth-taubin --help");
  ASSERT_EQ(taubin.exit_code, 0);
  for (const char* option : {"--pass-band", "--lambda", "--mu", "--iterations", "--operator",
                             "--selection", "--operator-frame"}) {
    EXPECT_NE(taubin.out.find(option), std::string::npos) << option;
  }
}

TEST(EditCli, EditingWithUnmovedHandlesReturnsTheSequence) {
  const auto dir = FreshTempDir("edit_cli");
  const auto input = Blob(dir, 3);
  { std::ofstream(dir / "sel.json") << R"({"handles": [0, 1, 2, 3], "fixed": [40, 41, 42]})"; }
  const auto output = dir / "edited.pc2";
  const CliResult result =
      RunDmc("edit laplacian-edit " + Quoted(input) + " -o " + Quoted(output) +
             " --operator cotan --selection " + Quoted(dir / "sel.json") + " --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = nlohmann::json::parse(result.out);
  EXPECT_EQ(report["method"], "laplacian-edit");
  EXPECT_EQ(report["operator"], "cotan");
  EXPECT_EQ(report["output_frames"], 3);
  EXPECT_EQ(report["parameters"]["constraints"], "hard");
  const auto original = ReadSequence(input);
  const auto edited = ReadSequence(output);
  ASSERT_TRUE(original.ok() && edited.ok());
  ASSERT_EQ(edited->frame_count(), 3);
  for (int f = 0; f < 3; ++f) {
    EXPECT_LT((edited->frame_d(f) - original->frame_d(f)).cwiseAbs().maxCoeff(), 1e-5) << f;
  }
  // A translation of the handles moves them by exactly that much (hard constraints).
  {
    std::ofstream(dir / "move.json")
        << R"({"handles": [0], "fixed": [40], "transform": [1,0,0,0, 0,1,0,0, 0,0,1,0.25, 0,0,0,1]})";
  }
  const auto moved_path = dir / "moved.pc2";
  ASSERT_EQ(RunDmc("edit laplacian-edit " + Quoted(input) + " -o " + Quoted(moved_path) +
                   " --operator tutte --selection " + Quoted(dir / "move.json"))
                .exit_code,
            0);
  const auto moved = ReadSequence(moved_path);
  ASSERT_TRUE(moved.ok());
  EXPECT_NEAR(moved->frame_d(1)(0, 2), original->frame_d(1)(0, 2) + 0.25, 1e-5);
}

TEST(EditCli, CurvatureWritesAScalarPlyPerFrame) {
  const auto dir = FreshTempDir("edit_cli");
  const auto input = Blob(dir, 2);
  const auto output = dir / "curvature";
  const CliResult result = RunDmc("edit curvature " + Quoted(input) + " -o " + Quoted(output) +
                                  " --operator cotan-area --frame-operator");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* frame : {"frame_0000.ply", "frame_0001.ply"}) {
    const std::string text = ReadText(output / frame);
    EXPECT_NE(text.find("property float mean_curvature"), std::string::npos) << frame;
    EXPECT_NE(text.find("property uchar red"), std::string::npos) << frame;
  }
  // The directory reads back as the input geometry.
  const auto read = ReadSequence(output);
  const auto original = ReadSequence(input);
  ASSERT_TRUE(read.ok() && original.ok()) << read.status().ToString();
  EXPECT_EQ(read->frame_count(), 2);
  EXPECT_LT((read->frame_d(1) - original->frame_d(1)).cwiseAbs().maxCoeff(), 1e-6);
  // One frame into one .ply file.
  const auto single = dir / "one.ply";
  const auto obj = dir / "blob.obj";  // frame 0, written beside the cache
  ASSERT_EQ(
      RunDmc("edit curvature " + Quoted(obj) + " -o " + Quoted(single) + " --operator cotan-area")
          .exit_code,
      0);
  EXPECT_NE(ReadText(single).find("mean_curvature"), std::string::npos);
}

TEST(EditCli, WholeSequenceAndPerFrameMethods) {
  const auto dir = FreshTempDir("edit_cli");
  const auto input = Blob(dir, 4);
  const CliResult morph =
      RunDmc("edit morph " + Quoted(input) + " -o " + Quoted(dir / "morph.pc2") +
             " --operator tutte --frames 6 --from 1 --to 3 --json");
  ASSERT_EQ(morph.exit_code, 0) << morph.err;
  EXPECT_EQ(nlohmann::json::parse(morph.out)["output_frames"], 6);
  const CliResult smooth =
      RunDmc("edit smooth-implicit " + Quoted(input) + " -o " + Quoted(dir / "smooth") +
             " --operator ddl --lambda 0.5 --frame-format obj --json");
  ASSERT_EQ(smooth.exit_code, 0) << smooth.err;
  const auto report = nlohmann::json::parse(smooth.out);
  EXPECT_EQ(report["output_frames"], 4);
  EXPECT_TRUE(std::filesystem::exists(dir / "smooth" / "frame_0003.obj"));
  bool has_volume = false;
  for (const auto& m : report["measurements"]) has_volume |= m["name"] == "volume_ratio";
  EXPECT_TRUE(has_volume);
}

TEST(EditCli, ErrorsHaveTheirExitCodes) {
  const auto dir = FreshTempDir("edit_cli");
  const auto input = Blob(dir, 2);
  const std::string out = " -o " + Quoted(dir / "out.pc2");
  // Usage errors (CLI11): unknown method, missing output.
  EXPECT_EQ(RunDmc("edit nope " + Quoted(input) + out).exit_code, 1);
  EXPECT_EQ(RunDmc("edit smooth-explicit " + Quoted(input) + " --operator tutte").exit_code, 1);
  // kNotFound (20): unknown operator, listing the known ones.
  const CliResult unknown = RunDmc("edit smooth-explicit " + Quoted(input) + out + " --operator x");
  EXPECT_EQ(unknown.exit_code, 20);
  EXPECT_NE(unknown.err.find("cotan-area"), std::string::npos);
  // kInvalidArgument (11): malformed parameter value, missing selection.
  EXPECT_EQ(RunDmc("edit smooth-explicit " + Quoted(input) + out + " --operator tutte --lambda x")
                .exit_code,
            11);
  EXPECT_EQ(RunDmc("edit laplacian-edit " + Quoted(input) + out + " --operator tutte").exit_code,
            11);
  // kUnsupported (16): a closed blob is no disk.
  const CliResult param =
      RunDmc("edit param-barycentric " + Quoted(input) + out + " --operator tutte");
  EXPECT_EQ(param.exit_code, 16) << param.err;
  // kParseError (13): a malformed selection file.
  { std::ofstream(dir / "bad.json") << "{\"handles\": [1,"; }
  EXPECT_EQ(RunDmc("edit ls-mesh " + Quoted(input) + out + " --operator tutte --selection " +
                   Quoted(dir / "bad.json"))
                .exit_code,
            13);
}

}  // namespace
}  // namespace dmc::testing
