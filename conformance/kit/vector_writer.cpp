// The kit's one writer, kept out of dmc_conformance_kit so that the runner links no file-format
// code: only the generator writes vectors.
#include "dmc/io.h"
#include "kit/vector_kit.h"

namespace dmc::conformance {

Status WriteBytes(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  return WriteFileAtomically(path, bytes);
}

}  // namespace dmc::conformance
