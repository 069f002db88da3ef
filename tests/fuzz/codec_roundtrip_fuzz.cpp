// Fuzz target: encoder and decoder round trip. The input chooses a small mesh (an n×n grid, with
// an optional isolated vertex), 1 to 4 frames of positions taken from the input bytes, a codec
// operator and a few parameters. Encoding a valid sequence must succeed, and decoding the stream
// must give back the same counts and finite positions (the values themselves depend on the
// quantisers, so only their error relative to the bounding box is bounded, loosely).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "dmc/decoder.h"
#include "dmc/encoder.h"
#include "fuzz_support.h"
#include "synth/grid_triangles.h"

namespace {

constexpr std::array<const char*, 7> kOperators = {"ddl",        "tutte",     "kirchhoff", "cotan",
                                                   "cotan-area", "cotan-sym", "mean-value"};

class ByteSource {
 public:
  ByteSource(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint8_t Next() { return position_ < size_ ? data_[position_++] : 0; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t position_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 6) return 0;
  ByteSource bytes(data, size);
  const int n = 2 + bytes.Next() % 6;  // 2..7 vertices per side
  const int frames = 1 + bytes.Next() % 4;
  const uint8_t flags = bytes.Next();
  const bool isolated = (flags & 1) != 0;
  dmc::EncoderOptions options;
  options.measure = false;
  options.operator_name = kOperators[bytes.Next() % kOperators.size()];
  options.allow_reorder = (flags & 2) != 0;
  options.residual_bits = 4 + bytes.Next() % 16;
  options.segment_frames = (flags & 4) != 0 ? 2 : 0;

  const dmc::Triangles triangles =
      dmc::synth::GridTriangles(n, n, dmc::synth::GridDiagonals::kUniform);
  const int v_count = n * n + (isolated ? 1 : 0);
  dmc::MeshSequence sequence(v_count, triangles, frames);
  for (int f = 0; f < frames; ++f) {
    for (int v = 0; v < v_count; ++v) {
      // A grid displaced by input bytes: any finite positions are a valid sequence.
      sequence.frame(f).row(v) << static_cast<float>(v % n) + (bytes.Next() - 128) / 64.0f,
          static_cast<float>(v / n) + (bytes.Next() - 128) / 64.0f, (bytes.Next() - 128) / 32.0f;
    }
  }
  const dmc::StatusOr<std::vector<uint8_t>> stream = dmc::Encode(sequence, options);
  if (!stream.ok()) {
    // Only a numerical failure of a degenerate input (e.g. every vertex at one point), or a
    // residual beyond the format's range (kUnsupported: an area-weighted operator on slivers with
    // a very fine step), may stop the encoder; anything else is a bug.
    if (stream.status().code() != dmc::ErrorCode::kNumericalFailure &&
        stream.status().code() != dmc::ErrorCode::kUnsupported) {
      dmc::fuzz::InvariantBroken("encode: " + stream.status().ToString());
    }
    return 0;
  }
  const dmc::StatusOr<dmc::MeshSequence> decoded = dmc::Decode(*stream);
  if (!decoded.ok()) {
    if (decoded.status().code() != dmc::ErrorCode::kNumericalFailure) {
      dmc::fuzz::InvariantBroken("decode: " + decoded.status().ToString());
    }
    return 0;
  }
  if (decoded->vertex_count() != v_count || decoded->frame_count() != frames ||
      decoded->triangle_count() != triangles.rows()) {
    dmc::fuzz::InvariantBroken();
  }
  for (size_t i = 0; i < decoded->position_value_count(); ++i) {
    if (!std::isfinite(decoded->data()[i])) dmc::fuzz::InvariantBroken();
  }
  return 0;
}
