// Names that are not UTF-8 (a stream's name is bytes, spec §3; a file name can hold any byte)
// reach the JSON and glTF writers without aborting them: invalid bytes come out as U+FFFD.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

TEST(NonUtf8NamesCli, JsonAndGltfWritersReplaceInvalidBytes) {
  const auto dir = FreshTempDir("non_utf8_names");
  const auto input = dir /
                     "b\xFF\xFE"
                     "d.pc2";  // the sequence's name comes from the file name
  const auto stream = dir / "s.dmc";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(input) + " --frames 6 --resolution 300").exit_code, 0);

  const CliResult source_info = RunDmc("info " + Quoted(input) + " --json");
  ASSERT_EQ(source_info.exit_code, 0) << source_info.err;
  EXPECT_TRUE(nlohmann::json::accept(source_info.out)) << source_info.out;

  const CliResult encoded = RunDmc("encode " + Quoted(input) + " -o " + Quoted(stream) + " --json");
  ASSERT_EQ(encoded.exit_code, 0) << encoded.err;
  EXPECT_TRUE(nlohmann::json::accept(encoded.out)) << encoded.out;

  const CliResult stream_info = RunDmc("info " + Quoted(stream) + " --json");
  ASSERT_EQ(stream_info.exit_code, 0) << stream_info.err;
  const nlohmann::json info = nlohmann::json::parse(stream_info.out);
  EXPECT_EQ(info["name"],
            "b\xEF\xBF\xBD\xEF\xBF\xBD"
            "d");

  const auto glb = dir / "s.glb";
  const CliResult exported = RunDmc("decode " + Quoted(stream) + " -o " + Quoted(glb));
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_TRUE(std::filesystem::exists(glb));
  const CliResult reread = RunDmc("info " + Quoted(glb) + " --json");
  ASSERT_EQ(reread.exit_code, 0) << reread.err;
}

}  // namespace
}  // namespace dmc::testing
