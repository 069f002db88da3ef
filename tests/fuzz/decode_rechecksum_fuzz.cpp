// Fuzz target: whole-stream decoding with every chunk checksum repaired before decoding. The
// plain decode target rarely gets past XXH32 (a mutation almost always breaks a checksum), so
// this one fixes the checksums of whatever chunks the input frames and lets the mutations reach
// the headers, the connectivity decoders, the range-coded payloads, the operator rebuild and the
// solver. A result must be a well-formed sequence.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "bitstream/syntax.h"
#include "dmc/decoder.h"
#include "entropy/byte_io.h"
#include "fuzz_support.h"

namespace {

// Rewrites every framed chunk's checksum; bytes that do not frame as chunks are kept as they are.
std::vector<uint8_t> RepairChecksums(std::span<const uint8_t> stream) {
  std::vector<uint8_t> repaired(stream.begin(), stream.end());
  dmc::ByteReader reader(stream);
  std::span<const uint8_t> preamble;
  if (!reader.GetBytes(7, &preamble, "").ok()) return repaired;
  while (!reader.at_end()) {
    uint8_t type = 0;
    uint64_t size = 0;
    std::span<const uint8_t> payload;
    if (!reader.GetU8(&type, "").ok() || !reader.GetVarU(&size, "").ok() ||
        size > reader.remaining() ||
        !reader.GetBytes(static_cast<size_t>(size), &payload, "").ok() || reader.remaining() < 4) {
      break;
    }
    const uint32_t checksum = dmc::format::ChunkChecksum(type, payload);
    for (int i = 0; i < 4; ++i) {
      repaired[reader.position() + i] = static_cast<uint8_t>(checksum >> (8 * i));
    }
    uint32_t ignored = 0;
    (void)reader.GetU32(&ignored, "");
    if (type == static_cast<uint8_t>(dmc::ChunkType::kEnd)) break;
  }
  return repaired;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<uint8_t> stream = RepairChecksums(std::span<const uint8_t>(data, size));
  if (!dmc::fuzz::DeclaredSizesAreSmall(stream)) return -1;
  const dmc::StatusOr<dmc::MeshSequence> decoded = dmc::Decode(stream);
  if (!decoded.ok()) return 0;
  for (Eigen::Index t = 0; t < decoded->triangles().rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t v = decoded->triangles()(t, k);
      if (v < 0 || v >= decoded->vertex_count()) dmc::fuzz::InvariantBroken();
    }
  }
  return 0;
}
