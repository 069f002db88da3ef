// dmc decode --max-memory: a stream whose declared output (or a segment's normal equations)
// exceeds the limit is refused as resource-limit (exit 22) before it is decoded, naming the flag
// that raises it; no output appears. Streams whose payloads cannot hold their declared sizes are
// corrupt-stream whatever the limit (bitstream spec §8.7, §11.4).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

const std::filesystem::path kInvalidVectors =
    std::filesystem::path(DMC_SOURCE_DIR) / "conformance/vectors/invalid";

TEST(DecoderLimitsCli, OutputAboveTheLimitIsRefusedBeforeDecoding) {
  const auto dir = FreshTempDir("decoder_limits");
  const auto stream = dir / "b.dmc";
  ASSERT_EQ(
      RunDmc("synth blob -o " + Quoted(dir / "b.pc2") + " --frames 4 --resolution 200").exit_code,
      0);
  ASSERT_EQ(RunDmc("encode " + Quoted(dir / "b.pc2") + " -o " + Quoted(stream)).exit_code, 0);

  for (const std::string output : {"out.pc2", "out.glb", "frames"}) {
    const CliResult refused =
        RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / output) + " --max-memory 1KiB");
    EXPECT_EQ(refused.exit_code, 22) << output << ": " << refused.err;
    EXPECT_NE(refused.err.find("resource-limit"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("above the limit of 1024 bytes"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("--max-memory"), std::string::npos) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(dir / output)) << output;
  }
  const CliResult segment = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "s.pc2") +
                                   " --segment 0 --max-memory 1KiB");
  EXPECT_EQ(segment.exit_code, 22) << segment.err;
  EXPECT_EQ(
      RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "ok.pc2") + " --max-memory 16MiB")
          .exit_code,
      0);
  EXPECT_EQ(
      RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "none.pc2") + " --max-memory 0")
          .exit_code,
      0);
  // Not a size: a usage error.
  EXPECT_EQ(
      RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "x.pc2") + " --max-memory lots")
          .exit_code,
      1);
}

TEST(DecoderLimitsCli, StreamsDeclaringHugeMeshesAreRefusedWithTheirOwnCode) {
  const auto dir = FreshTempDir("decoder_limits");
  // 2^26 vertices in 21 frames: above the default 4 GiB, and corrupt without a limit.
  const auto bomb = kInvalidVectors / "residuals_cannot_hold_declared_vertices.dmc";
  const CliResult limited = RunDmc("decode " + Quoted(bomb) + " -o " + Quoted(dir / "a.pc2"));
  EXPECT_EQ(limited.exit_code, 22) << limited.err;
  const CliResult unlimited =
      RunDmc("decode " + Quoted(bomb) + " -o " + Quoted(dir / "a.pc2") + " --max-memory 0");
  EXPECT_EQ(unlimited.exit_code, 17) << unlimited.err;
  EXPECT_NE(unlimited.err.find("residual payload of"), std::string::npos) << unlimited.err;
  // dmc info reads the structure only: no limit applies, the payload check does.
  const CliResult info = RunDmc("info " + Quoted(bomb));
  EXPECT_EQ(info.exit_code, 17) << info.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.pc2"));
}

}  // namespace
}  // namespace dmc::testing
