// dmc encode / decode streaming PC2 caches segment by segment: --progress, identical bytes to the
// in-memory route, no output left behind on failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

std::vector<char> Bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

class StreamingCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshTempDir("streaming_cli");
    input_ = dir_ / "walk.pc2";
    const CliResult made =
        RunDmc("synth walker -o " + Quoted(input_) + " --frames 30 --resolution 800");
    ASSERT_EQ(made.exit_code, 0) << made.err;
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  std::filesystem::path dir_, input_;
};

TEST_F(StreamingCli, ProgressFlagShowsEveryStageOnStderr) {
  const auto stream = dir_ / "walk.dmc";
  const CliResult encoded = RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream) +
                                   " --segment-frames 10 --progress");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  for (const char* stage : {"scanning 100%", "encoding 100%", "measuring 100%"}) {
    EXPECT_NE(encoded.err.find(stage), std::string::npos) << stage << " in: " << encoded.err;
  }
  // Three segments of 10 frames: encoding passes through 33% and 66% on its way.
  EXPECT_NE(encoded.err.find("encoding  33%"), std::string::npos) << encoded.err;
  EXPECT_NE(encoded.out.find("3 segment(s)"), std::string::npos) << encoded.out;

  const auto decoded = dir_ / "decoded.pc2";
  const CliResult decode =
      RunDmc("decode " + Quoted(stream) + " -o " + Quoted(decoded) + " --progress");
  ASSERT_EQ(decode.exit_code, 0) << decode.err;
  EXPECT_NE(decode.err.find("decoding 100%"), std::string::npos) << decode.err;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "decoded.obj"));
}

TEST_F(StreamingCli, NoProgressWhenStderrIsNotATerminal) {
  const auto stream = dir_ / "walk.dmc";
  const CliResult encoded = RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream));
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  EXPECT_EQ(encoded.err.find('%'), std::string::npos) << encoded.err;
  const CliResult decode = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir_ / "d.pc2"));
  ASSERT_EQ(decode.exit_code, 0) << decode.err;
  EXPECT_EQ(decode.err.find('%'), std::string::npos) << decode.err;
}

TEST_F(StreamingCli, StreamedPc2MatchesTheInMemoryRoutes) {
  // The same frames as a directory of OBJ files are read whole before encoding.
  const auto frames = dir_ / "frames";
  ASSERT_EQ(RunDmc("convert " + Quoted(input_) + " -o " + Quoted(frames)).exit_code, 0);
  const auto from_pc2 = dir_ / "a.dmc", from_frames = dir_ / "b.dmc";
  const CliResult streamed =
      RunDmc("encode " + Quoted(input_) + " -o " + Quoted(from_pc2) + " --segment-frames 8 --json");
  ASSERT_EQ(streamed.exit_code, 0) << streamed.err;
  const CliResult loaded = RunDmc("encode " + Quoted(frames) + " -o " + Quoted(from_frames) +
                                  " --segment-frames 8 --json");
  ASSERT_EQ(loaded.exit_code, 0) << loaded.err;
  // The stream's name is the input's stem ("walk" vs "frames"): compare everything else.
  const auto a = nlohmann::json::parse(streamed.out), b = nlohmann::json::parse(loaded.out);
  for (const char* key : {"kg", "sted", "rank", "segments"}) EXPECT_EQ(a[key], b[key]) << key;
  EXPECT_EQ(a["breakdown"]["residuals"], b["breakdown"]["residuals"]);
  EXPECT_EQ(a["breakdown"]["basis"], b["breakdown"]["basis"]);

  // Streaming decode to PC2 against the in-memory decode to frames converted to PC2.
  const auto streamed_pc2 = dir_ / "s.pc2", via_frames = dir_ / "decoded_frames";
  ASSERT_EQ(RunDmc("decode " + Quoted(from_pc2) + " -o " + Quoted(streamed_pc2)).exit_code, 0);
  ASSERT_EQ(RunDmc("decode " + Quoted(from_pc2) + " -o " + Quoted(via_frames)).exit_code, 0);
  const auto converted = dir_ / "m.pc2";
  ASSERT_EQ(RunDmc("convert " + Quoted(via_frames) + " -o " + Quoted(converted)).exit_code, 0);
  EXPECT_EQ(Bytes(streamed_pc2), Bytes(converted));
}

TEST_F(StreamingCli, FailedDecodeLeavesNothing) {
  const auto stream = dir_ / "walk.dmc";
  ASSERT_EQ(
      RunDmc("encode " + Quoted(input_) + " -o " + Quoted(stream) + " --no-measure").exit_code, 0);
  std::vector<char> bytes = Bytes(stream);
  bytes[bytes.size() / 2] ^= 0x21;
  { std::ofstream(stream, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size())); }
  const auto out = dir_ / "out" / "x.pc2";
  std::filesystem::create_directories(out.parent_path());
  const CliResult decode = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(out));
  EXPECT_NE(decode.exit_code, 0);
  EXPECT_NE(decode.err.find("error"), std::string::npos) << decode.err;
  EXPECT_TRUE(std::filesystem::is_empty(out.parent_path()));
}

}  // namespace
}  // namespace dmc::testing
