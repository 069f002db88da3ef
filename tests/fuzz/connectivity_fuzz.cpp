// Fuzz target: the connectivity chunk decoder (all three methods, Draco included). Input: u16 LE
// vertex count, u16 LE triangle count, then the chunk payload. A result must hold exactly the
// declared number of triangles with indices in range.
#include <cstddef>
#include <cstdint>
#include <span>

#include "decoder/connectivity_decoder.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 4) return 0;
  const uint32_t vertex_count = data[0] | (uint32_t{data[1]} << 8);
  const uint32_t triangle_count = data[2] | (uint32_t{data[3]} << 8);
  const std::span<const uint8_t> payload(data + 4, size - 4);
  const dmc::StatusOr<dmc::Triangles> triangles =
      dmc::DecodeConnectivity(payload, vertex_count, triangle_count);
  if (!triangles.ok()) return 0;
  if (triangles->rows() != static_cast<Eigen::Index>(triangle_count)) dmc::fuzz::InvariantBroken();
  for (Eigen::Index t = 0; t < triangles->rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t v = (*triangles)(t, k);
      if (v < 0 || static_cast<uint32_t>(v) >= vertex_count) dmc::fuzz::InvariantBroken();
    }
  }
  return 0;
}
