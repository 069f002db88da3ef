// Fuzz target: connectivity round trip. The input is read as a triangle list over at most 64
// vertices (one byte per index, mod the vertex count given by the first byte); whatever method
// EncodeConnectivity picks, decoding its payload must give back the same oriented triangles
// (exactly, for the indexed method; as a set for Draco, which may reorder triangles and rotate
// their corners; through vertex_order when reordering is allowed).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "decoder/connectivity_decoder.h"
#include "encoder/connectivity_encoder.h"
#include "fuzz_support.h"

namespace {

std::vector<std::array<int32_t, 3>> CanonicalSet(const dmc::Triangles& triangles) {
  std::vector<std::array<int32_t, 3>> set;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const std::array<int32_t, 3> tri = {triangles(t, 0), triangles(t, 1), triangles(t, 2)};
    const int first = static_cast<int>(std::min_element(tri.begin(), tri.end()) - tri.begin());
    set.push_back({tri[first], tri[(first + 1) % 3], tri[(first + 2) % 3]});
  }
  std::sort(set.begin(), set.end());
  return set;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 5) return 0;
  const int vertex_count = 3 + data[0] % 62;
  const bool allow_reorder = (data[1] & 1) != 0;
  const size_t triangle_count = std::min<size_t>((size - 2) / 3, 200);
  dmc::Triangles input(static_cast<Eigen::Index>(triangle_count), 3);
  for (size_t t = 0; t < triangle_count; ++t) {
    for (int k = 0; k < 3; ++k)
      input(static_cast<Eigen::Index>(t), k) = data[2 + 3 * t + k] % vertex_count;
  }
  const dmc::StatusOr<dmc::ConnectivityCode> code =
      dmc::EncodeConnectivity(input, vertex_count, allow_reorder);
  if (!code.ok()) dmc::fuzz::InvariantBroken();  // every valid triangle list is codable
  const dmc::StatusOr<dmc::Triangles> decoded = dmc::DecodeConnectivity(
      code->payload, static_cast<uint32_t>(vertex_count), static_cast<uint32_t>(triangle_count));
  if (!decoded.ok()) dmc::fuzz::InvariantBroken();
  dmc::Triangles in_input_labels = *decoded;
  if (!code->vertex_order.empty()) {
    for (Eigen::Index t = 0; t < in_input_labels.rows(); ++t) {
      for (int k = 0; k < 3; ++k) in_input_labels(t, k) = code->vertex_order[(*decoded)(t, k)];
    }
  }
  const bool exact = code->method() == dmc::ConnectivityMethod::kIndexed
                         ? in_input_labels == input
                         : CanonicalSet(in_input_labels) == CanonicalSet(input);
  if (!exact) dmc::fuzz::InvariantBroken();
  return 0;
}
