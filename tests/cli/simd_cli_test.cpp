// DMC_SIMD through the built binary: every variant this CPU runs is the one in use (--version)
// and decodes and encodes the same bytes as the default one; a variant the CPU lacks, and a
// misspelt name, fail before any work with the exit code and message of their error.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

std::vector<char> FileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Sets DMC_SIMD for the commands run in its lifetime (RunDmc's shell inherits the environment).
class ScopedSimdEnvironment {
 public:
  explicit ScopedSimdEnvironment(const std::string& value) { setenv("DMC_SIMD", value.c_str(), 1); }
  ~ScopedSimdEnvironment() { unsetenv("DMC_SIMD"); }
};

TEST(SimdCli, EveryAvailableVariantGivesTheSameBytes) {
  const auto dir = FreshTempDir("simd_cli");
  const auto input = dir / "walker.pc2";
  ASSERT_EQ(RunDmc("synth walker -o " + Quoted(input) + " --frames 20 --resolution 1500").exit_code,
            0);
  const auto reference_stream = dir / "reference.dmc";
  const auto reference_frames = dir / "reference.pc2";
  ASSERT_EQ(RunDmc("encode " + Quoted(input) + " -o " + Quoted(reference_stream)).exit_code, 0);
  ASSERT_EQ(
      RunDmc("decode " + Quoted(reference_stream) + " -o " + Quoted(reference_frames)).exit_code,
      0);
  int available = 0;
  for (const std::string variant : {"avx512", "avx2", "sse4", "ssse3", "neon", "baseline"}) {
    const ScopedSimdEnvironment simd(variant);
    const auto stream = dir / (variant + ".dmc");
    const auto frames = dir / (variant + ".pc2");
    const CliResult encoded = RunDmc("encode " + Quoted(input) + " -o " + Quoted(stream));
    if (encoded.exit_code != 0) {
      // Only an instruction set this CPU lacks may be refused (unsupported: 10 + 6).
      EXPECT_NE(variant, "baseline") << encoded.err;
      EXPECT_EQ(encoded.exit_code, 16) << encoded.err;
      EXPECT_NE(
          encoded.err.find("DMC_SIMD: SIMD variant '" + variant + "' is not available on this CPU"),
          std::string::npos)
          << encoded.err;
      EXPECT_FALSE(std::filesystem::exists(stream));
      continue;
    }
    ++available;
    const CliResult version = RunDmc("--version");
    EXPECT_NE(version.out.find("SIMD variant " + variant + ";"), std::string::npos) << version.out;
    EXPECT_EQ(FileBytes(stream), FileBytes(reference_stream)) << variant;
    ASSERT_EQ(RunDmc("decode " + Quoted(stream) + " -o " + Quoted(frames)).exit_code, 0);
    EXPECT_EQ(FileBytes(frames), FileBytes(reference_frames)) << variant;
  }
  EXPECT_GE(available, 1);
}

TEST(SimdCli, MisspeltVariantIsAnInvalidArgument) {
  const ScopedSimdEnvironment simd("avx-512");
  const CliResult result = RunDmc("synth blob -o /dev/null --frames 1");
  EXPECT_EQ(result.exit_code, 11) << result.err;  // invalid-argument: 10 + 1
  EXPECT_NE(result.err.find("DMC_SIMD: SIMD variant 'avx-512' is not one of avx512, avx2"),
            std::string::npos)
      << result.err;
}

}  // namespace
}  // namespace dmc::testing
