// A command never writes over a file it reads: the output path compared as a file (links and
// other spellings too) against the input and a PC2's connectivity, refused before any work with
// invalid-argument, the input left byte for byte.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cli/cli_runner.h"

namespace dmc::testing {
namespace {

std::vector<char> Bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(OutputIsInputCli, RefusedBeforeAnyWorkAndTheInputKept) {
  const auto dir = FreshTempDir("output_is_input");
  const auto cache = dir / "w.pc2";
  const auto mesh = dir / "w.obj";  // the cache's connectivity, written beside it
  const auto stream = dir / "w.dmc";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(cache) + " --frames 6 --resolution 300").exit_code, 0);
  ASSERT_EQ(RunDmc("encode " + Quoted(cache) + " -o " + Quoted(stream)).exit_code, 0);
  std::filesystem::create_symlink(cache, dir / "link.pc2");
  // A cache whose connectivity beside it is an .off, as FindPc2Connectivity finds it.
  const auto off_cache = dir / "v.pc2", off_mesh = dir / "v.off";
  std::filesystem::copy_file(cache, off_cache);
  ASSERT_EQ(RunDmc("convert " + Quoted(mesh) + " -o " + Quoted(off_mesh)).exit_code, 0);
  const auto off_bytes = Bytes(off_mesh);
  const auto cache_bytes = Bytes(cache), mesh_bytes = Bytes(mesh), stream_bytes = Bytes(stream);

  const auto same_dir = dir / "." / "w.pc2";
  for (const std::string& command :
       {"encode " + Quoted(cache) + " -o " + Quoted(cache),
        "encode " + Quoted(cache) + " -o " + Quoted(mesh),
        "encode " + Quoted(dir / "link.pc2") + " -o " + Quoted(same_dir),
        "decode " + Quoted(stream) + " -o " + Quoted(stream),
        "convert " + Quoted(cache) + " -o " + Quoted(same_dir),
        "convert " + Quoted(off_cache) + " -o " + Quoted(off_mesh)}) {
    const CliResult result = RunDmc(command);
    EXPECT_EQ(result.exit_code, 11) << command << "\n" << result.err;  // invalid-argument
    EXPECT_NE(result.err.find("is the input"), std::string::npos) << result.err;
  }
  EXPECT_EQ(Bytes(cache), cache_bytes);
  EXPECT_EQ(Bytes(mesh), mesh_bytes);
  EXPECT_EQ(Bytes(stream), stream_bytes);
  EXPECT_EQ(Bytes(off_mesh), off_bytes);
  // A different output is written as before.
  EXPECT_EQ(RunDmc("decode " + Quoted(stream) + " -o " + Quoted(dir / "out.pc2")).exit_code, 0);
}

}  // namespace
}  // namespace dmc::testing
