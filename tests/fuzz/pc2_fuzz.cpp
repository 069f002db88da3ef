// Fuzz target: PC2 point caches through the public reader (dmc::ReadSequence), which needs a
// file: the input is written to a per-process temporary directory next to a fixed 4-vertex
// connectivity mesh. A result must have the mesh's 4 vertices and finite positions.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "dmc/io.h"
#include "fuzz_support.h"

namespace {

const std::filesystem::path& Directory() {
  static const std::filesystem::path directory = [] {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("dmc_pc2_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    std::ofstream(path / "mesh.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                        "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
    return path;
  }();
  return directory;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path cache = Directory() / "input.pc2";
  {
    std::ofstream out(cache, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  dmc::ReadOptions options;
  options.connectivity = Directory() / "mesh.obj";
  options.threads = 1;
  const dmc::StatusOr<dmc::MeshSequence> sequence = dmc::ReadSequence(cache, options);
  if (!sequence.ok()) return 0;
  if (sequence->vertex_count() != 4) dmc::fuzz::InvariantBroken();
  for (size_t i = 0; i < sequence->position_value_count(); ++i) {
    if (!std::isfinite(sequence->data()[i])) dmc::fuzz::InvariantBroken();
  }
  return 0;
}
