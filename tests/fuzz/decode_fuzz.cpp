// Fuzz target: whole-stream decoding (dmc::Decode) of untrusted bytes. A result must be a
// well-formed sequence: the declared counts, indices in range.
#include <cstddef>
#include <cstdint>
#include <span>

#include "dmc/decoder.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> stream(data, size);
  const dmc::StatusOr<dmc::MeshSequence> decoded =
      dmc::Decode(stream, dmc::fuzz::kFuzzDecoderOptions);
  if (!decoded.ok()) return 0;
  const dmc::MeshSequence& sequence = *decoded;
  if (sequence.position_value_count() != static_cast<size_t>(sequence.vertex_count()) * 3 *
                                             static_cast<size_t>(sequence.frame_count())) {
    dmc::fuzz::InvariantBroken();
  }
  for (Eigen::Index t = 0; t < sequence.triangles().rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t v = sequence.triangles()(t, k);
      if (v < 0 || v >= sequence.vertex_count()) dmc::fuzz::InvariantBroken();
    }
  }
  return 0;
}
