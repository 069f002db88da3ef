// Fuzz target: whole-stream decoding with every chunk checksum repaired before decoding. The
// plain decode target rarely gets past XXH32 (a mutation almost always breaks a checksum), so
// this one fixes the checksums of whatever chunks the input frames and lets the mutations reach
// the headers, the connectivity decoders, the range-coded payloads, the operator rebuild and the
// solver. A result must be a well-formed sequence.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "dmc/decoder.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<uint8_t> stream =
      dmc::fuzz::RepairChecksums(std::span<const uint8_t>(data, size));
  const dmc::StatusOr<dmc::MeshSequence> decoded =
      dmc::Decode(stream, dmc::fuzz::kFuzzDecoderOptions);
  if (!decoded.ok()) return 0;
  for (Eigen::Index t = 0; t < decoded->triangles().rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t v = decoded->triangles()(t, k);
      if (v < 0 || v >= decoded->vertex_count()) dmc::fuzz::InvariantBroken();
    }
  }
  return 0;
}
