// A command never writes over a file it reads: the output path compared as a file (links and
// other spellings too) against the input and a PC2's connectivity, refused before any work with
// invalid-argument, the input left byte for byte.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
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

// dmc edit and dmc edit tvm, and outputs that are directories: a directory output is replaced as a
// whole (WriteSequence) or written into (edit tvm), so it may not hold an input either.
TEST(OutputIsInputCli, EditAndDirectoryOutputsAreRefusedToo) {
  const auto dir = FreshTempDir("output_is_input");
  const auto mesh = dir / "m.obj", frames = dir / "frames", selection = dir / "sel.txt";
  ASSERT_EQ(RunDmc("synth blob -o " + Quoted(frames) + " --frames 3 --resolution 200").exit_code,
            0);
  ASSERT_EQ(
      RunDmc("convert " + Quoted(frames / "frame_0000.obj") + " -o " + Quoted(mesh)).exit_code, 0);
  std::ofstream(selection) << "0 1 2\n";
  const auto tvm = dir / "tvm";
  ASSERT_EQ(
      RunDmc("synth collision -o " + Quoted(tvm) + " --frames 3 --resolution 300 --centres 40")
          .exit_code,
      0);
  std::ofstream(tvm / "lift.json") << "{}";
  std::filesystem::create_symlink(mesh, dir / "link.obj");
  const auto mesh_bytes = Bytes(mesh), selection_bytes = Bytes(selection),
             frame_bytes = Bytes(frames / "frame_0001.obj"), tvm_bytes = Bytes(tvm / "centres.txt");

  const std::string smooth = "edit smooth-explicit --operator cotan ";
  for (const auto& [command, relation] : std::vector<std::pair<std::string, std::string>>{
           {smooth + Quoted(mesh) + " -o " + Quoted(mesh), "is the input"},
           {smooth + Quoted(dir / "link.obj") + " -o " + Quoted(dir / "." / "m.obj"),
            "is the input"},
           {smooth + Quoted(mesh) + " --selection " + Quoted(selection) + " -o " +
                Quoted(selection),
            "is the input"},
           {smooth + Quoted(frames) + " -o " + Quoted(frames), "is the input"},
           {smooth + Quoted(frames / "frame_0000.obj") + " -o " + Quoted(frames),
            "holds the input"},
           {"convert " + Quoted(frames / "frame_0001.obj") + " -o " + Quoted(frames),
            "holds the input"},
           {"convert " + Quoted(frames / "frame_*.obj") + " -o " + Quoted(frames), "is the input"},
           {"edit tvm " + Quoted(tvm) + " -o " + Quoted(tvm) + " --selection " +
                Quoted(tvm / "lift.json"),
            "is the input"},
           {"edit tvm " + Quoted(tvm) + " -o " + Quoted(dir) + " --selection " +
                Quoted(tvm / "lift.json"),
            "holds the input"}}) {
    const CliResult result = RunDmc(command);
    EXPECT_EQ(result.exit_code, 11) << command << "\n" << result.err;  // invalid-argument
    EXPECT_NE(result.err.find(relation), std::string::npos) << command << "\n" << result.err;
  }
  EXPECT_EQ(Bytes(mesh), mesh_bytes);
  EXPECT_EQ(Bytes(selection), selection_bytes);
  EXPECT_EQ(Bytes(frames / "frame_0001.obj"), frame_bytes);
  EXPECT_EQ(Bytes(tvm / "centres.txt"), tvm_bytes);
  // Other outputs are written as before, a directory output beside the inputs too.
  EXPECT_EQ(RunDmc(smooth + Quoted(mesh) + " -o " + Quoted(dir / "smoothed.obj")).exit_code, 0);
  EXPECT_EQ(RunDmc(smooth + Quoted(frames) + " -o " + Quoted(dir / "smoothed")).exit_code, 0);
}

}  // namespace
}  // namespace dmc::testing
