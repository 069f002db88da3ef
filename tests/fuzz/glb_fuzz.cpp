// Fuzz target: GLB files through the public reader (dmc::ReadSequence): the container check,
// tinygltf, the compressed-geometry extensions (EXT_meshopt_compression views, Draco primitives)
// and posing. At most 4 frames are posed, so a fuzzed clip length costs nothing. A result must
// have finite positions.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "dmc/io.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                            ("dmc_glb_fuzz_" + std::to_string(::getpid()) + ".glb");
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  dmc::ReadOptions options;
  options.max_frames = 4;
  options.threads = 1;
  const dmc::StatusOr<dmc::MeshSequence> sequence = dmc::ReadSequence(path, options);
  if (!sequence.ok()) return 0;
  for (size_t i = 0; i < sequence->position_value_count(); ++i) {
    if (!std::isfinite(sequence->data()[i])) dmc::fuzz::InvariantBroken();
  }
  return 0;
}
